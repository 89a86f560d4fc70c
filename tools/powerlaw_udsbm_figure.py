"""docs/powerlaw_udsbm.png: UDSBM with power-law coefficients (a = 1, the thesis' UDSBM,
and a = 5/6, the viscoelastic gas) against granular.theory -- ensemble MSD with the
overdamped t^(1/6) asymptote, TAMSD, and the exact and Euler-Maruyama schemes' error
computed without noise.  Run: .venv/bin/python tools/powerlaw_udsbm_figure.py"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from granular import langevin, plot, theory

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_langevin_powerlaw import _scheme_moments  # the noise-free moments of each scheme

G0, D0, TAU0 = 9.26, 0.072, 0.972
OUT = Path(__file__).resolve().parents[1] / "docs" / "powerlaw_udsbm.png"


def main():
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax_msd, ax_tamsd, ax_err = axes
    t_stop = 200.0
    for a, colour, name in ((1.0, "C0", "1"), (5 / 6, "C3", "5/6")):
        r = langevin.run(
            2000,
            gamma0=G0,
            D0=D0,
            tau0=TAU0,
            exponent=a,
            dt=0.01,
            t_stop=t_stop,
            tamsd_lags=np.geomspace(0.01, 50, 12),
            seed=1,
        )
        ok = r.times > 0
        label = f"a = {name}"
        ax_msd.loglog(r.times[ok], r.msd()[ok], "o", ms=3, color=colour, label=f"{label}: run")
        ax_msd.loglog(r.times[ok], r.theory_msd()[ok], "-", color=colour, label=f"{label}: theory")
        ax_tamsd.loglog(r.tamsd_lags, r.tamsd(), "s", ms=4, color=colour, label=f"{label}: TAMSD")
        ax_tamsd.loglog(r.tamsd_lags, r.theory_tamsd(), "-", color=colour, label="its theory")
        ax_tamsd.loglog(
            r.tamsd_lags, r.theory_msd(r.tamsd_lags), ":", color=colour, label="ensemble MSD"
        )
    t = np.geomspace(1, 1e6, 50)
    ax_msd.loglog(
        t,
        theory.msd_powerlaw_udsbm_asymptote(t, D0=D0, tau0=TAU0, exponent=5 / 6),
        "k--",
        lw=1,
        label=r"a = 5/6 overdamped: $\propto t^{1/6}$",
    )
    ax_msd.loglog(
        t, theory.msd_powerlaw_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0, exponent=5 / 6), "C3-", lw=0.8
    )
    ax_msd.set(
        xlabel=plot.TIME, ylabel=plot.MSD, title=r"ensemble MSD (3D), N = 2000, $\Delta t$ = 0.01"
    )
    ax_msd.legend(fontsize=8)
    ax_tamsd.set(
        xlabel=plot.LAG_OR_TIME,
        ylabel=plot.MSD_AND_TAMSD,
        title=f"time-averaged MSD (3D) over t = {t_stop:g}",
    )
    ax_tamsd.legend(fontsize=7, ncol=2)

    t_end = 5.0
    xx, _, _ = theory.powerlaw_udsbm_moments(t_end, D0=D0, gamma0=G0, tau0=TAU0, exponent=5 / 6)
    dts = np.array([0.1, 0.05, 0.02, 0.01, 0.005, 0.002])
    for scheme, marker in (("exact", "o-"), ("em", "s-")):
        err = [
            abs(_scheme_moments(scheme, 5 / 6, dt, round(t_end / dt), D0 * G0)[-1, 0] / xx - 1)
            for dt in dts
        ]
        name = {"exact": "exact scheme", "em": "Euler-Maruyama"}[scheme]
        ax_err.loglog(dts, err, marker, label=name)
    ax_err.loglog(dts, 0.2 * dts, "k:", lw=1, label=r"$\propto \Delta t$")
    ax_err.loglog(dts, 0.009 * dts**2, "k--", lw=1, label=r"$\propto \Delta t^2$")
    ax_err.set(
        xlabel=r"time step $\Delta t$ [$L\sqrt{m/\varepsilon}$]",
        ylabel=r"$|\langle x^2 \rangle$ / theory $- 1|$ at t = 5 (dimensionless)",
        title="scheme error without noise, a = 5/6",
    )
    ax_err.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT, dpi=110)
    print(OUT)


if __name__ == "__main__":
    main()
