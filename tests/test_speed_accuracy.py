"""Speed against accuracy and the failure maps (quick sizes): the artefacts exist, each
method fails where it should, and never hangs."""

import json
import math

import numpy as np

from granular.cli import speed_accuracy
from granular.simulation import _LIST_SHELL


def test_failure_maps_pin_each_failure_mode():
    stab = speed_accuracy.em_stability(quick=True)
    by_g = {r["gamma_dt"]: r for r in stab}
    # Euler-Maruyama is refused at and past the limit; the exact scheme never is
    assert all(by_g[g]["em"] is None for g in (2.0, 3.0, 10.0))
    assert all(r["exact"] is not None and math.isfinite(r["exact"]) for r in stab)
    # EM's stationary velocity bias follows 2 / (2 - gamma dt) - 1 (5 standard errors of
    # the mean over 3 x 2000 Gaussian components, sqrt(2/6000) = 1.8%)
    for g in (0.5, 1.0, 1.5):
        assert abs(by_g[g]["em_v2_bias"] - (2 / (2 - g) - 1)) < 5 * math.sqrt(2 / 6000) * (
            2 / (2 - g)
        )
        assert abs(by_g[g]["exact_v2_bias"]) < 5 * math.sqrt(2 / 6000)
    cells = speed_accuracy.collapse_map(quick=True)
    plain = {(c["eta"], c["xi"]): c for c in cells if c["contact_duration"] == 0}
    tc = [c for c in cells if c["contact_duration"] > 0]
    assert plain[(0.1, 0.3)]["status"] == "collapse"  # 2D walls, strongly inelastic
    assert plain[(0.1, 0.9)]["status"] in ("ok", "tc")
    assert all(c["status"] != "collapse" for c in tc)  # the TC model lets every run finish
    assert all(c["seconds"] < 60 for c in cells)  # bounded work, never a hang
    # a run stopped by the event budget is neither ok nor tc: it did not reach its goal.
    # 4000 events per particle suffice for every cell here; 10 suffice for none
    assert "budget" not in {c["status"] for c in cells}
    starved = speed_accuracy.collapse_map(
        quick=True, contact_durations=(1e-4,), events_per_particle=10
    )
    assert {c["status"] for c in starved} == {"budget"}


def test_speed_accuracy_cli_quick(tmp_path):
    import subprocess
    import sys

    subprocess.run(
        [
            sys.executable,
            "-m",
            "granular",
            "bench",
            "--speed-accuracy",
            "--quick",
            "--out",
            str(tmp_path),
        ],
        check=True,
        capture_output=True,
        timeout=600,
    )

    def refuse(constant):  # strict JSON: no Infinity or NaN, which other parsers reject
        raise ValueError(f"speed_accuracy.json holds {constant}, which is not JSON")

    data = json.loads((tmp_path / "speed_accuracy.json").read_text(), parse_constant=refuse)
    methods = {p["method"] for p in data["points"]}
    assert methods == {"edmd", "em", "exact"}
    assert {p["gas"] for p in data["points"]} == {"granular", "molecular"}
    for p in data["points"]:
        assert p["seconds"] > 0 and np.isfinite(p["msd_error"]) and np.isfinite(p["slope_error"])
    # per gas: Euler-Maruyama up to gamma0 dt = 1.9, just short of its limit; the exact
    # scheme at the same steps and past the limit
    for gas in ("granular", "molecular"):
        em, exact = (
            {
                round(p["gamma_dt"], 6)
                for p in data["points"]
                if p["gas"] == gas and p["method"] == m
            }
            for m in ("em", "exact")
        )
        assert max(em) == 1.9 and em < exact and max(exact) > 2
    for name in ("speed_accuracy.png", "em_stability.png", "collapse_map.png", "dense_cost.png"):
        assert (tmp_path / name).stat().st_size > 5000
    dense = data["dense_cost"]
    assert max(r["eta"] for r in dense if r["dim"] == 3) >= 0.55
    assert max(r["eta"] for r in dense if r["dim"] == 2) >= 0.7
    # 3D with both cells and lists, at every packing
    assert {r["shell"] for r in dense if r["dim"] == 3} == {0.0, _LIST_SHELL}
    assert {r["shell"] for r in dense if r["dim"] == 2} == {0.0}


def test_collapse_map_chart_reads_well():
    """The collapse map's legend lists only the outcomes that occur, and each cell's label
    lies inside its square (synthetic cells: all four outcomes possible, two occur)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    cells = [
        dict(
            contact_duration=tc, eta=eta, xi=xi, status="collapse" if xi < 0.5 and tc == 0 else "ok"
        )
        for tc in (0.0, 1e-4)
        for eta in (0.05, 0.2, 0.4, 0.6, 0.7)
        for xi in (0.9, 0.7, 0.5, 0.3, 0.1)
    ]
    fig = speed_accuracy._collapse_map(plt, cells)
    legend = [t.get_text().split(":")[0] for t in fig.legends[0].get_texts()]
    assert sorted(legend) == ["collapse", "ok"]
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        squares = [p.get_window_extent(renderer) for p in ax.patches if isinstance(p, Rectangle)]
        assert len(squares) == 25 and len(ax.texts) == 25
        for text, square in zip(ax.texts, squares, strict=True):
            box = text.get_window_extent(renderer)
            assert (
                square.x0 <= box.x0
                and box.x1 <= square.x1
                and square.y0 <= box.y0
                and box.y1 <= square.y1
            ), text.get_text()
    plt.close(fig)
