"""Every plot renders to PNG, returns its axes and labels its axes with units."""
import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
import matplotlib.pyplot as plt  # noqa: E402

from granular import plot, theory  # noqa: E402


def test_all_plots_render(tmp_path):
    rng = np.random.default_rng(0)
    t = np.logspace(-2, 1, 20)
    v = rng.normal(size=(500, 3))
    figs = [
        plot.energy(t, 1 + 1e-15 * rng.normal(size=20)),
        plot.collisions_per_particle(t, 3 * t, label="PBC"),
        plot.speed_distribution(v),
        plot.haff(t, theory.haff_temperature(t, 1.0, 2.0), tau0=2.0),
        plot.msd(t, theory.msd_langevin(t, 0.1, 5.0), error=0.01 * t, theory_values=theory.msd_langevin(t, 0.1, 5.0)),
        plot.diffusivity(t, 0.1 * np.ones(20), theory_values=0.1 * np.ones(20)),
        plot.msd_vs_tamsd(t, t, t[::4], t[::4]),
        plot.snapshot(rng.random((30, 2)), 0.02, [0, 0], [1, 1]),
    ]
    for k, ax in enumerate(figs):
        assert hasattr(ax, "plot")
        # labelled units: every axis names its unit (L, m, epsilon, or dimensionless)
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert "[" in label or "dimensionless" in label, f"plot {k}: no unit in {label!r}"
        ax.figure.savefig(tmp_path / f"f{k}.png")
        assert (tmp_path / f"f{k}.png").stat().st_size > 1000
    fig, ax = plt.subplots()
    assert plot.energy(t, np.ones(20), ax=ax) is ax
    plt.close("all")
