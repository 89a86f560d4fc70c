"""Speed against accuracy, and where each method fails
(``python -m granular bench --speed-accuracy --out DIR``).

Target: the MSD of a granular gas (xi = 0.8), of a molecular gas and of a viscoelastic gas
(``viscoelastic_points``: EDMD against power-law UDSBM, a = 5/6) in the thesis' standard box
(N = 1000, r = 0.025, unit box, T0 = 2/3) at log-spaced times in [1e-2, 1e2].

Error measures (each point measured, none modelled):
- ``msd_error``: the largest relative deviation of the MSD from the reference over the
  log-spaced sample times, ``max_t |MSD(t) / MSD_ref(t) - 1|`` (for an SDE step dt, at its
  sample times rounded to whole steps, t >= dt: it cannot answer below one step; the
  reference is interpolated log-log between its samples);
- ``slope_error``: relative error of the long-time slope (MSD against t for the molecular
  gas, against ln t for the granular gas, fitted over t in [10, 100]).
The reference is a high-statistics EDMD ensemble; errors against theory ((2.68), (2.79))
are reported beside.

Cost (``seconds``) is CPU-seconds of this process (``time.process_time``), every method
run serially on one thread, so EDMD and the SDE schemes are charged alike and other load
on the machine does not inflate them.  An EDMD point's cost includes equilibrating its
start (10 collisions per particle from a random placement): the question needs it.  One
equilibrated state serves all runs of a point (velocities shuffled per run, thesis 3.8),
so it is paid once per point, not once per run; the two gases of the same (N, runs)
start from the same state, computed once but charged in full to each point.  The SDE
runs need no equilibration: they draw the stationary Gaussian velocities directly.

The steady states' transport coefficients (``speed_accuracy_transport``): a white-noise
driven granular gas' self-diffusion by EDMD against the Langevin model with the matching
friction and noise, and the elastic fluid's shear viscosity by Green-Kubo against NEMD.

Where methods fail: Euler-Maruyama's MSD error against gamma0*dt up to and past its
stability limit (refused at gamma0*dt >= 2) beside the exact scheme; inelastic collapse of
2D disks between walls over restitution and area fraction, with and without the TC
model, and with the viscoelastic law of the same mean restitution; the cost of EDMD per
unit time as the packing approaches the dense limit.
"""

from __future__ import annotations

import functools
import itertools
import math
import os
import time
import warnings

import numpy as np

from .. import (
    InelasticCollapseError,
    Scene,
    Simulation,
    UnstableStepError,
    Viscoelastic,
    analysis,
    ensemble,
    langevin,
    theory,
)
from ..restitution import matched_viscoelastic
from ..simulation import _LIST_SHELL  # the shell of shell="auto": dense_cost measures it
from . import speed_accuracy_transport
from .bench_langevin import log_lags
from .output import write_json

T0 = 2.0 / 3.0
R = 0.025
clock = time.process_time  # CPU-seconds of this process: every cost below is measured so


def _times(t_max):
    return np.concatenate([[0.0], np.logspace(-2, math.log10(t_max), 25)])


def _loglog_interp(t, t_ref, y_ref):
    """A smooth curve (the MSD) at other times: linear interpolation in log-log."""
    ok = t_ref > 0
    return np.exp(np.interp(np.log(t), np.log(t_ref[ok]), np.log(y_ref[ok])))


def _errors(times, msd, t_ref, ref, slope_ref, log, t_fit):
    """Errors at the method's own sample times (a step dt cannot answer below dt)."""
    ok = times > 0
    sel = times >= t_fit
    slope = analysis.fit_slope(times[sel], msd[sel], log=log)[0]
    ref_at = _loglog_interp(times[ok], t_ref, ref)
    return float(np.max(np.abs(msd[ok] / ref_at - 1))), float(abs(slope / slope_ref - 1))


@functools.cache
def _equilibrated(n, seed):
    """N particles at the standard density (box scaled), equilibrated at T0, and the CPU
    seconds that took (cached: both gases start from the same state)."""
    t0 = clock()
    sim = Simulation(Scene.random(n, R, box=(n / 1000) ** (1 / 3), temperature=T0, seed=seed))
    sim.run(stop_when={"collisions_per_particle": 10}, store=())
    return sim.scene, clock() - t0


