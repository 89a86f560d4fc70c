"""Speed against accuracy for the steady states' transport coefficients (two panels of
``bench --speed-accuracy``): the self-diffusion of a white-noise driven granular gas by EDMD
and by the Langevin model that matches it, and the shear viscosity of the elastic fluid by
Green-Kubo and by NEMD.  Every point is measured, cost in CPU-seconds of this process
(``speed_accuracy.clock``), each method run serially on one thread in the same run.

**The driven gas** (``driven_points``): 3D, xi = 0.8, packing 0.03, unit diameter, heated
by ``WhiteNoise`` of the strength whose theory steady temperature is T_s = 1 (as in
reproduce_driven, with the finite-kick a2 of ``theory.sonine_a2_driven``; kicks of variance
T / (5 m), fewer than reproduce_driven's T / (50 m) and ten times cheaper: they raise a2 from
-0.009 to +0.022, which the strength includes, a 0.4 % shift of T_s had it not).  The
matching Langevin model: a tracer's velocity relaxes by
collisions at the rate gamma_v = (1 + xi) / 2 gamma_E, gamma_E the elastic Enskog rate
(each collision changes v by -(1 + xi)/2 (g.n) n: the thesis' derivation of (2.49) with the
restitution kept linear); the white-noise kicks do not depend on v and add no relaxation,
and T = T_s stays constant, so the velocity is an Ornstein-Uhlenbeck process with constant
gamma_v and noise 2 gamma_v T_s / m, and D = T_s / (m gamma_v) = 2 D_E(T_s) / (1 + xi).
(In the cooling state the same rate less zeta / 2 gives the thesis' D0 = 4 D_E / (1 + xi)^2,
(2.52); under a stochastic thermostat the zeta / 2 is absent, as in Garzo & Montanero, Phys.
Rev. E 69, 021301 (2004), whose Sonine corrections this first-order form leaves out.)  The
Langevin model is ``langevin.run(gamma0=gamma_v, D0=D)`` (tau0 = inf).

The quantity, the same for both: D from the slope of the particle- and time-averaged MSD
(all origins) over lags 5..15 / gamma_v, divided by 2d, compared with theory's MSD ([G20]
eq. 2.68 at (D, gamma_v)) fitted over the same lags -- the window's own small bias (e^-5)
cancels.  Each point is ``REPLICAS`` independent runs (own placement, own kicks, own
equilibration of 10 / gamma_v, charged in full); its value the mean, its error bar the
standard error over the replicas.

**The sheared gas** (``viscosity_points``): the elastic fluid at packing ``VISCOSITY_ETA``
(3D, periodic), the reduced viscosity eta* = eta sigma^2 / sqrt(m T) by Green-Kubo
(Einstein-Helfand, ``transport.shear_viscosity``, lags 3-8 mean free times, as in
reproduce_transport) at several (N, run length), and by NEMD (``reproduce_transport.nemd_run``
and ``transport.nemd_viscosity``, the gamma*^2 extrapolation) at several (N, sweep end).
The error of one run is the spread (standard deviation) of ``REPLICAS`` independent runs'
values, its error bar that of a standard deviation of k Gaussian draws, 1/sqrt(2(k-1));
the cost is the mean CPU-seconds of one run, equilibration included.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .. import Scene, Simulation, WhiteNoise, langevin, theory, transport
from . import reproduce_transport

XI, ETA, RADIUS = 0.8, 0.03, 0.5
KICK = 0.2  # one kick's velocity variance over T / m
FIT_LAGS = np.arange(5.0, 15.5, 1.0)  # in 1 / gamma_v
SETTLE = 10.0  # in 1 / gamma_v: equilibration of each EDMD replica
VISCOSITY_ETA = 0.30
VISCOSITY_FIT = reproduce_transport.VISCOSITY_FIT  # lags in mean free times
NEMD_START, NEMD_FIT = 1.0, 0.6  # the sweep's first gamma*, the largest fitted
clock = time.process_time  # as speed_accuracy.clock: CPU-seconds of this process


def _replicas(quick):
    return 3 if quick else 10


def driven_model():
    """The driven gas and its matching Langevin model: dict of the noise's strength and
    rate, the number density, the steady temperature T_s (theory), D_E(T_s), gamma_v
    and D = T_s / (m gamma_v) (module docstring)."""
    density = ETA / (4.0 / 3.0 * math.pi * RADIUS**3)
    a2 = theory.sonine_a2_driven(restitution=XI, dim=3, kick=KICK)
    # the strength whose steady temperature is 1 (reproduce_driven.driven_parameters)
    cooling = theory.cooling_rate(
        temperature=1.0, density=density, radius=RADIUS, restitution=XI, dim=3
    )
    strength = float(cooling * (1 + 3 * a2 / 16))
    t_s = float(
        theory.driven_temperature(
            strength=strength, density=density, radius=RADIUS, restitution=XI, dim=3, kick=KICK
        )
    )
    d_e = float(theory.enskog_diffusion(ETA, radius=RADIUS, temperature=t_s))
    diffusion = 2.0 * d_e / (1.0 + XI)
    return dict(
        strength=strength,
        rate=strength / KICK,
        density=density,
        temperature=t_s,
        enskog_diffusion=d_e,
        gamma=t_s / diffusion,
        diffusion=diffusion,
    )


def _slope_d(lags, msd):
    """D per dimension from an MSD (total over 3 dimensions): its slope / 6."""
    return float(np.polyfit(lags, msd, 1)[0] / 6.0)


def _theory_d(lags, model):
    """Theory's D read as the data are: [G20] eq. 2.68's MSD fitted over the same lags."""
    return _slope_d(lags, theory.msd_langevin(lags, D0=model["diffusion"], gamma0=model["gamma"]))


def _tamsd(x, steps):
    """Mean over particles, components' sum and all origins of |x(s + k) - x(s)|^2."""
    return np.array([np.mean(np.sum((x[k:] - x[:-k]) ** 2, axis=-1)) for k in steps])


