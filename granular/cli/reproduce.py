"""``python -m granular reproduce``: chapter 4 of the thesis, figure by figure.

Public entry points
-------------------
``FIGURES``
    The experiments in the thesis' order, by name: ``"4.1"``, ``"4.2-4.4"``, ``"4.5-4.7"``,
    ``"4.8+4.10"``, ``"4.9"``, ``"4.11-4.16+F"``, ``"4.17-4.23"``, then ``"clustering"``
    (where the homogeneous cooling of Fig. 4.10 ends; ``reproduce_clustering``) and
    ``"viscoelastic"`` (the viscoelastic gas and its power-law UDSBM; ``reproduce_visco``);
    then the experiments beyond the thesis, each in its own module ``reproduce_<name>``:
    ``"transport"`` (elastic viscosity, self-diffusion, equation of state),
    ``"langevin-forces"`` (the Langevin model in a harmonic trap), ``"driven"`` (a2 of the
    cooling and the white-noise driven state, the driven temperature), ``"rough"`` (rough
    spheres and disks: T_rot/T_tr, the coupled cooling, Walton's rule), ``"vibrated"`` (a
    gas kept hot by a vibrating wall), ``"gravity"`` (the hydrostatic profile of an elastic
    column),
    ``"shear"`` (uniform shear flow of the inelastic gas).
``figure(name, quick=False, out="granular-reproduce", runs=None, backend=None)``
    Run one experiment, write its PNG files into ``out`` and return ``(paths, rows)``: the
    files written and the experiment's rows for ``summary.json``.
``ABOUT``
    Per experiment: what it shows, and its expected wall time (full, quick) on a quiet
    2-core machine, which the progress line says before it starts.
``main(out="granular-reproduce", quick=False, runs=None, backend=None, only=None)``
    Every experiment (or those named in ``only``), then ``summary.json`` and ``report.md``
    (``python -m granular reproduce``); returns the rows.

``backend`` is the ensembles' (``granular.ensemble``; the results are the same on each):
by default threads in quick mode, processes otherwise.

Each experiment runs the thesis' system (N = 1000, r = 0.025, eta = 0.065 in 3D; N = 2000,
r = 0.005 in 2D) with five times the thesis' number of runs by default, or, with ``quick``,
smaller systems over shorter times with ``QUICK_RUNS`` runs each.  A row is
``{"id", "quantity", "ours", "ours_error", "runs", "thesis", "theory"}``: our value, its
central-limit standard error over ``runs`` independent runs (both None where the value is
not a mean over runs), the thesis' value where it printed one for the same system (the App. F
slopes are None in quick mode, whose system is smaller; the quantity text quotes them), and
theory's; non-finite numbers are written as null (strict JSON has no Infinity).
``report.md`` (written by ``reproduce_text``, which holds the report's prose) shows the table
beside the figures; its sentences are generated from the rows: each comparison with its
relative deviation and whether it lies within ``reproduce_text.SIGMA`` standard errors.

Where the thesis had a slip we use the correct physics: isotropic initial directions
instead of eq. 3.3, and the mean collision time of (2.42) rather than the printed
(2.70)-(2.71).  Granular runs start, as in the thesis, from an equilibrated molecular gas
whose velocity vectors are shuffled among the particles for each run (section 3.8).
"""

from __future__ import annotations

import functools
import math
import os
import sys
import time
import warnings

import numpy as np

from .. import ClusteringWarning, Scene, Simulation, analysis, ensemble, langevin, plot, theory
from .output import write_json
from .reproduce_text import THESIS_SLOPES, THESIS_T0, report

QUICK_RUNS = 20  # runs per experiment in quick mode: enough for Student-t error bars


class Config:
    """Sizes of one reproduction: the thesis' (full) or small ones (quick)."""

    def __init__(self, quick=False, runs=None, backend=None):
        self.quick = quick
        self.runs_given = runs
        # the ensembles' backend (results are the same on every one): quick mode runs many
        # small ensembles, where starting worker processes costs more than the runs (threads:
        # 18 s against 31 s for all of it), and the C core releases the GIL
        self.backend = backend or ("threads" if quick else "processes")
        self.n3, self.r3 = (1000, 0.025) if not quick else (250, 0.025 * 4 ** (1 / 3))
        self.n2, self.r2 = (2000, 0.005) if not quick else (400, 0.005 * 5**0.5)
        self.t_long = 100.0 if not quick else 10.0
        # t_stop of the time-averaged MSDs of Fig. 4.23 (the thesis: 10 and 100); includes
        # t_long, the t_stop of Figs 4.21-4.22
        self.tamsd_t_stops = (10.0, 100.0, 1000.0) if not quick else (1.0, 10.0, 50.0)
        # the thesis' run counts x 5
        self.runs_few = runs or (20 if not quick else QUICK_RUNS)  # thesis: 4
        self.runs_many = runs or (100 if not quick else QUICK_RUNS)  # thesis: 20
        self.c_speed = 0.2  # collisions per particle per particle (c_stop = 0.2 N)