def _edmd_msd(n, xi, runs, times, seed):
    """Mean MSD of `runs` serial EDMD runs of N particles from one equilibrated start, and
    the CPU seconds of the runs plus the equilibration."""
    start, equilibration = _equilibrated(n, seed)
    t0 = clock()
    res = ensemble(
        start.replace(restitution=xi),
        runs,
        seed=seed,
        backend="serial",
        t_stop=times[-1],
        sample_times=times,
        quantities=("msd",),
        progress=False,
    )
    return res.mean["msd"], equilibration + clock() - t0


def speed_accuracy_points(quick=False):
    """All points of the chart: EDMD (N, runs), EM and exact SDE schemes (dt).

    Euler-Maruyama runs at fixed steps (1e-3 to 0.1) and at gamma0*dt = 1.5 and 1.9 of
    each gas, approaching its stability limit 2; the exact scheme at the same steps and
    past the limit, gamma0*dt = 3 and 10 (quick: dt = 0.01, gamma0*dt = 1.9 and 3)."""
    t_max = 100.0 if not quick else 10.0
    t_fit = t_max / 10
    times = _times(t_max)
    ref_runs = 32 if not quick else 4
    points, refs = [], {}
    for xi in (1.0, 0.8):
        c = theory.langevin_coefficients(
            n=1000, radius=R, volume=1.0, restitution=xi, temperature0=T0
        )
        th = np.asarray(theory.msd_granular(times, D0=c.D0, gamma0=c.gamma0, tau0=c.tau0))
        ref, ref_cost = _edmd_msd(1000, xi, ref_runs, times, seed=99)
        log = xi < 1
        sel = times >= t_fit
        slope_ref = analysis.fit_slope(times[sel], ref[sel], log=log)[0]
        refs[xi] = dict(
            times=times.tolist(),
            msd=ref.tolist(),
            theory=th.tolist(),
            runs=ref_runs,
            seconds=ref_cost,
            slope=slope_ref,
        )
        slope_th = analysis.fit_slope(times[sel], th[sel], log=log)[0]

        # this iteration's reference and theory bound as defaults, not looked up at call time
        def add(
            method,
            label,
            msd,
            seconds,
            at=times,
            *,
            xi=xi,
            ref=ref,
            slope_ref=slope_ref,
            th=th,
            slope_th=slope_th,
            log=log,
            **extra,
        ):
            e_ref, s_ref = _errors(at, msd, times, ref, slope_ref, log, t_fit)
            e_th, s_th = _errors(at, msd, times, th, slope_th, log, t_fit)
            points.append(
                dict(
                    gas="molecular" if xi == 1 else "granular",
                    xi=xi,
                    method=method,
                    label=label,
                    seconds=seconds,
                    msd_error=e_ref,
                    slope_error=s_ref,
                    msd_error_theory=e_th,
                    slope_error_theory=s_th,
                    **extra,
                )
            )

        sizes = (
            [(250, 1), (250, 4), (1000, 1), (1000, 4), (4000, 1)]
            if not quick
            else [(125, 1), (250, 2)]
        )
        for n, runs in sizes:
            msd, sec = _edmd_msd(n, xi, runs, times, seed=n + runs)
            add("edmd", f"N={n}, runs={runs}", msd, sec, n=n, runs=runs)
        n_sde = 4000 if not quick else 500
        fixed = [1e-3, 1e-2, 0.05, 0.1] if not quick else [1e-2]
        near, beyond = ((1.5, 1.9), (3.0, 10.0)) if not quick else ((1.9,), (3.0,))
        em_dts = fixed + [g / c.gamma0 for g in near]
        exact_dts = em_dts + [g / c.gamma0 for g in beyond]
        _sde_points(add, c, n_sde, {"em": em_dts, "exact": exact_dts}, t_max, times)
    return points, refs


# The viscoelastic gas of the chart: the thesis' standard gas with the law whose eps is 0.9
# at the rms normal impact speed of colliding pairs, sqrt(4 T0 / m) (delta(T0) = 0.09).
VISCO_EPS, VISCO_A = 0.9, 5.0 / 6.0