def _edmd_driven(n, span, model, seed):
    """One EDMD replica: N particles equilibrated SETTLE / gamma_v, then ``span`` (in
    1 / gamma_v) sampled every half 1 / gamma_v.  Returns (D, T, CPU seconds)."""
    g = model["gamma"]
    t0 = clock()
    side = (n * 4.0 / 3.0 * math.pi * RADIUS**3 / ETA) ** (1.0 / 3.0)
    scene = Scene.random(n, RADIUS, dim=3, box=side, restitution=XI, temperature=1.0, seed=seed)
    drive = WhiteNoise(model["strength"], model["rate"], seed=seed)
    sim = Simulation(scene.replace(driving=drive))
    sim.run(t_stop=SETTLE / g, store=())
    times = sim.time + np.arange(0.0, 2 * span + 1) / (2 * g)
    tr = sim.run(float(times[-1]), sample_times=times, store=("positions",))
    pos = tr._need("positions")
    x = pos - pos.mean(axis=1, keepdims=True)  # the centre of mass is fixed
    d = _slope_d(FIT_LAGS / g, _tamsd(x, (2 * FIT_LAGS).astype(int)))
    temp = float(2.0 * tr.kinetic_energy.mean() / (3 * (n - 1)))
    return d, temp, clock() - t0


def _sde_driven(n, span, dt, scheme, model, seed):
    """One Langevin replica: N independent particles for ``span`` / gamma_v, TAMSD at the
    fit lags rounded to whole steps.  Returns (D, theory's D at those lags, seconds)."""
    g = model["gamma"]
    lags = np.unique(np.round(FIT_LAGS / g / dt)) * dt
    t0 = clock()
    r = langevin.run(
        n,
        gamma0=g,
        D0=model["diffusion"],
        dt=dt,
        t_stop=span / g,
        scheme=scheme,
        tamsd_lags=lags,
        tamsd_estimator="all",
        seed=seed,
    )
    sec = clock() - t0
    return _slope_d(r.tamsd_lags, r.tamsd()), _theory_d(r.tamsd_lags, model), sec


def _summary(values, reference):
    v = np.asarray(values) / reference
    return float(v.mean() - 1.0), float(v.std(ddof=1) / math.sqrt(len(v)))