# the thesis' names of the boundaries, spelt out where a figure shows them
BOUNDARY_NAMES = (("periodic", "periodic box (PBC)"), ("walls", "reflecting walls (RBC)"))


def _checked_ensemble(*args, **kwargs):
    return _checked(ensemble(*args, **kwargs))


def _checked(res):
    """An ensemble result, or the first failure raised: a reproduction must not quietly
    average fewer runs than it says."""
    if res.failures:
        f = res.failures[0]
        raise RuntimeError(
            f"{len(res.failures)} runs failed; run {f.index}: {f.error}\n{f.traceback}"
        )
    return res


def _row(id_, quantity, ours, error=None, runs=None, thesis=None, theory_value=None):
    def f(x):
        return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else float(x)

    return {
        "id": id_,
        "quantity": quantity,
        "ours": f(ours),
        "ours_error": f(error),
        "runs": runs,
        "thesis": f(thesis),
        "theory": f(theory_value),
    }


def _mean_row(id_, quantity, per_run, thesis=None, theory_value=None):
    """A row from one value per run: their mean, its standard error and the run count."""
    m, e = analysis.ensemble_mean(per_run)
    return _row(id_, quantity, m, e, len(per_run), thesis, theory_value)


def _save(fig, out, name):
    path = os.path.join(out, name)
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return name


def _fig(ncols=1, size=(5.5, 4.0)):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=(size[0] * ncols, size[1]), layout="constrained")
    return fig, axes


def equilibrium_scene(cfg, seed=2020, boundary="periodic"):
    """The thesis' starting state for granular runs: the standard 3D gas after 20
    collisions per particle at xi = 1 (Maxwell-Boltzmann velocities)."""
    sim = Simulation(Scene.random(cfg.n3, cfg.r3, boundary=boundary, seed=seed))
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    return sim.scene


# -- 4.1: verification ------------------------------------------------------------------------


def _fig_4_1(cfg, out):
    """Two disks in a head-on collision between walls."""
    s = Scene([[0.25, 0.5], [0.75, 0.5]], [[0.5, 0.0], [-0.5, 0.0]], 0.05, boundary="walls")
    t = np.linspace(0, 2.0, 401)
    tr = Simulation(s).run(t_stop=2.0, sample_times=t)
    fig, ax = _fig()
    for k in range(2):
        ax.plot(t, tr._need("positions")[:, k, 0], label=f"particle {k}")
    ax.axvline(0.4, color="0.7", ls=":", label="contact, t = 0.4")
    ax.set_xlabel(plot.TIME)
    ax.set_ylabel(plot.POSITION.format("x"))
    ax.legend()
    ax.set_title("Fig. 4.1: head-on collision, reflecting walls")
    return [_save(fig, out, "fig4_1_head_on.png")], []


def _fig_4_2_to_4_4(cfg, out):
    """Energy conservation (xi = 1) and collisions per particle (xi = 1, 0.8), PBC vs RBC."""
    t = np.linspace(0, 10.0 if not cfg.quick else 2.0, 101)
    res = {}
    for boundary in ("periodic", "walls"):
        eq = equilibrium_scene(cfg, boundary=boundary)
        for xi in (1.0, 0.8):
            res[boundary, xi] = _checked_ensemble(
                eq.replace(restitution=xi),
                cfg.runs_few,
                seed=42,
                backend=cfg.backend,
                t_stop=t[-1],
                sample_times=t,
                quantities=("kinetic_energy", "collisions_per_particle"),
            )
    fig, ax = _fig()
    drifts = []
    for boundary, name in BOUNDARY_NAMES:
        r = res[boundary, 1.0]
        rel = np.array([run["kinetic_energy"] / run["kinetic_energy"][0] - 1 for run in r.runs])
        drifts.append(np.max(np.abs(rel)))
        ax.plot(t, rel.mean(0), label=name)
    ax.set_xlabel(plot.TIME)
    ax.set_ylabel(r"$\langle E \rangle(t) / \langle E \rangle(0) - 1$ (dimensionless)")
    ax.set_title("Fig. 4.2: energy of a molecular gas")
    ax.legend()
    names = [_save(fig, out, "fig4_2_energy.png")]
    for xi, fig_no in ((1.0, "4_3"), (0.8, "4_4")):
        fig, ax = _fig()
        for boundary, name in BOUNDARY_NAMES:
            r = res[boundary, xi]
            ax.errorbar(
                t,
                r.mean["collisions_per_particle"],
                yerr=r.error["collisions_per_particle"],
                label=name,
                errorevery=10,
            )
        ax.set_xlabel(plot.TIME)
        ax.set_ylabel(plot.COLLISIONS)
        ax.set_title(
            f"Fig. {fig_no.replace('_', '.')}: "
            + ("molecular gas" if xi == 1 else r"granular gas, $\xi$ = 0.8")
        )
        ax.legend()
        names.append(_save(fig, out, f"fig{fig_no}_collisions.png"))
    rows = [
        _row(
            "energy.drift.xi1",
            f"max |E(t)/E(0) - 1| over {2 * cfg.runs_few} runs, molecular gas, "
            f"PBC and RBC, t <= {t[-1]:g}",
            max(drifts),
            thesis=1e-14,
            theory_value=0.0,
        )
    ]
    return names, rows