def viscoelastic_points(quick=False):
    """The viscoelastic gas (``VISCO_EPS`` law) by EDMD (N, runs) against power-law UDSBM
    (a = 5/6, ``theory.viscoelastic_langevin_coefficients``), both schemes, against an
    EDMD reference.  ``slope_error`` here is the relative error of the late exponent
    d ln MSD / d ln t over t in [t_max / 10, t_max] (it tends to 1/6 only as t -> inf).
    Theory's MSD (``theory.msd_viscoelastic``) is reported beside, not used as the
    reference: it misses the ballistic start and Enskog's D0 sits below EDMD's."""
    t_max = 100.0 if not quick else 10.0
    t_fit = t_max / 10
    times = _times(t_max)
    law = Viscoelastic.from_restitution(VISCO_EPS, math.sqrt(4 * T0))
    c = theory.viscoelastic_langevin_coefficients(
        n=1000, radius=R, volume=1.0, a_kappa=law.a_kappa, temperature0=T0
    )
    ref_runs = 64 if not quick else 4
    ref, ref_cost = _edmd_msd(1000, law, ref_runs, times, seed=99)
    th = np.asarray(theory.msd_viscoelastic(times, D0=c.D0, tau0=c.tau0))
    # the late exponent d ln MSD / d ln t, fitted over t >= t_fit
    slope_ref = analysis.fit_power_law(times, ref, t_min=t_fit)[0]
    slope_th = analysis.fit_power_law(times, th, t_min=t_fit)[0]
    ref_info = dict(
        times=times.tolist(),
        msd=ref.tolist(),
        theory=th.tolist(),
        runs=ref_runs,
        seconds=ref_cost,
        slope=slope_ref,
        law=repr(law),
        a_kappa=law.a_kappa,
        tau0=c.tau0,
    )
    points = []

    def add(method, label, msd, seconds, at=times, **extra):
        ok = at > 0
        e_ref = float(np.max(np.abs(msd[ok] / _loglog_interp(at[ok], times, ref) - 1)))
        th_at = theory.msd_viscoelastic(at[ok], D0=c.D0, tau0=c.tau0)
        slope = analysis.fit_power_law(at, msd, t_min=t_fit)[0]
        points.append(
            dict(
                gas="viscoelastic",
                xi=None,
                method=method,
                label=label,
                seconds=seconds,
                msd_error=e_ref,
                slope_error=abs(slope / slope_ref - 1),
                msd_error_theory=float(np.max(np.abs(msd[ok] / th_at - 1))),
                slope_error_theory=abs(slope / slope_th - 1),
                **extra,
            )
        )

    for n, runs in [(250, 1), (1000, 1), (1000, 4), (4000, 1)] if not quick else [(125, 1)]:
        msd, sec = _edmd_msd(n, law, runs, times, seed=n + runs)
        add("edmd", f"N={n}, runs={runs}", msd, sec, n=n, runs=runs)
    n_sde = 4000 if not quick else 500
    dts = ([1e-2, 0.05, 0.1] if not quick else [1e-2]) + [1.9 / c.gamma0]
    _sde_points(add, c, n_sde, {"em": dts, "exact": dts}, t_max, times, VISCO_A, "UDSBM a=5/6")
    return points, ref_info


def em_stability(quick=False):
    """MSD error of Euler-Maruyama and of the exact scheme against the Langevin theory as
    gamma0*dt grows, for the molecular gas' coefficients; EM refused at >= 2."""
    c = theory.langevin_coefficients(n=1000, radius=R, volume=1.0, restitution=1.0, temperature0=T0)
    n = 20000 if not quick else 2000
    t_max = 20.0 if not quick else 5.0
    rows = []
    for gdt in (0.01, 0.05, 0.1, 0.3, 0.5, 1.0, 1.5, 1.9, 2.0, 3.0, 10.0):
        dt = gdt / c.gamma0
        times = np.unique(np.round(np.logspace(math.log10(dt), math.log10(t_max), 20) / dt)) * dt
        th = np.asarray(theory.msd_langevin(times, D0=c.D0, gamma0=c.gamma0))
        row: dict[str, float | None] = dict(gamma_dt=gdt, dt=dt)
        for scheme in ("em", "exact"):
            try:
                r = langevin.run(
                    n,
                    gamma0=c.gamma0,
                    D0=c.D0,
                    dt=dt,
                    t_stop=t_max,
                    scheme=scheme,
                    sample_times=times,
                    seed=1,
                )
                ok = r.times > 0
                row[scheme] = float(np.max(np.abs(r.msd()[ok] / th[ok] - 1)))
                row[f"{scheme}_v2_bias"] = float(r.v2[-1] / (3 * c.gamma0 * c.D0) - 1)
            except UnstableStepError:
                row[scheme] = None
                row[f"{scheme}_v2_bias"] = None
        rows.append(row)
    return rows


