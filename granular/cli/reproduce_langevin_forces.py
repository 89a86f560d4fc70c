"""The reproduction's experiment on external forces in the Langevin model (the thesis'
"further work", ch. 5): a Brownian particle in a harmonic trap.

- **The trap's MSD** in the three damping regimes -- underdamped (k/m = 4 gamma0^2/4),
  critical (k/m = gamma0^2/4) and overdamped (k/m = 0.3 gamma0^2/4) -- with the thesis'
  molecular-gas coefficients gamma0 = 9.26, D0 = 0.072 (T/m = D0 gamma0) and the exact
  scheme at gamma0 dt = 0.0926, particles started in the trap's stationary state.  Against
  ``theory.msd_trap`` (Uhlenbeck & Ornstein 1930; Chandrasekhar 1943 ch. II sec. 3): the
  rows are the plateau 2 d T / k, measured per run as the mean MSD over the samples past
  ten slowest relaxation times, with its standard error over the runs.
- **Where Euler-Maruyama fails** (the figure's right panel): EM's stationary variance of x
  in the underdamped trap against (k/m) dt / gamma0, from runs and from its own discrete
  Lyapunov equation, diverging at the stability limit (k/m) dt = gamma0, beyond which the
  run is refused; the exact scheme keeps T / k at any step.
"""

from __future__ import annotations

import math

import numpy as np

from .. import langevin, theory

G0, D0 = 9.26, 0.072  # the thesis' standard gas (theory.langevin_coefficients, xi = 0.8)
CRITICAL = G0 * G0 / 4  # k/m at critical damping (mass 1)
REGIMES = (("underdamped", 4.0 * CRITICAL), ("critical", CRITICAL), ("overdamped", 0.3 * CRITICAL))
DT = 0.01
DIM = 3


def _slowest_rate(w):
    """The slowest decay rate of the mean: gamma0/2, or w / (gamma0/2 + q) overdamped."""
    q2 = G0 * G0 / 4 - w
    return w / (G0 / 2 + math.sqrt(q2)) if q2 > 0 else G0 / 2


def em_stationary_x(w, dt):
    """Euler-Maruyama's own stationary <x^2> in the trap: S = M S M^T + diag(0, 2 D0
    gamma0^2 dt), M = [[1, dt], [-w dt, 1 - gamma0 dt]], solved as a linear system (inf at
    and past the stability limit w dt >= gamma0)."""
    if w * dt >= G0:
        return math.inf
    M = np.array([[1.0, dt], [-w * dt, 1.0 - G0 * dt]])
    q = np.array([0.0, 0.0, 0.0, 2.0 * D0 * G0 * G0 * dt])
    return float(np.linalg.solve(np.eye(4) - np.kron(M, M), q)[0])


def _fig_langevin_forces(cfg, out, *, ensemble, save, fig, row, mean_row):
    runs = cfg.runs_few
    n = 500 if cfg.quick else 2000
    T = D0 * G0  # mass 1
    f, (ax, ax2) = fig(ncols=2)
    rows = []
    for (name, w), color in zip(REGIMES, ("C0", "C1", "C2"), strict=True):
        t_relax = 1.0 / _slowest_rate(w)
        t_stop = 20.0 * t_relax
        times = np.unique(np.rint(np.geomspace(DT, t_stop, 40) / DT)) * DT
        per_run_msd = []
        for run in range(runs):
            r = langevin.run(
                n,
                gamma0=G0,
                D0=D0,
                dt=DT,
                t_stop=t_stop,
                trap_stiffness=w,
                sample_times=times,
                seed=(2026, run, int(w * 1000)),
                threads=1,
            )
            per_run_msd.append(r.msd())
        msd = np.array(per_run_msd)
        t = r.times
        plateau = theory.msd_trap_plateau(w, temperature=T, dim=DIM)
        late = t >= 10 * t_relax
        per_run = msd[:, late].mean(axis=1)
        rows.append(
            mean_row(
                "langevin.trap.msd" + ("" if name == "underdamped" else f".{name}"),
                f"MSD plateau 2 d T / k in a harmonic trap, {name} (k/m = "
                f"{w / CRITICAL:g} gamma0^2/4), exact scheme, {n} particles a run, mean MSD "
                f"over t >= 10 relaxation times",
                per_run,
                theory_value=plateau,
            )
        )
        mean = msd.mean(axis=0)
        err = msd.std(axis=0, ddof=1) / math.sqrt(runs)
        ax.errorbar(t, mean / plateau, err / plateau, fmt="o", ms=3, color=color, label=name)
        th = theory.msd_trap(t, D0=D0, gamma0=G0, stiffness=w, dim=DIM)
        ax.plot(t, th / plateau, "-", color=color, lw=1)
    ax.set_xscale("log")
    ax.set_xlabel("t")
    ax.set_ylabel("MSD / (2 d T / k)")
    ax.set_title("Harmonic trap: MSD (points) against theory (lines)")
    ax.legend(fontsize=8)

    # where Euler-Maruyama fails: its stationary <x^2> against (k/m) dt / gamma0
    w = REGIMES[0][1]
    exact = T / w
    ratios = np.array([0.1, 0.3, 0.5, 0.7, 0.85, 0.95])
    n_em = 500 if cfg.quick else 4000
    measured = []
    for ratio in ratios:
        dt = ratio * G0 / w
        t_stop = dt * max(200, round(20 / (G0 * dt * (1 - ratio))))
        r = langevin.run(
            n_em,
            gamma0=G0,
            D0=D0,
            dt=dt,
            t_stop=t_stop,
            dim=1,
            trap_stiffness=w,
            scheme="em",
            seed=(7, int(ratio * 100)),
            threads=1,
        )
        assert r.initial_positions is not None
        x = r.initial_positions + r.final_positions
        measured.append(float(np.mean(x * x)))
    fine = np.linspace(0.02, 0.99, 200)
    ax2.plot(fine, [em_stationary_x(w, q * G0 / w) / exact for q in fine], "-", color="C3",
             label="EM: its discrete Lyapunov solution")  # fmt: skip
    ax2.plot(ratios, np.array(measured) / exact, "o", color="C3", label=f"EM runs (N = {n_em})")
    ax2.axhline(1.0, color="k", lw=1, label="exact scheme: T / k at any step")
    ax2.axvline(1.0, color="grey", ls="--", lw=1)
    ax2.set_yscale("log")
    ax2.set_xlabel("(k/m) dt / gamma0  (EM unstable at 1)")
    ax2.set_ylabel("stationary <x^2> / (T / k)")
    ax2.set_title("Euler-Maruyama in the trap (underdamped)")
    ax2.legend(fontsize=8)
    return [save(f, out, "langevin_trap_msd.png")], rows