def driven_points(quick=False):
    """The driven gas' points: EDMD at (N, span) and both Langevin schemes at (N, gamma_v
    dt), each ``_replicas`` independent runs; ``d_error`` = mean D / theory's D - 1 and
    ``d_error_bar`` its standard error.  Returns (points, the model)."""
    model = driven_model()
    reps = _replicas(quick)
    th = _theory_d(FIT_LAGS / model["gamma"], model)
    points = []
    edmd = (
        [(250, 60), (1000, 60), (1000, 240), (4000, 60), (4000, 240)] if not quick else [(250, 30)]
    )
    for n, span in edmd:
        runs = [_edmd_driven(n, span, model, seed=1000 * n + span + k) for k in range(reps)]
        err, bar = _summary([r[0] for r in runs], th)
        side = (n * 4.0 / 3.0 * math.pi * RADIUS**3 / ETA) ** (1.0 / 3.0)
        # Yeh & Hummer's finite-box correction, estimated with the elastic Enskog viscosity
        fs = (
            float(
                theory.diffusion_infinite_system(
                    side,
                    diffusion=th,
                    viscosity=theory.enskog_viscosity(ETA, radius=RADIUS, temperature=1.0),
                    temperature=model["temperature"],
                )
            )
            - th
        )
        points.append(
            dict(
                method="edmd",
                label=f"N={n}, {span}/gamma",
                n=n,
                span=span,
                runs=reps,
                seconds=sum(r[2] for r in runs),
                d_error=err,
                d_error_bar=bar,
                temperature=float(np.mean([r[1] for r in runs])),
                finite_size_correction=fs / th,
            )
        )
    span = 240 if not quick else 30
    sde = [(1000, 0.1), (4000, 0.1), (4000, 0.5), (4000, 1.0), (4000, 1.9)]
    if quick:
        sde = [(500, 0.5)]
    for scheme in ("exact", "em"):
        steps = sde + ([(4000, 3.0), (4000, 5.0)] if scheme == "exact" and not quick else [])
        for n, gdt in steps:
            runs = [
                _sde_driven(n, span, gdt / model["gamma"], scheme, model, seed=7 + k)
                for k in range(reps)
            ]
            err, bar = _summary([r[0] / r[1] * th for r in runs], th)
            points.append(
                dict(
                    method=scheme,
                    label=f"N={n}, gamma dt={gdt:g}",
                    n=n,
                    span=span,
                    runs=reps,
                    gamma_dt=gdt,
                    seconds=sum(r[2] for r in runs),
                    d_error=err,
                    d_error_bar=bar,
                )
            )
    return points, model