# The collapse map's goal: at 100 collisions per particle constant xi = 0.8 does not yet
# collapse anywhere, at 400 it does in the dense cells -- where the viscoelastic law of the
# same mean restitution (the lowest xi it can match) is put to the test.
COLLAPSE_GOAL = 400


def collapse_map(
    quick=False, contact_durations=(0.0, 1e-4), events_per_particle=4000, viscoelastic=True
):
    """2D disks between walls (where the thesis met collapse): for each restitution and area
    fraction, run to ``COLLAPSE_GOAL`` collisions per particle (bounded by a budget of
    ``events_per_particle`` events per particle) and record 'collapse' (with time and
    particles), 'budget' (the budget ran out first: the run did not reach its goal), 'tc'
    (it did, with the TC model acting) or 'ok'.  Cells carry ``law``: "constant" (xi) or,
    with ``viscoelastic``, "viscoelastic": the same scenes (no TC model) with the law of
    the same mean restitution (``matched_viscoelastic``), or status 'n/a' where the law
    cannot represent that xi."""
    n = 500 if not quick else 150
    xis = (0.9, 0.8, 0.7, 0.5, 0.3, 0.1) if not quick else (0.9, 0.3)
    etas = (0.05, 0.2, 0.4, 0.6, 0.7) if not quick else (0.1, 0.5)
    cases = [("constant", tc) for tc in contact_durations]
    if viscoelastic:
        cases.append(("viscoelastic", 0.0))
    cells = []
    for law_kind, tc in cases:
        for eta in etas:
            r = math.sqrt(eta / (n * math.pi))
            for xi in xis:
                s = Scene.random(
                    n, r, dim=2, boundary="walls", restitution=xi, contact_duration=tc, seed=1
                )
                cell = dict(law=law_kind, contact_duration=tc, eta=eta, xi=xi)
                if law_kind == "viscoelastic":
                    law, info = matched_viscoelastic(xi, s.temperature)
                    cell.update(info)
                    if law is None:
                        cell.update(status="n/a", seconds=0.0)
                        cells.append(cell)
                        continue
                    s = s.replace(restitution=law)
                sim = Simulation(s)
                t0 = clock()
                try:
                    goal = {
                        "collisions_per_particle": COLLAPSE_GOAL,
                        "events": events_per_particle * n,
                    }
                    with warnings.catch_warnings():
                        # a hot start's few collisions past the law's range: counted below
                        warnings.simplefilter("ignore", RuntimeWarning)
                        tr = sim.run(stop_when=goal, store=())
                    status = (
                        "budget"
                        if tr.stop_reason == "events"
                        else "tc"
                        if sim.stats["tc_elastic_collisions"]
                        else "ok"
                    )
                    cell.update(status=status, stop=tr.stop_reason)
                except InelasticCollapseError as e:
                    cell.update(status="collapse", time=e.time, particles=list(e.particles))
                cell.update(
                    seconds=clock() - t0,
                    tc_elastic_collisions=sim.stats["tc_elastic_collisions"],
                    law_clamped_collisions=sim.stats["law_clamped_collisions"],
                    pair_collisions=sim.stats["pair_collisions"],
                    collisions_per_particle=sim.stats["collisions_per_particle"],
                )
                cells.append(cell)
    return cells