def _speeds_task(n, radius, dim, collisions, seed):
    """One run of Figs 4.5-4.6: fixed speed sqrt(2) in isotropic directions, RBC, until
    `collisions` per particle; returns the final velocities."""
    s = Scene.random(n, radius, dim=dim, boundary="walls", seed=seed)
    tr = Simulation(s).run(stop_when={"collisions_per_particle": collisions}, store=("velocities",))
    return {"velocities": tr._need("velocities")[-1]}


def _fig_4_5_to_4_7(cfg, out):
    """Speed distributions in 2D and 3D against Maxwell-Boltzmann, Table 4.1."""
    names, rows = [], []
    for dim, n, r, fig_no in ((2, cfg.n2, cfg.r2, "4_5"), (3, cfg.n3, cfg.r3, "4_6")):
        task = functools.partial(_speeds_task, n, r, dim, cfg.c_speed * n)
        res = _checked_ensemble(task, cfg.runs_many, seed=7, backend=cfg.backend)
        v = np.array([run["velocities"] for run in res.runs])  # (K, N, d)
        # the runs' mean temperature (their energies differ slightly: centre-of-mass
        # velocity removed), so that <v^2> = d T holds by construction, as in the thesis
        T = float(np.mean(analysis.temperature(v)))
        fig, ax = _fig()
        plot.speed_distribution(v.reshape(-1, dim), temperature=T, ax=ax, label=f"{len(v)} runs")
        ax.set_title(f"Fig. {fig_no.replace('_', '.')}: speeds, {dim}D, N = {n}")
        names.append(_save(fig, out, f"fig{fig_no}_speeds_{dim}d.png"))
        per_run = [analysis.speed_statistics(vr, temperature=T) for vr in v]
        mb = theory.maxwell_boltzmann_moments(temperature=T, dim=dim)
        for key, label in (("mean", "<v>"), ("mean_sq", "<v^2>"), ("std", "std(v)")):
            rows.append(
                _mean_row(
                    f"table4.1.{dim}d.{key}",
                    f"{label}, {dim}D, N = {n} (T = {T:.4g})",
                    [p[key]["ours"] for p in per_run],
                    None,
                    mb[key],
                )
            )
        if dim == 3:
            fig, ax = _fig()
            plot.speed_distribution(v[0], temperature=T, ax=ax, label="one run")
            ax.set_title("Fig. 4.7: one equilibrium state (3D)")
            names.append(_save(fig, out, "fig4_7_one_state.png"))
    return names, rows