def _gk_run(n, taus, seed):
    """One Green-Kubo run: (eta*, CPU seconds), equilibration (20 collisions per particle)
    included."""
    t0 = clock()
    r = (VISCOSITY_ETA / n / (4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sim = Simulation(Scene.random(n, r, dim=3, temperature=1.0, seed=seed), stress=True)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    tau = sim.time / sim.stats["collisions_per_particle"]
    samples = reproduce_transport.SAMPLES_PER_TAU
    times = sim.time + tau * np.linspace(0.0, taus, int(taus * samples) + 1)
    tr = sim.run(float(times[-1]), sample_times=times, store=())
    temp = float(2.0 * tr.kinetic_energy.mean() / (3 * (n - 1)))
    fit = (VISCOSITY_FIT[0] * tau, VISCOSITY_FIT[1] * tau)
    visc = transport.shear_viscosity(tr, fit=fit, blocks=2)
    return visc.value * (2 * r) ** 2 / math.sqrt(temp), clock() - t0


def _nemd_runs(n, end, reps, seed):
    """``reps`` sheared runs (gamma* from NEMD_START to ``end``): each run's extrapolated
    eta*_0 and its CPU seconds."""
    windows, seconds = [], []
    for k in range(reps):
        t0 = clock()
        windows.append(
            reproduce_transport.nemd_run(VISCOSITY_ETA, n, NEMD_START, end, seed + k, windows=24)
        )
        seconds.append(clock() - t0)
    fit = transport.nemd_viscosity(windows, max_rate=NEMD_FIT, power=2.0)
    return list(fit.runs), seconds


def _spread_point(route, label, values, seconds, **extra):
    v = np.asarray(values, dtype=np.float64)
    k = len(v)
    return dict(
        route=route,
        label=label,
        runs=k,
        seconds=float(np.mean(seconds)),
        mean=float(v.mean()),
        mean_error=float(v.std(ddof=1) / math.sqrt(k)),
        spread=float(v.std(ddof=1)),
        spread_error=float(v.std(ddof=1) / math.sqrt(2 * (k - 1))),
        values=v.tolist(),
        # averaging independent runs: the CPU-seconds to reach a standard error of 1 % of eta*
        seconds_for_1pc=float(np.mean(seconds) * (v.std(ddof=1) / (0.01 * v.mean())) ** 2),
        **extra,
    )


def viscosity_points(quick=False):
    """Green-Kubo at (N, run length in mean free times) and NEMD at (N, end of the
    gamma* sweep), ``_replicas`` runs each (module docstring).  Returns (points, Enskog's
    eta*)."""
    reps = _replicas(quick)
    points = []
    gk = (
        [(108, 250), (108, 1000), (256, 250), (256, 1000), (500, 1000), (500, 4000)]
        if not quick
        else [(108, 250)]
    )
    for n, taus in gk:
        runs = [_gk_run(n, taus, seed=500 + n + taus + k) for k in range(reps)]
        points.append(
            _spread_point(
                "green_kubo",
                f"N={n}, {taus} tau",
                [r[0] for r in runs],
                [r[1] for r in runs],
                n=n,
                taus=taus,
            )
        )
    nemd = (
        [(108, 0.2), (256, 0.2), (256, 0.1), (500, 0.2), (500, 0.1), (1000, 0.1)]
        if not quick
        else [(108, 0.2)]
    )
    for n, end in nemd:
        values, seconds = _nemd_runs(n, end, reps, seed=2900 + n + int(100 * end))
        points.append(
            _spread_point("nemd", f"N={n}, to {end:g}", values, seconds, n=n, sweep_end=end)
        )
    enskog = float(theory.enskog_viscosity(VISCOSITY_ETA, radius=0.5, temperature=1.0))
    return points, enskog


def chart(plt, driven, model, visc, enskog):
    """speed_accuracy_transport.png: the driven gas' D error against cost (left), the
    viscosity's spread of one run against its cost (middle) and each point's mean eta*
    (right)."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    fig, axes = plt.subplots(
        1, 3, figsize=(19, 5.5), layout="constrained", gridspec_kw=dict(width_ratios=(1.4, 1, 1))
    )
    ax = axes[0]
    names = {
        "edmd": "EDMD, white noise (N, run length)",
        "exact": r"Langevin $\gamma_v$, $D$, exact scheme (label $\gamma_v\Delta t$)",
        "em": r"Langevin $\gamma_v$, $D$, Euler-Maruyama (label $\gamma_v\Delta t$)",
    }
    big = max(p["n"] for p in driven if p["method"] != "edmd")

    def label(p):  # short: the SDE points crowd near zero
        if p["method"] == "edmd":
            return f"N={p['n']}, {p['span']}/" + r"$\gamma_v$"
        return (f"N={p['n']}, " if p["n"] != big else "") + f"{p['gamma_dt']:g}"

    for method, marker in (("edmd", "o"), ("exact", "^"), ("em", "s")):
        pts = [p for p in driven if p["method"] == method]
        ax.errorbar(
            [p["seconds"] for p in pts],
            [100 * p["d_error"] for p in pts],
            yerr=[100 * p["d_error_bar"] for p in pts],
            fmt=marker,
            capsize=2,
            label=names[method],
        )
        for p in pts:
            ax.annotate(
                label(p),
                (p["seconds"], 100 * p["d_error"]),
                fontsize=6,
                xytext=(3, 3),
                textcoords="offset points",
            )
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xscale("log")
    # linear within +-1 %, logarithmic beyond: Euler-Maruyama near its limit is off by ~90 %
    ax.set_yscale("symlog", linthresh=1.0)
    ax.yaxis.set_major_locator(FixedLocator([-100, -30, -10, -3, -1, 0, 1, 3, 10]))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.set_ylim(-200, 10)
    ax.set_xlabel(
        f"CPU seconds, one core, {driven[0]['runs']} runs per point "
        f"(Langevin: N = {big} unless labelled)"
    )
    ax.set_ylabel(r"$D / D_{theory} - 1$ (%), mean $\pm$ standard error")
    ax.set_title(
        rf"driven gas, $\xi$ = {XI}, packing {ETA}: self-diffusion"
        "\n"
        rf"theory $D = 2 D_E(T_s)/(1+\xi)$ = {model['diffusion']:.3f}, "
        rf"$1/\gamma_v$ = {1 / model['gamma']:.2f}",
        fontsize=10,
    )
    ax.legend(fontsize=7)
    routes = (("green_kubo", "o", "Green-Kubo (N, run length)"), ("nemd", "s", "NEMD (N, sweep)"))
    for route, marker, name in routes:
        pts = [p for p in visc if p["route"] == route]
        axes[1].errorbar(
            [p["seconds"] for p in pts],
            [p["spread"] for p in pts],
            yerr=[p["spread_error"] for p in pts],
            fmt=marker,
            capsize=2,
            label=name,
        )
        axes[2].errorbar(
            [p["seconds"] for p in pts],
            [p["mean"] for p in pts],
            yerr=[p["mean_error"] for p in pts],
            fmt=marker,
            capsize=2,
            label=name,
        )
        for p in pts:
            for a, y in ((axes[1], p["spread"]), (axes[2], p["mean"])):
                a.annotate(
                    p["label"], (p["seconds"], y), fontsize=6, xytext=(3, 3),
                    textcoords="offset points",
                )  # fmt: skip
    axes[1].set_xscale("log")
    axes[1].set_yscale("log")
    axes[1].set_ylabel(r"one run's error: spread of $\eta^*$ over runs (std)")
    axes[2].set_xscale("log")
    axes[2].axhline(enskog, color="k", ls="--", lw=0.8, label="Enskog (first Sonine)")
    axes[2].set_ylabel(r"$\eta^* = \eta\sigma^2/\sqrt{mT}$, mean $\pm$ standard error")
    for a in axes[1:]:
        a.set_xlabel(f"CPU seconds of one run, one core ({visc[0]['runs']} runs per point)")
        a.set_title(f"elastic fluid, packing {VISCOSITY_ETA}: shear viscosity", fontsize=10)
        a.legend(fontsize=7)
    return fig
