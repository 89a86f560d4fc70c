"""Speed against accuracy and the failure maps (quick sizes): the artefacts exist, each
method fails where it should, and never hangs."""

import json
import math

import numpy as np
import pytest

from granular import Viscoelastic, restitution
from granular.cli import speed_accuracy, speed_accuracy_transport
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
    plain = {
        (c["eta"], c["xi"]): c
        for c in cells
        if c["law"] == "constant" and c["contact_duration"] == 0
    }
    tc = [c for c in cells if c["contact_duration"] > 0]
    visco = {(c["eta"], c["xi"]): c for c in cells if c["law"] == "viscoelastic"}
    assert set(visco) == set(plain)
    # the law's series stops at eps = 0.76: xi = 0.3 cannot be matched and is not run;
    # xi = 0.9 is, with the same mean restitution, and does not collapse
    assert all(c["status"] == "n/a" for k, c in visco.items() if k[1] == 0.3)
    assert all(c["status"] == "ok" for k, c in visco.items() if k[1] == 0.9)
    assert all(
        c["mean_eps"] == pytest.approx(0.9, abs=1e-9) and c["law_clamped_collisions"] == 0
        for k, c in visco.items()
        if k[1] == 0.9
    )
    assert plain[(0.1, 0.3)]["status"] == "collapse"  # 2D walls, strongly inelastic
    assert plain[(0.1, 0.9)]["status"] in ("ok", "tc")
    assert all(c["status"] != "collapse" for c in tc)  # the TC model lets every run finish
    assert all(c["seconds"] < 60 for c in cells)  # bounded work, never a hang
    # a run stopped by the event budget is neither ok nor tc: it did not reach its goal.
    # 4000 events per particle suffice for every cell here; 10 suffice for none
    assert "budget" not in {c["status"] for c in cells}
    starved = speed_accuracy.collapse_map(
        quick=True, contact_durations=(1e-4,), events_per_particle=10, viscoelastic=False
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
    assert {p["gas"] for p in data["points"]} == {"granular", "molecular", "viscoelastic"}
    for p in data["points"]:
        assert p["seconds"] > 0 and np.isfinite(p["msd_error"]) and np.isfinite(p["slope_error"])
    # per gas: Euler-Maruyama up to gamma0 dt = 1.9, just short of its limit; the exact
    # scheme at the same steps and past the limit
    for gas in ("granular", "molecular", "viscoelastic"):
        em, exact = (
            {
                round(p["gamma_dt"], 6)
                for p in data["points"]
                if p["gas"] == gas and p["method"] == m
            }
            for m in ("em", "exact")
        )
        if gas == "viscoelastic":  # both schemes at the same steps, up to gamma0 dt = 1.9
            assert max(em) == 1.9 and em == exact
        else:
            assert max(em) == 1.9 and em < exact and max(exact) > 2
    # the steady states' transport panels: every method, a cost and an error bar each
    driven = data["driven_diffusion"]["points"]
    assert {p["method"] for p in driven} == {"edmd", "exact", "em"}
    assert all(p["seconds"] > 0 and p["d_error_bar"] > 0 and p["runs"] >= 3 for p in driven)
    visc = data["shear_viscosity"]["points"]
    assert {p["route"] for p in visc} == {"green_kubo", "nemd"}
    for p in visc:
        assert p["seconds"] > 0 and p["spread"] > 0 and len(p["values"]) == p["runs"] >= 3
        assert p["spread"] == pytest.approx(np.std(p["values"], ddof=1))
    names = ("speed_accuracy.png", "em_stability.png", "collapse_map.png", "dense_cost.png")
    for name in (*names, "speed_accuracy_transport.png"):
        assert (tmp_path / name).stat().st_size > 5000
    dense = data["dense_cost"]
    assert max(r["eta"] for r in dense if r["dim"] == 3) >= 0.55
    assert max(r["eta"] for r in dense if r["dim"] == 2) >= 0.7
    # 3D with both cells and lists, at every packing
    assert {r["shell"] for r in dense if r["dim"] == 3} == {0.0, _LIST_SHELL}
    assert {r["shell"] for r in dense if r["dim"] == 2} == {0.0}


def test_collapse_map_chart_reads_well():
    """The collapse map's legend lists only the outcomes that occur, and each cell's label
    lies inside its square (synthetic cells: five outcomes possible, two occur, then three
    with a viscoelastic panel)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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
    _labels_inside_squares(fig)
    plt.close(fig)
    # a third panel, the viscoelastic law: cells it cannot match are n/a
    cells += [
        dict(
            law="viscoelastic",
            contact_duration=0.0,
            eta=eta,
            xi=xi,
            status="n/a" if xi < 0.8 else "ok",
        )
        for eta in (0.05, 0.2, 0.4, 0.6, 0.7)
        for xi in (0.9, 0.7, 0.5, 0.3, 0.1)
    ]
    fig = speed_accuracy._collapse_map(plt, cells)
    legend = [t.get_text().split(":")[0] for t in fig.legends[0].get_texts()]
    assert sorted(legend) == ["collapse", "n/a", "ok"] and len(fig.axes) == 3
    assert "viscoelastic" in fig.axes[2].get_title()
    _labels_inside_squares(fig)
    plt.close(fig)


def _labels_inside_squares(fig):
    from matplotlib.patches import Rectangle

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


def test_matched_viscoelastic_law_has_the_mean_restitution():
    """granular.restitution.matched_viscoelastic (with the laws; the benchmark's collapse
    map uses it): the law matched to a constant xi has eps(g) averaged over the Rayleigh density of
    initial impact speeds equal to xi, checked here by Monte Carlo: g = s sqrt(-2 ln U) is
    Rayleigh with s^2 = 2 T / m; 400 000 draws give the mean to about 2e-5 (the spread of
    eps over g, < 0.1, over sqrt(4e5)), so 2e-4 is ten standard errors.  Below the law's
    range it refuses, saying why."""
    rng = np.random.default_rng(1)
    g = math.sqrt(2 * 1.5) * np.sqrt(-2 * np.log(rng.random(400_000)))
    for xi in (0.95, 0.85):
        law, info = restitution.matched_viscoelastic(xi, 1.5)
        assert isinstance(law, Viscoelastic)
        assert law(g).mean() == pytest.approx(xi, abs=2e-4)
        assert info["clamped_share"] <= restitution.MATCH_CLAMPED_SHARE
    for xi in (0.7, 0.5):  # the series stops at eps = 0.7615: out of reach
        law, info = restitution.matched_viscoelastic(xi, 1.5)
        assert law is None and info["mean_eps"] > 0.76


def _em_tamsd(steps, n_steps, dt, gamma, diffusion, v0_sq):
    """Euler-Maruyama's expected TAMSD (all windows, one component) at lags of ``steps``:
    v_{i+1} = rho v_i + noise, rho = 1 - gamma dt, is AR(1) with stationary variance
    s2 = 2 gamma D / (2 - gamma dt) (csrc/sde.c), started at v0_sq; x_{i+1} = x_i + v_i dt,
    so a window's displacement is dt times a sum of consecutive v, whose variance follows
    from cov(v_i, v_j) = rho^|i - j| var(v_min(i, j))."""
    rho = 1.0 - gamma * dt
    s2 = 2.0 * gamma * diffusion / (2.0 - gamma * dt)
    i = np.arange(n_steps)
    var = s2 + (v0_sq - s2) * rho ** (2 * i)
    cov = rho ** np.abs(i[:, None] - i[None, :]) * var[np.minimum.outer(i, i)]
    out = []
    for k in steps:
        sums = [cov[s : s + k, s : s + k].sum() for s in range(n_steps - k + 1)]
        out.append(dt * dt * np.mean(sums))
    return np.array(out)


def test_driven_langevin_points_are_what_their_schemes_give():
    """The driven gas' Langevin points: the exact scheme's D over the fit window is
    theory's (it integrates the OU process exactly at any step), and Euler-Maruyama near
    its limit (gamma dt = 1.9) is not -- its velocity is AR(1) with rho = -0.9, whose MSD
    alternates with the parity of the lag for ~20 steps, so the window's slope is far off;
    measured against that closed form (``_em_tamsd``), not against a tolerance.  Six
    independent runs each; 5 standard errors of their mean (t with 5 degrees of freedom:
    a 0.4 % chance of a false alarm)."""
    model = speed_accuracy_transport.driven_model()
    g, d = model["gamma"], model["diffusion"]
    assert g * d == pytest.approx(model["temperature"])  # D = T / (m gamma_v)
    assert d == pytest.approx(2 * model["enskog_diffusion"] / 1.8)  # 2 D_E / (1 + xi)
    span, dt = 60, 1.9 / g
    n_steps = round(span / g / dt)
    lags = np.unique(np.round(speed_accuracy_transport.FIT_LAGS / g / dt)).astype(int)
    em_pred = speed_accuracy_transport._slope_d(
        lags * dt, 3 * _em_tamsd(lags, n_steps, dt, g, d, g * d)
    )
    for scheme, expected_over_theory in (("exact", 1.0), ("em", None)):
        runs = [
            speed_accuracy_transport._sde_driven(2000, span, dt, scheme, model, seed=40 + k)
            for k in range(6)
        ]
        ratio = np.array([r[0] / r[1] for r in runs])
        if expected_over_theory is None:
            expected_over_theory = em_pred / runs[0][1]
            assert expected_over_theory < 0.5  # the failure is real, not noise
        assert abs(ratio.mean() - expected_over_theory) < 5 * ratio.std(ddof=1) / math.sqrt(6)