def _fig_4_8_and_4_10(cfg, out):
    """Haff's law: boundary conditions at xi = 0.8, then xi = 0.99, 0.5, 0.3 with PBC."""
    t = np.linspace(0, cfg.t_long, 201)
    names, rows = [], []
    fig, ax = _fig()
    for label, boundary, wall_e in (
        (dict(BOUNDARY_NAMES)["periodic"], "periodic", 1.0),
        (dict(BOUNDARY_NAMES)["walls"], "walls", 1.0),
        ("reflecting walls, wall restitution 0.8", "walls", 0.8),
    ):
        eq = equilibrium_scene(cfg, boundary=boundary)
        s = eq.replace(restitution=0.8, wall_restitution=wall_e)
        r = _checked_ensemble(
            s,
            cfg.runs_few,
            seed=8,
            backend=cfg.backend,
            t_stop=t[-1],
            sample_times=t,
            quantities=("temperature",),
        )
        ax.plot(t[1:], r.mean["temperature"][1:], label=label)
        T0 = eq.temperature
    c = theory.langevin_coefficients(
        n=cfg.n3, radius=cfg.r3, volume=1.0, restitution=0.8, temperature0=T0
    )
    ax.plot(
        t[1:],
        theory.haff_temperature(t[1:], temperature0=T0, tau0=c.tau0),
        "k--",
        label="Haff, [G20] eq. 2.40",
    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(plot.TIME)
    ax.set_ylabel(plot.TEMPERATURE)
    ax.set_title(r"Fig. 4.8: boundary conditions, $\xi$ = 0.8")
    ax.legend()
    names.append(_save(fig, out, "fig4_8_haff_boundaries.png"))

    eq = equilibrium_scene(cfg)
    fig, axes = _fig(3)
    for ax, xi in zip(axes, (0.99, 0.5, 0.3), strict=True):
        r = _checked_ensemble(
            eq.replace(restitution=xi),
            cfg.runs_few,
            seed=9,
            backend=cfg.backend,
            t_stop=t[-1],
            sample_times=t,
            quantities=("temperature",),
        )
        c = theory.langevin_coefficients(
            n=cfg.n3, radius=cfg.r3, volume=1.0, restitution=xi, temperature0=eq.temperature
        )
        row = _mean_row(
            f"haff.tau0.xi{xi}",
            f"Haff tau0 fitted over t <= {t[-1]:g}, xi = {xi}; theory (2.45)",
            [analysis.fit_haff_tau0(t, run["temperature"])[0] for run in r.runs],
            None,
            c.tau0,
        )
        rows.append(row)
        plot.haff(
            t,
            r.mean["temperature"],
            tau0=c.tau0,
            temperature0=eq.temperature,
            ax=ax,
            error=r.error["temperature"],
            label=rf"EDMD, fit $\tau_0$ = {row['ours']:.3g}",
        )
        ax.set_title(rf"Fig. 4.10: $\xi$ = {xi}")
    names.append(_save(fig, out, "fig4_10_haff_xi.png"))
    return names, rows


def _fig_4_9(cfg, out):
    """2D granular gas (xi = 0.8) at t = 2.5 and 10, PBC vs RBC (TC model t_c = 1e-3 as the
    thesis used against collapse in 2D)."""
    fig, axes = _fig(4, size=(3.6, 3.6))
    k = 0
    for boundary, name in BOUNDARY_NAMES:
        s = Scene.random(
            cfg.n2, cfg.r2, dim=2, boundary=boundary, restitution=0.8, contact_duration=1e-3, seed=3
        )
        sim = Simulation(s)
        for t_snap in (2.5, 10.0):
            with warnings.catch_warnings():
                # the figure shows the clusters that ClusteringWarning foretells (L / L_c ~ 3.6)
                warnings.simplefilter("ignore", ClusteringWarning)
                sim.run(t_stop=t_snap, sample_times=[t_snap], store=())
            plot.snapshot(
                sim.scene.positions, radii=s.radii, lower=s.lower, upper=s.upper, ax=axes[k]
            )
            axes[k].set_title(f"{name}, t = {t_snap:g}", fontsize="medium")
            k += 1
    fig.suptitle(rf"Fig. 4.9: 2D granular gas, $\xi$ = 0.8, N = {cfg.n2}")
    return [_save(fig, out, "fig4_9_clusters_2d.png")], []


# -- 4.1.4: Brownian motion of the EDMD gas ----------------------------------------------------


def _fig_4_11_to_4_16_and_F(cfg, out):
    """MSD (Figs 4.11-4.13), diffusivity (4.14-4.16), linear axes and slopes (F.1-F.2).

    The long-time slopes are fitted over t in [t_long / 10, t_long], against t (xi = 1) or
    ln t (xi = 0.8); theory's slope is the same fit to the theory curve over the same
    window, so the two compare like with like (the asymptotes 6 D0 and 6 D0 tau0, which
    the thesis compared with, are in the quantity text)."""
    t = np.concatenate([[0.0], np.logspace(-2, math.log10(cfg.t_long), 50)])
    window = t >= cfg.t_long / 10
    eq = equilibrium_scene(cfg)
    names, rows = [], []
    figF, axF = _fig(2)
    for xi, fig_msd, fig_d in ((1.0, "4_11", "4_14"), (0.8, "4_12", "4_15"), (0.3, "4_13", "4_16")):
        r = _checked_ensemble(
            eq.replace(restitution=xi),
            cfg.runs_few,
            seed=10,
            backend=cfg.backend,
            t_stop=t[-1],
            sample_times=t,
            quantities=("msd",),
        )
        c = theory.langevin_coefficients(
            n=cfg.n3, radius=cfg.r3, volume=1.0, restitution=xi, temperature0=eq.temperature
        )
        th = theory.msd_granular(t, D0=c.D0, gamma0=c.gamma0, tau0=c.tau0)
        equation = "[G20] eq. 2.68" if xi == 1 else "[G20] eq. 2.79"
        fig, ax = _fig()
        plot.msd(
            t,
            r.mean["msd"],
            error=r.error["msd"],
            theory_values=th,
            ax=ax,
            label=f"EDMD, {len(r.runs)} runs",
            theory_label=equation,
        )
        ax.set_title(f"Fig. {fig_msd.replace('_', '.')}: MSD, " + rf"$\xi$ = {xi:g}")
        names.append(_save(fig, out, f"fig{fig_msd}_msd_xi{xi}.png"))
        fig, ax = _fig()
        dims = [analysis.diffusivity(t, run["msd"]) for run in r.runs]
        dm, _ = analysis.ensemble_mean(dims)
        plot.diffusivity(t, dm, theory_values=c.D0 / (1 + t / c.tau0), ax=ax, label="EDMD")
        ax.set_title(
            f"Fig. {fig_d.replace('_', '.')}: diffusivity, "
            + rf"$\xi$ = {xi:g}; theory $D_0 / (1 + t/\tau_0)$",
            fontsize="medium",
        )
        names.append(_save(fig, out, f"fig{fig_d}_diffusivity_xi{xi}.png"))
        if xi in THESIS_SLOPES:
            log = xi < 1

            def slope(msd, log=log):
                return analysis.fit_slope(t[window], msd[window], log=log)[0]

            measured, thesis_theory = THESIS_SLOPES[xi]
            asymptote = ("6 D0", 6 * c.D0) if xi == 1 else ("6 D0 tau0", 6 * c.D0 * c.tau0)
            quantity = (
                f"slope of the MSD against {'ln t' if log else 't'}, fitted over t in "
                f"[{cfg.t_long / 10:g}, {cfg.t_long:g}]; theory: {equation} fitted the same way "
                f"(its asymptote {asymptote[0]} = {asymptote[1]:.4g}); thesis (N = 1000, App. F): "
                f"measured {measured:.3f}, theory {thesis_theory:.3f}"
            )
            row = _mean_row(
                f"msd.slope.xi{xi:g}",
                quantity,
                [slope(run["msd"]) for run in r.runs],
                None if cfg.quick else measured,
                slope(th),
            )
            rows.append(row)
            ax = axF[0 if xi == 1 else 1]
            plot.msd(
                t,
                r.mean["msd"],
                error=r.error["msd"],
                theory_values=th,
                ax=ax,
                loglog=False,
                label="EDMD",
                theory_label=equation,
            )
            if log:
                ax.set_xscale("log")
            ax.set_title(
                f"Fig. F.{1 if xi == 1 else 2}: slope {row['ours']:.3f} vs theory "
                f"{row['theory']:.3f}"
            )
    names.append(_save(figF, out, "figF_linear_axes.png"))
    return names, rows


# -- 4.2: Langevin models ----------------------------------------------------------------------


def _fig_4_17_to_4_23(cfg, out):
    """Langevin and UDSBM by Euler-Maruyama (4.17-4.20) and ergodicity (4.21-4.23)."""
    names, rows = [], []
    v0_sq = THESIS_T0  # per component: every particle starts at speed sqrt(2), as in the thesis
    coeff = {
        xi: theory.langevin_coefficients(
            n=cfg.n3, radius=cfg.r3, volume=1.0, restitution=xi, temperature0=THESIS_T0
        )
        for xi in (1.0, 0.8, 0.5)
    }
    t_samples = np.concatenate([[0.0], np.logspace(-2, math.log10(cfg.t_long), 50)])

    def run(xi, dt, t_stop, scheme="em", lags=None, samples=t_samples):
        c = coeff[xi]
        samples = np.unique(np.round(np.asarray(samples) / dt)) * dt  # whole steps
        task = functools.partial(
            langevin.run,
            cfg.n3,
            gamma0=c.gamma0,
            D0=c.D0,
            tau0=c.tau0,
            dt=dt,
            t_stop=t_stop,
            scheme=scheme,
            initial="fixed",
            speed=math.sqrt(2.0),
            sample_times=samples,
            tamsd_lags=lags,
            threads=1,  # the ensemble's workers already use every core
        )
        return _checked(ensemble(task, cfg.runs_few, seed=11, backend=cfg.backend))

    def msd_theory(xi, t):
        c = coeff[xi]
        return (
            theory.msd_langevin(t, D0=c.D0, gamma0=c.gamma0, v0_sq=v0_sq)
            if xi == 1
            else theory.msd_udsbm(t, D0=c.D0, gamma0=c.gamma0, tau0=c.tau0, v0_sq=v0_sq)
        )

    for xi, fig_no in ((1.0, "4_17"), (0.8, "4_18"), (0.5, "4_19")):
        r = run(xi, 0.01, cfg.t_long)
        th = msd_theory(xi, r.times)
        model = "Langevin" if xi == 1 else f"UDSBM, xi = {xi}"
        fig, ax = _fig()
        plot.msd(
            r.times,
            r.mean["msd"],
            error=r.error["msd"],
            theory_values=th,
            ax=ax,
            label=r"Euler-Maruyama, $\Delta t$ = 0.01",
            theory_label="[G20] eq. 2.68" if xi == 1 else "[G20] eq. 2.113, initial speed √2",
        )
        ax.set_title(
            f"Fig. {fig_no.replace('_', '.')}: "
            + ("Langevin" if xi == 1 else rf"UDSBM, $\xi$ = {xi}")
        )
        names.append(_save(fig, out, f"fig{fig_no}_sde_msd_xi{xi}.png"))
        rows.append(
            _mean_row(
                f"sde.msd.xi{xi:g}",
                f"{model}: MSD at t = {r.times[-1]:g}, Euler-Maruyama "
                f"dt = 0.01; theory {'(2.68)' if xi == 1 else '(2.113)'} with the initial "
                "speed sqrt(2)",
                [run_["msd"][-1] for run_ in r.runs],
                None,
                th[-1],
            )
        )

    fig, ax = _fig()
    c = coeff[0.8]
    for dt in (0.01, 0.1, 1.0):
        stable = c.gamma0 * dt < 2  # Euler-Maruyama's stability limit
        r = run(0.8, dt, cfg.t_long, scheme="em" if stable else "exact")
        ax.plot(
            r.times[1:],
            r.mean["msd"][1:],
            "o-",
            ms=3,
            label=rf"$\Delta t$ = {dt} ("
            + (
                "Euler-Maruyama"
                if stable
                else "exact: Euler-Maruyama "
                rf"diverges, $\gamma_0 \Delta t$ = {c.gamma0 * dt:.1f}"
            )
            + ")",
        )
    ax.plot(t_samples[1:], msd_theory(0.8, t_samples[1:]), "k--", label="theory, [G20] eq. 2.113")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(plot.TIME)
    ax.set_ylabel(plot.MSD)
    ax.set_title(r"Fig. 4.20: UDSBM $\xi$ = 0.8, time steps")
    ax.legend(fontsize=7)
    names.append(_save(fig, out, "fig4_20_dt_sweep.png"))

    lag_ref = 10.0 if not cfg.quick else 2.0

    def ergodicity(xi, t_stop):
        lags = np.unique(np.round(np.logspace(-2, math.log10(t_stop / 2), 24), 2))
        if lag_ref <= t_stop / 2:
            lags = np.unique(np.append(lags, lag_ref))
        r = run(
            xi,
            0.01,
            t_stop,
            lags=lags,
            samples=np.unique(np.append(t_samples[t_samples <= t_stop], lags)),
        )
        lags = r.mean["tamsd_lags"]
        c = coeff[xi]
        tamsd_th = langevin.theory_tamsd(
            lags, gamma0=c.gamma0, D0=c.D0, tau0=c.tau0, dt=0.01, t_stop=t_stop, v0_sq=v0_sq
        )
        return r, lags, tamsd_th

    def ratio_row(label, xi, r, lags, tamsd_th):
        k_lag = int(np.argmin(np.abs(lags - lag_ref)))
        k_t = int(np.argmin(np.abs(r.times - lag_ref)))
        ratios = [run_["tamsd"][k_lag] / run_["msd"][k_t] for run_ in r.runs]
        return _mean_row(
            f"ergodicity.{label}",
            f"TAMSD / MSD at lag = t = {lag_ref:g}, t_stop = "
            f"{r.times[-1]:g}, {label} (xi = {xi:g}), Euler-Maruyama dt = 0.01; theory: expected "
            "time average / ensemble MSD",
            ratios,
            None,
            tamsd_th[k_lag] / msd_theory(xi, lag_ref),
        )

    udsbm = {t_stop: ergodicity(0.8, t_stop) for t_stop in cfg.tamsd_t_stops}
    for label, xi, (r, lags, tamsd_th), fig_no in (
        ("langevin", 1.0, ergodicity(1.0, cfg.t_long), "4_21"),
        ("udsbm", 0.8, udsbm[cfg.t_long], "4_22"),
    ):
        fig, ax = _fig()
        plot.msd_vs_tamsd(r.times, r.mean["msd"], lags=lags, tamsd_values=r.mean["tamsd"], ax=ax)
        ax.plot(lags, tamsd_th, "k--", lw=1, label="time-averaged MSD, theory")
        ax.legend()
        ax.set_title(
            f"Fig. {fig_no.replace('_', '.')}: "
            + ("Langevin" if xi == 1 else rf"UDSBM, $\xi$ = {xi}")
            + rf", $t_{{stop}}$ = {cfg.t_long:g}"
        )
        names.append(_save(fig, out, f"fig{fig_no}_ergodicity_{label}_t{cfg.t_long:g}.png"))
        rows.append(ratio_row(label, xi, r, lags, tamsd_th))

    fig, ax = _fig()
    longest = udsbm[max(cfg.tamsd_t_stops)][0]
    keep = longest.times > 0
    ax.plot(longest.times[keep], longest.mean["msd"][keep], "k-", label="ensemble MSD")
    for i, (t_stop, (r, lags, tamsd_th)) in enumerate(sorted(udsbm.items())):
        ax.plot(
            lags,
            r.mean["tamsd"],
            "o",
            ms=3,
            color=f"C{i}",
            label=rf"time-averaged MSD, $t_{{stop}}$ = {t_stop:g}",
        )
        ax.plot(lags, tamsd_th, "--", lw=1, color=f"C{i}")
    ax.plot([], [], "--", lw=1, color="0.4", label="time-averaged MSD, theory")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(plot.LAG_OR_TIME)
    ax.set_ylabel(plot.MSD_AND_TAMSD)
    ax.legend(fontsize=7)
    ax.set_title(r"Fig. 4.23: UDSBM, $\xi$ = 0.8, against $t_{stop}$")
    names.append(_save(fig, out, "fig4_23_ergodicity_udsbm_tstop.png"))
    return names, rows


def _tools():
    """What the experiments in their own modules (reproduce_clustering, reproduce_visco)
    take from this one: ensembles in this process (threads: their warnings can be
    silenced, and results do not depend on the backend), figures and rows."""
    return dict(
        ensemble=functools.partial(_checked_ensemble, backend="threads"),
        save=_save,
        fig=_fig,
        row=_row,
        mean_row=_mean_row,
    )


def _fig_clustering(cfg, out):
    """Where homogeneous cooling ends: see ``reproduce_clustering``."""
    from . import reproduce_clustering

    # its big box lies beyond L_c on purpose: silence the warning, which needs the runs in
    # this process (threads; the C core releases the GIL, and results do not depend on the
    # backend)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClusteringWarning)
        return reproduce_clustering._fig_clustering(cfg, out, **_tools())


def _fig_visco(cfg, out):
    """Viscoelastic gases: see ``reproduce_visco``."""
    from . import reproduce_visco

    return reproduce_visco._fig_visco(cfg, out, **_tools())


def _fig_transport(cfg, out):
    """Elastic hard-sphere viscosity and self-diffusion: see ``reproduce_transport``."""
    from . import reproduce_transport

    return reproduce_transport._fig_transport(cfg, out, **_tools())


def _fig_langevin_forces(cfg, out):
    """External forces in the Langevin model: see ``reproduce_langevin_forces``."""
    from . import reproduce_langevin_forces

    return reproduce_langevin_forces._fig_langevin_forces(cfg, out, **_tools())


def _fig_driven(cfg, out):
    """Velocity distributions of cooling and driven gases: see ``reproduce_driven``."""
    from . import reproduce_driven

    return reproduce_driven._fig_driven(cfg, out, **_tools())


def _fig_rough(cfg, out):
    """Rough spheres: see ``reproduce_rough``."""
    from . import reproduce_rough

    return reproduce_rough._fig_rough(cfg, out, **_tools())


def _fig_vibrated(cfg, out):
    """A gas kept hot by a vibrating wall: see ``reproduce_vibrated``."""
    from . import reproduce_vibrated

    return reproduce_vibrated._fig_vibrated(cfg, out, **_tools())


def _fig_gravity(cfg, out):
    """An elastic gas under gravity against its hydrostatic profile: see
    ``reproduce_gravity``."""
    from . import reproduce_gravity

    return reproduce_gravity._fig_gravity(cfg, out, **_tools())


def _fig_shear(cfg, out):
    """Uniform shear flow of the inelastic gas: see ``reproduce_shear``."""
    from . import reproduce_shear

    return reproduce_shear._fig_shear(cfg, out, **_tools())


FIGURES = {
    "4.1": _fig_4_1,
    "4.2-4.4": _fig_4_2_to_4_4,
    "4.5-4.7": _fig_4_5_to_4_7,
    "4.8+4.10": _fig_4_8_and_4_10,
    "4.9": _fig_4_9,
    "4.11-4.16+F": _fig_4_11_to_4_16_and_F,
    "4.17-4.23": _fig_4_17_to_4_23,
    "clustering": _fig_clustering,
    "viscoelastic": _fig_visco,
    "transport": _fig_transport,
    "langevin-forces": _fig_langevin_forces,
    "driven": _fig_driven,
    "rough": _fig_rough,
    "vibrated": _fig_vibrated,
    "gravity": _fig_gravity,
    "shear": _fig_shear,
}

# What each experiment shows (``--help`` lists them), and its wall time in seconds on the
# reference machine, at the thesis' sizes and with ``quick``: one run each on a 2-core virtual
# machine shared with other work -- the full run's first six experiments at a load average
# below 2.5, its last three near 5; the quick run at 7-8.5.  Before each experiment the
# progress line scales its time by how much slower or faster the ones done so far ran.
ABOUT: dict[str, tuple[str, float, float]] = {
    "4.1": ("a head-on collision of two disks between walls", 0.7, 1.6),
    "4.2-4.4": ("energy and collisions per particle, periodic and wall boxes", 4.1, 4.4),
    "4.5-4.7": ("speeds in 2D and 3D against Maxwell-Boltzmann (Table 4.1)", 24.5, 4.4),
    "4.8+4.10": ("Haff's law: three boundaries at xi = 0.8, then xi = 0.99, 0.5, 0.3", 7.6, 8.3),
    "4.9": ("2D granular gas at t = 2.5 and 10: clusters in periodic and wall boxes", 0.4, 3.2),
    "4.11-4.16+F": ("MSD, diffusivity and long-time slopes of the EDMD gas", 13.9, 19.1),
    "4.17-4.23": ("Langevin and UDSBM: time steps, ergodicity (TAMSD against MSD)", 131.0, 22.0),
    "clustering": ("where homogeneous cooling ends: three boxes around L_c", 18.9, 18.8),
    "viscoelastic": ("viscoelastic gas: cooling, MSD, power-law UDSBM, no collapse", 20.4, 15.9),
    "transport": (
        "elastic hard spheres: Green-Kubo, NEMD viscosity; diffusion; equation of state",
        130.0,
        25.0,
    ),
    "langevin-forces": ("Langevin model in a harmonic trap: MSD plateau, EM's limit", 20.0, 8.0),
    "driven": ("a2 of cooling and white-noise driven gases, driven temperature", 101.6, 18.7),
    "rough": (
        "rough spheres: T_rot / T_tr against beta, coupled cooling, Walton's rule",
        31.0,
        9.2,
    ),
    "vibrated": ("a gas and a bed under gravity on a vibrating wall: T against V", 35.0, 14.0),
    "gravity": ("elastic disks under gravity: the hydrostatic density profile", 60.0, 25.0),
    "shear": ("uniform shear flow of the inelastic gas: steady state, stresses", 15.0, 5.0),
}


def _run(name, cfg, out):
    if name not in FIGURES:
        raise ValueError(f"unknown experiment {name!r}; choose from {', '.join(FIGURES)}")
    os.makedirs(out, exist_ok=True)
    return FIGURES[name](cfg, out)


def figure(name, quick=False, out="granular-reproduce", runs=None, backend=None):
    """Run one experiment of ``FIGURES`` (e.g. ``"4.8+4.10"``) at the thesis' sizes or, with
    ``quick``, small ones; write its PNG files into ``out``.

    Parameters
    ----------
    name : str
        The experiment, a key of ``FIGURES``.
    quick : bool
        Small systems over short times, ``QUICK_RUNS`` runs each.
    out : str
        The folder the PNG files are written into (made if missing).
    runs : int, optional
        Runs per experiment (default: five times the thesis' count, or ``QUICK_RUNS``).
    backend : str or distributed.Client, optional
        The ensembles' backend (``granular.ensemble``).

    Returns
    -------
    (list of str, list of dict)
        The paths of the files written and the experiment's rows for ``summary.json`` (see
        the module docstring).
    """
    names, rows = _run(name, Config(quick=quick, runs=runs, backend=backend), out)
    return [os.path.join(out, n) for n in names], rows


def _selected(only):
    """The experiments to run, in the thesis' order: all, or those named in ``only``."""
    if only is None:
        return list(FIGURES)
    only = [only] if isinstance(only, str) else list(only)
    unknown = [name for name in only if name not in FIGURES]
    if unknown or not only:
        raise ValueError(
            f"unknown experiment {', '.join(map(repr, unknown)) or '(none given)'}; "
            f"choose from {', '.join(FIGURES)}"
        )
    return [name for name in FIGURES if name in only]


def _pace(seconds_done, reference_done):
    """How much slower than the reference this machine runs: the wall time of the
    experiments done over their reference time, once that is long enough (5 s) to say;
    1 before."""
    return seconds_done / reference_done if reference_done >= 5.0 else 1.0


def _progress(i, count, name, cfg, pace=1.0):
    """The line said before experiment ``name`` starts (to stderr: stdout keeps the results):
    what it shows and its reference time (``ABOUT``) times the ``pace`` so far."""
    what, full, quick = ABOUT[name]
    reference = quick if cfg.quick else full
    how = (
        "the reference machine's time"
        if pace == 1.0
        else f"{reference:g} s on the reference machine x {pace:.2g}, the pace so far"
    )
    runs = "" if cfg.runs_given is None else ", at the default run counts"
    return f"[{i}/{count}] {name}: {what} (expected ~{reference * pace:.0f} s: {how}{runs})"


def main(out="granular-reproduce", quick=False, runs=None, backend=None, only=None):
    """The experiments of ``FIGURES`` (all, or those in ``only``), then ``summary.json`` and
    ``report.md`` in ``out``; says each experiment before it starts and its time after.

    Parameters
    ----------
    out : str
        The output folder (made if missing).
    quick : bool
        Small systems over short times, ``QUICK_RUNS`` runs each.
    runs : int, optional
        Runs per experiment (default: five times the thesis' count, or ``QUICK_RUNS``).
    backend : str or distributed.Client, optional
        The ensembles' backend (``granular.ensemble``).
    only : str or list of str, optional
        Run only these experiments (keys of ``FIGURES``); an unknown name raises ValueError
        listing the valid ones, before anything runs.

    Returns
    -------
    list of dict
        The rows of ``summary.json``.
    """
    selected = _selected(only)
    import matplotlib

    matplotlib.use("Agg")
    cfg = Config(quick=quick, runs=runs, backend=backend)
    started = time.perf_counter()
    reference = {name: ABOUT[name][2] if quick else ABOUT[name][1] for name in selected}
    print(
        f"reproducing {len(selected)} experiment(s) into {out}/: ~{sum(reference.values()):.0f} s "
        "on the reference machine (2 cores), longer on a busy one",
        file=sys.stderr,
        flush=True,
    )
    names, rows = [], []
    seconds_done = reference_done = 0.0
    for i, name in enumerate(selected, 1):
        pace = _pace(seconds_done, reference_done)
        print(_progress(i, len(selected), name, cfg, pace), file=sys.stderr, flush=True)
        t0 = time.perf_counter()
        n, r = _run(name, cfg, out)
        names += n
        rows += r
        seconds = time.perf_counter() - t0
        seconds_done += seconds
        reference_done += reference[name]
        print(f"  Fig. {name:<12} {seconds:6.1f} s  {', '.join(n)}", flush=True)
    write_json(os.path.join(out, "summary.json"), rows)
    with open(os.path.join(out, "report.md"), "w") as f:
        f.write(report(rows, cfg, names, time.perf_counter() - started))
    print(
        f"reproduced {len(names)} figures, {len(rows)} summary rows in {out}/ "
        f"({time.perf_counter() - started:.0f} s)"
    )
    return rows
