"""Every plot renders to PNG, returns its axes and labels its axes with units."""

import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
import matplotlib.pyplot as plt  # noqa: E402

import granular  # noqa: E402
from granular import plot, theory  # noqa: E402

# a call in the old positional form fails here: nothing in the repository may use it
pytestmark = pytest.mark.filterwarnings("error::FutureWarning")


def test_all_plots_render(tmp_path):
    rng = np.random.default_rng(0)
    t = np.logspace(-2, 1, 20)
    v = rng.normal(size=(500, 3))
    figs = [
        plot.energy(t, 1 + 1e-15 * rng.normal(size=20)),
        plot.collisions_per_particle(t, 3 * t, label="PBC"),
        plot.speed_distribution(v),
        plot.haff(t, theory.haff_temperature(t, temperature0=1.0, tau0=2.0), tau0=2.0),
        plot.msd(
            t,
            theory.msd_langevin(t, D0=0.1, gamma0=5.0),
            error=0.01 * t,
            theory_values=theory.msd_langevin(t, D0=0.1, gamma0=5.0),
        ),
        plot.diffusivity(t, 0.1 * np.ones(20), theory_values=0.1 * np.ones(20)),
        plot.msd_vs_tamsd(t, t, lags=t[::4], tamsd_values=t[::4]),
        plot.snapshot(rng.random((30, 2)), radii=0.02, lower=[0, 0], upper=[1, 1]),
    ]
    for k, ax in enumerate(figs):
        assert hasattr(ax, "plot")
        # labelled units: every axis names its unit (L, m, epsilon, or dimensionless)
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert "[" in label or "dimensionless" in label, f"plot {k}: no unit in {label!r}"
        ax.figure.savefig(tmp_path / f"f{k}.png")
        assert (tmp_path / f"f{k}.png").stat().st_size > 1000
    _, ax = plt.subplots()
    assert plot.energy(t, np.ones(20), ax=ax) is ax
    plt.close("all")


def _texts(ax):
    """Every piece of text a reader sees on the axes: labels, title, legend entries."""
    legend = ax.get_legend()
    return [
        ax.get_xlabel(),
        ax.get_ylabel(),
        ax.get_title(),
        *([t.get_text() for t in legend.get_texts()] if legend else []),
    ]


def test_demo_panels_read_well():
    """The demo's panels, drawn from synthetic results: the two MSD theories are told apart by
    line style, every axis has a unit, Greek symbols are mathtext (never 'tau0' or 'xi'),
    and the speed histograms end at the fastest particle rather than far beyond it."""
    from types import SimpleNamespace

    from granular.cli import demo

    rng = np.random.default_rng(1)
    t = np.concatenate([[0.0], np.logspace(-2, 1, 20)])
    results = {}
    for label, xi in (("molecular", 1.0), ("granular", 0.8)):
        c = theory.langevin_coefficients(
            n=300, radius=0.037, volume=1.0, restitution=xi, temperature0=0.66
        )
        T = (
            theory.haff_temperature(t, temperature0=0.66, tau0=c.tau0)
            if xi < 1
            else np.full_like(t, 0.66)
        )
        msd = theory.msd_granular(t, D0=c.D0, gamma0=c.gamma0, tau0=c.tau0)
        res = SimpleNamespace(
            mean=dict(msd=msd, temperature=T),
            error=dict(msd=0.01 * msd, temperature=0.01 * T),
            times=t,
            runs=[dict(velocities=[rng.normal(size=(300, 3)) * np.sqrt(T[-1])])],
        )
        results[label] = (res, msd, T, c)
    _, axes = plt.subplots(1, 4)
    demo._msd(axes[0], t, results)
    demo._temperature(axes[1], t, results)
    demo._speeds(axes[2], "molecular", results)
    demo._speeds(axes[3], "granular", results)
    theories = [line for line in axes[0].get_lines() if "theory" in line.get_label()]
    assert len(theories) == 2
    assert len({(line.get_linestyle(), line.get_color()) for line in theories}) == 2, (
        "theories look alike"
    )
    for ax in axes:
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert "[" in label or "dimensionless" in label, f"no unit in {label!r}"
        for text in _texts(ax):
            assert "tau0" not in text and "xi " not in text and "xi=" not in text, text
    for ax, label in ((axes[2], "molecular"), (axes[3], "granular")):
        v = results[label][0].runs[0]["velocities"][-1]
        fastest = np.max(np.linalg.norm(v, axis=1))
        # the histogram's last bin ends 2% past the fastest particle; matplotlib's 5% margin
        assert ax.get_xlim()[1] < 1.1 * fastest
    plt.close("all")


def _small_run():
    scene = granular.Scene.random(4, 0.05, dim=2, seed=1)
    return granular.Simulation(scene).run(t_stop=0.1, sample_times=[0.0, 0.1])


@pytest.mark.parametrize(
    "draw",
    [
        lambda: plot.msd(np.arange(1.0, 4.0), np.arange(1.0, 4.0)),
        lambda: plot.snapshot(np.zeros((1, 2)), radii=0.1, lower=[0, 0], upper=[1, 1]),
        lambda: plot.animate(_small_run()),
    ],
)
def test_without_matplotlib_the_message_names_the_extra(monkeypatch, draw):
    # a bare install: matplotlib (an extra, not a dependency) cannot be imported
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(ModuleNotFoundError, match=r"pip install 'granular\[plot\]'"):
        draw()
