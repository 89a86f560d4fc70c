"""The command line: the demo and the benchmark run and write what they promise."""
import json
import subprocess
import sys

import pytest


def run(*args, cwd):
    return subprocess.run([sys.executable, "-m", "granular", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=600, check=True)


def test_demo_quick(tmp_path):
    """The demo's granular gas cools by Haff's law (within 10% of (2.40) at t_end, the
    accuracy of the Maxwellian tau0 compounded over 10 tau0) and its molecular gas keeps
    its temperature to rounding."""
    out = run("demo", "--quick", "--out", str(tmp_path / "demo"), cwd=tmp_path)
    assert "granular demo" in out.stdout
    rows = {r["gas"]: r for r in json.loads((tmp_path / "demo" / "summary.json").read_text())}
    assert (tmp_path / "demo" / "demo.png").stat().st_size > 10_000
    mol, gran = rows["molecular"], rows["granular"]
    assert mol["T_end"] == pytest.approx(mol["T_end_theory"], rel=1e-12)
    assert gran["T_end"] == pytest.approx(gran["T_end_theory"], rel=0.10)
    assert mol["msd_end"] == pytest.approx(mol["msd_end_theory"], rel=0.15)


def test_bench_quick_json(tmp_path):
    run("bench", "--quick", "--json", "b.json", cwd=tmp_path)
    rows = json.loads((tmp_path / "b.json").read_text())
    edmd = [r for r in rows if r["engine"] == "edmd"]
    assert len(edmd) == 5 and {r["dim"] for r in edmd} == {2, 3}
    for r in edmd:
        for key in ("name", "dim", "n", "packing_fraction", "boundary", "restitution",
                    "pair_collisions", "seconds", "pair_collisions_per_second"):
            assert key in r
        assert r["pair_collisions"] > 0 and r["pair_collisions_per_second"] > 0
    lang = [r for r in rows if r["engine"] == "langevin"]
    assert lang and all(r["particle_steps_per_second"] > 0 for r in lang)


def test_reproduce_quick(tmp_path):
    """Chapter 4 at small sizes: every figure and row is there, and the rows that theory
    fixes exactly fall within five standard errors of it (errors from the run count);
    Haff's tau0 within 12% (the Maxwellian theory's own accuracy, see
    test_physics_edmd); the UDSBM time average well below its ensemble MSD."""
    run("reproduce", "--quick", "--out", "rep", cwd=tmp_path)
    rows = {r["id"]: r for r in json.loads((tmp_path / "rep" / "summary.json").read_text())}
    required = ["energy.drift.xi1", "msd.slope.xi1", "msd.slope.xi0.8", "ergodicity.langevin",
                "ergodicity.udsbm"] + [f"table4.1.{d}.{k}" for d in ("2d", "3d") for k in ("mean", "mean_sq", "std")] \
        + [f"haff.tau0.xi{x}" for x in ("0.99", "0.5", "0.3")]
    assert set(required) <= set(rows)
    for r in rows.values():
        assert set(r) == {"id", "quantity", "ours", "ours_error", "thesis", "theory"}
    assert rows["energy.drift.xi1"]["ours"] < 1e-13
    for d in ("2d", "3d"):
        r = rows[f"table4.1.{d}.mean"]
        assert abs(r["ours"] - r["theory"]) < 5 * r["ours_error"]
    r = rows["ergodicity.langevin"]
    assert abs(r["ours"] - 1) < 5 * r["ours_error"]
    assert rows["ergodicity.udsbm"]["ours"] < 0.7
    for x in ("0.99", "0.5", "0.3"):
        r = rows[f"haff.tau0.xi{x}"]
        assert r["ours"] == pytest.approx(r["theory"], rel=0.12)
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "| table4.1.3d.mean |" in report
    pngs = list((tmp_path / "rep").glob("*.png"))
    assert len(pngs) >= 20