def dense_cost(quick=False):
    """EDMD cost per unit of simulated time (and per collision) as the packing grows; in
    3D with cells and with neighbour lists (the shell Simulation's shell="auto" uses),
    the evidence for where "auto" switches."""
    rows = []
    cases = [
        (3, (0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 0.55, 0.6), (0.0, _LIST_SHELL)),
        (2, (0.1, 0.3, 0.5, 0.6, 0.7, 0.8), (0.0,)),
    ]
    for dim, etas, shells in cases:
        # a full face-centred cubic lattice (4 k^3 sites) reaches the densest 3D cases
        n = (2048 if dim == 3 else 2000) if not quick else (256 if dim == 3 else 300)
        if quick:
            etas = (etas[0], etas[-1])  # the dilute and the densest case
        for eta, shell in itertools.product(etas, shells):
            r = (
                (eta / (n * 4 / 3 * math.pi)) ** (1 / 3)
                if dim == 3
                else math.sqrt(eta / (n * math.pi))
            )
            sim = Simulation(Scene.random(n, r, dim=dim, temperature=1.0, seed=2), shell=shell)
            sim.run(stop_when={"collisions_per_particle": 5}, store=())
            b = sim.stats
            t0 = clock()
            sim.run(stop_when={"collisions_per_particle": 5 + (50 if not quick else 5)}, store=())
            sec = clock() - t0
            a = sim.stats
            pairs = a["pair_collisions"] - b["pair_collisions"]
            rows.append(
                dict(
                    dim=dim,
                    eta=eta,
                    n=n,
                    shell=shell,
                    seconds_per_time=sec / (a["time"] - b["time"]),
                    ns_per_collision=1e9 * sec / pairs,
                    collisions_per_particle_per_time=2 * pairs / n / (a["time"] - b["time"]),
                )
            )
    return rows


def scene_costs(quick=False):
    """What modelling choices cost, measured: 2D vs 3D, walls vs periodic, small N, a large
    tracer kept out of the cell grid or not, and storing trajectories vs accumulating
    statistics."""
    rows = []
    coll = 100.0 if not quick else 10.0

    def per_collision(scene, big_ratio=3.0, **run):
        sim = Simulation(scene, big_ratio=big_ratio)
        sim.run(stop_when={"collisions_per_particle": 5}, store=())
        b = sim.stats
        t0 = clock()
        sim.run(stop_when={"collisions_per_particle": 5 + coll}, store=(), **run)
        sec = clock() - t0
        return 1e9 * sec / (sim.stats["pair_collisions"] - b["pair_collisions"])

    n = 2000
    rows.append(
        dict(
            case="3D periodic, eta 0.1",
            ns_per_collision=per_collision(
                Scene.random(n, (0.1 / (n * 4 / 3 * math.pi)) ** (1 / 3), seed=1)
            ),
        )
    )
    rows.append(
        dict(
            case="2D periodic, eta 0.1",
            ns_per_collision=per_collision(
                Scene.random(n, math.sqrt(0.1 / (n * math.pi)), dim=2, seed=1)
            ),
        )
    )
    rows.append(
        dict(
            case="3D walls, eta 0.1",
            ns_per_collision=per_collision(
                Scene.random(n, (0.1 / (n * 4 / 3 * math.pi)) ** (1 / 3), boundary="walls", seed=1)
            ),
        )
    )
    for small in (20, 100):
        rows.append(
            dict(
                case=f"3D periodic, eta 0.1, N = {small}",
                ns_per_collision=per_collision(
                    Scene.random(small, (0.1 / (small * 4 / 3 * math.pi)) ** (1 / 3), seed=1)
                ),
            )
        )
    # one tracer of radius 0.1 among spheres of radius 0.008 (eta 0.065 in all)
    small = 2000 if not quick else 500
    r_small = ((0.065 - 4 / 3 * math.pi * 0.1**3) / (small * 4 / 3 * math.pi)) ** (1 / 3)
    radii = np.r_[0.1, np.full(small, r_small)]
    tracer = Scene.random(small + 1, radii, mass=(radii / r_small) ** 3, seed=1)
    for big_ratio, how in (
        (3.0, "kept out of the cell grid"),
        (math.inf, "in cells as wide as it"),
    ):
        rows.append(
            dict(
                case=f"3D, one tracer {0.1 / r_small:.1f}x wider than {small} others, {how}",
                ns_per_collision=per_collision(tracer, big_ratio=big_ratio),
            )
        )
    s = Scene.random(1000, R, seed=1)
    for store in ((), ("positions", "velocities")):
        sim = Simulation(s)
        t0 = clock()
        tr = sim.run(t_stop=10.0, sample_times=np.linspace(0, 10, 1001), store=store)
        sec = clock() - t0
        mb = sum(a.nbytes for a in (tr.positions, tr.velocities) if a is not None) / 2**20
        rows.append(
            dict(
                case=f"1000 samples, store={store or 'statistics only'}",
                seconds=sec,
                stored_megabytes=mb,
            )
        )
    for lags in (0, 30):
        t0 = clock()
        r = langevin.run(
            1000,
            gamma0=9.26,
            D0=0.072,
            dt=0.01,
            t_stop=100.0 if not quick else 10.0,
            tamsd_lags=log_lags(lags, 10.0, 0.01) if lags else None,
            scheme="em",
            seed=1,
        )
        rows.append(
            dict(
                case=f"Langevin EM, N = 1000, {len(r.tamsd_lags)} TAMSD lags accumulated",
                seconds=clock() - t0,
            )
        )
    return rows


# the collapse map's outcomes, in legend order, with their colours and meanings
COLLAPSE_STATUS = {
    "ok": ("tab:green", f"ok: reached {COLLAPSE_GOAL} collisions per particle"),
    "tc": ("tab:blue", "tc: reached it, TC model acting"),
    "budget": ("tab:orange", "budget: event budget ran out first"),
    "collapse": ("tab:red", "collapse: inelastic collapse"),
    "n/a": ("0.6", "n/a: the viscoelastic law cannot reach this mean restitution"),
}


def _log_ticks(axis, limits):
    """Ticks of a log axis that never collide: matplotlib labels every minor tick of an
    axis spanning about a decade (2e-3, 3e-3, ... run into each other); such an axis gets
    labels at 1, 2 and 5 times the powers of ten, and no minor labels."""
    from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

    axis.set_minor_formatter(NullFormatter())
    if math.log10(limits[1] / limits[0]) < 1.5:
        axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(LogFormatterSciNotation(labelOnlyBase=False))


def _em_chart(plt, out, stab):
    """em_stability.png: each scheme's MSD error against gamma0 dt (rows of ``em_stability``)."""
    fig, ax = plt.subplots(figsize=(6, 4.2), layout="constrained")
    g = [r["gamma_dt"] for r in stab]
    for scheme, marker in (("em", "s-"), ("exact", "^-")):
        ax.loglog(
            g,
            [r[scheme] if r[scheme] is not None else np.nan for r in stab],
            marker,
            label={"em": "Euler-Maruyama", "exact": "exact scheme"}[scheme],
        )
    ax.axvline(2.0, color="r", ls=":", label=r"EM refused ($\gamma_0 \Delta t \geq 2$)")
    ax.set_xlabel(r"$\gamma_0 \Delta t$ (dimensionless)")
    ax.set_ylabel("max relative MSD error\nvs [G20] eq. 2.68 (dimensionless)")
    ax.legend()
    fig.savefig(os.path.join(out, "em_stability.png"), dpi=110)
    plt.close(fig)


def _collapse_map(plt, cells):
    """One panel per law and contact duration (constant xi without and with the TC model,
    then the viscoelastic law): a grid of cells (area fraction x restitution), each
    coloured and labelled by its outcome; the legend lists only the outcomes that occur."""
    from matplotlib.patches import Patch, Rectangle

    def panel(c):
        return (c.get("law", "constant") != "constant", c["contact_duration"])

    panels = sorted({panel(c) for c in cells})
    etas = sorted({c["eta"] for c in cells})
    xis = sorted({c["xi"] for c in cells})
    fig, axes = plt.subplots(
        1, len(panels), figsize=(4.5 * len(panels) + 1.5, 4.2), layout="constrained", squeeze=False
    )
    for ax, (visco, tc) in zip(axes[0], panels, strict=True):
        for c in (c for c in cells if panel(c) == (visco, tc)):
            x, y = etas.index(c["eta"]), xis.index(c["xi"])
            ax.add_patch(
                Rectangle((x - 0.45, y - 0.45), 0.9, 0.9, color=COLLAPSE_STATUS[c["status"]][0])
            )
            ax.text(x, y, c["status"], ha="center", va="center", fontsize=8, color="w")
        ax.set_xlim(-0.5, len(etas) - 0.5)
        ax.set_ylim(-0.5, len(xis) - 0.5)
        ax.set_xticks(range(len(etas)), [f"{e:g}" for e in etas])
        ax.set_yticks(range(len(xis)), [f"{x:g}" for x in xis])
        ax.set_xlabel(
            "area fraction"
            if not visco
            else "area fraction\n"
            r"$\varepsilon(g)$ averaged over the initial collisions (Rayleigh density of the"
            "\n"
            r"normal impact speed $g$) equals $\xi$; the law's series holds for"
            "\n"
            r"$\varepsilon \geq 0.76$ only: $\xi \leq 0.7$ cannot be matched (n/a)",
            fontsize=None if not visco else 8,
        )
        ax.set_ylabel(r"restitution $\xi$" if not visco else r"mean $\varepsilon$ = $\xi$")
        ax.set_title(
            "2D disks, walls, "
            + ("no TC model" if tc == 0 else rf"TC model $t_c$ = {tc:g}")
            + ("" if not visco else "\nviscoelastic law, same mean restitution"),
            fontsize=10,
        )
    seen = {c["status"] for c in cells}
    fig.legend(
        handles=[
            Patch(color=color, label=text)
            for status, (color, text) in COLLAPSE_STATUS.items()
            if status in seen
        ],
        loc="outside lower center",
        ncols=len(seen),
        fontsize=8,
    )
    return fig


def _charts(out, points, refs, stab, cells, dense):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    gases = [
        g for g in ("granular", "molecular", "viscoelastic") if any(p["gas"] == g for p in points)
    ]
    fig, axes = plt.subplots(
        2, len(gases), figsize=(6 * len(gases), 9), layout="constrained", squeeze=False
    )
    for col, gas in enumerate(gases):
        for row, key in enumerate(("msd_error", "slope_error")):
            ax = axes[row, col]
            model = "power-law UDSBM a = 5/6" if gas == "viscoelastic" else "Langevin/UDSBM"
            for method, marker in (("edmd", "o"), ("em", "s"), ("exact", "^")):
                pts = [p for p in points if p["gas"] == gas and p["method"] == method]
                if not pts:
                    continue
                if method != "edmd":
                    # one line per scheme in order of the step, labelled at its two ends only:
                    # a label at every step would pile up where the steps cost alike
                    pts = sorted(pts, key=lambda p: p["dt"])
                    marker += "-"
                ax.loglog(
                    [p["seconds"] for p in pts],
                    [max(p[key], 1e-5) for p in pts],
                    marker,
                    label={
                        "edmd": "EDMD (N, runs)",
                        "em": rf"{model}, Euler-Maruyama ($\Delta t$)",
                        "exact": rf"{model}, exact scheme ($\Delta t$)",
                    }[method],
                )
                for p in pts if method == "edmd" else (pts[0], pts[-1]):
                    ax.annotate(
                        p["label"] if method == "edmd" else rf"$\Delta t$ = {p['dt']:.3g}",
                        (p["seconds"], max(p[key], 1e-5)),
                        fontsize=6,
                        xytext=(3, 3),
                        textcoords="offset points",
                    )
            for axis, limits in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
                _log_ticks(axis, limits)
            ax.set_xlabel("CPU seconds, one core (EDMD: equilibration included)")
            ax.set_ylabel(
                (
                    "max relative MSD error vs EDMD reference"
                    if key == "msd_error"
                    else "relative error of the late exponent d ln MSD / d ln t"
                    if gas == "viscoelastic"
                    else "relative error of the long-time slope"
                )
                + " (dimensionless)"
            )
            ax.set_title(
                f"{gas} gas"
                + {
                    "granular": r", $\xi$ = 0.8",
                    "molecular": "",
                    "viscoelastic": rf", $\varepsilon$ = {VISCO_EPS} at $g = \sqrt{{4T_0/m}}$",
                }[gas]
            )
            ax.legend(fontsize=7)
    fig.savefig(os.path.join(out, "speed_accuracy.png"), dpi=110)
    plt.close(fig)

    _em_chart(plt, out, stab)

    fig = _collapse_map(plt, cells)
    fig.savefig(os.path.join(out, "collapse_map.png"), dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for dim, shell in sorted({(r["dim"], r["shell"]) for r in dense}):
        rows = [r for r in dense if r["dim"] == dim and r["shell"] == shell]
        label = f"{dim}D, N = {rows[0]['n']}, " + (f"lists (shell {shell:g})" if shell else "cells")
        eta = [r["eta"] for r in rows]
        axes[0].semilogy(eta, [r["seconds_per_time"] for r in rows], "o-", label=label)
        axes[1].plot(eta, [r["ns_per_collision"] / 1e3 for r in rows], "o-", label=label)
    for ax in axes:
        ax.set_xlabel("packing (area) fraction")
        ax.legend()
    axes[0].set_ylabel("seconds per unit of simulated time (T = 1)")
    axes[1].set_ylabel("µs per pair collision")
    fig.savefig(os.path.join(out, "dense_cost.png"), dpi=110)
    plt.close(fig)


def _transport_chart(out, driven, model, visc, enskog):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = speed_accuracy_transport.chart(plt, driven, model, visc, enskog)
    fig.savefig(os.path.join(out, "speed_accuracy_transport.png"), dpi=110)
    plt.close(fig)


def main(out="speed-accuracy", quick=False):
    os.makedirs(out, exist_ok=True)
    started = time.perf_counter()
    points, refs = speed_accuracy_points(quick)
    visco_points, refs["viscoelastic"] = viscoelastic_points(quick)
    points += visco_points
    print(
        f"  speed/accuracy points: {len(points)}  ({time.perf_counter() - started:.0f} s)",
        flush=True,
    )
    driven, driven_model = speed_accuracy_transport.driven_points(quick)
    visc, enskog_viscosity = speed_accuracy_transport.viscosity_points(quick)
    stab = em_stability(quick)
    cells = collapse_map(quick)
    dense = dense_cost(quick)
    costs = scene_costs(quick)
    _charts(out, points, refs, stab, cells, dense)
    _transport_chart(out, driven, driven_model, visc, enskog_viscosity)
    write_json(
        os.path.join(out, "speed_accuracy.json"),
        dict(
            seconds="CPU-seconds of one process, every method serial on one thread",
            points=points,
            references=refs,
            em_stability=stab,
            collapse_map=cells,
            dense_cost=dense,
            scene_costs=costs,
            driven_diffusion=dict(model=driven_model, points=driven),
            shear_viscosity=dict(
                packing=speed_accuracy_transport.VISCOSITY_ETA,
                enskog=enskog_viscosity,
                points=visc,
            ),
        ),
    )
    print(f"{'method':<34} {'CPU s':>8} {'MSD err':>8} {'slope err':>9}")
    for p in points:
        print(
            f"{p['gas'][:4] + ' ' + p['label']:<34} {p['seconds']:>8.2f} {p['msd_error']:>8.3f} "
            f"{p['slope_error']:>9.3f}"
        )
    for p in driven:
        print(
            f"driven {p['method']} {p['label']:<24} {p['seconds']:>8.2f} s  D/theory - 1 = "
            f"{p['d_error']:+.4f} +- {p['d_error_bar']:.4f}"
        )
    for p in visc:
        print(
            f"viscosity {p['route']} {p['label']:<16} {p['seconds']:>8.3f} s/run  eta* = "
            f"{p['mean']:.4f} +- {p['mean_error']:.4f}, one run +- {p['spread']:.4f}"
        )
    print(f"charts and speed_accuracy.json in {out}/ ({time.perf_counter() - started:.0f} s)")
    return dict(
        points=points,
        em_stability=stab,
        collapse_map=cells,
        dense_cost=dense,
        scene_costs=costs,
        driven_diffusion=driven,
        shear_viscosity=visc,
    )


def _sde_points(add, c, n_sde, dts_by_scheme, t_max, times, exponent=1.0, label=None):
    """One Langevin run per (scheme, dt), timed, each handed to ``add`` as a point:
    its MSD at ``times``, its cost and its step (``gamma0 dt``)."""
    for scheme, dts in dts_by_scheme.items():
        for dt in dts:
            t0 = clock()
            r = langevin.run(
                n_sde,
                gamma0=c.gamma0,
                D0=c.D0,
                tau0=c.tau0,
                exponent=exponent,
                dt=dt,
                t_stop=t_max,
                scheme=scheme,
                sample_times=times,
                seed=5,
            )
            sec = clock() - t0
            add(
                scheme,
                f"{label or r.model} {scheme}, dt={dt:.3g}",
                r.msd(),
                sec,
                at=r.times,
                dt=dt,
                n=n_sde,
                gamma_dt=c.gamma0 * dt,
            )
