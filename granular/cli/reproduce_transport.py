"""The reproduction's transport experiment: the shear viscosity (Green-Kubo, in its
Einstein-Helfand form) and the self-diffusion coefficient of the elastic hard-sphere fluid
from equilibrium EDMD runs, against Enskog's theory and Pieprzyk et al.'s MD.

Viscosity: one run per packing fraction (3D, periodic cube, N = 500 full, 256 quick, eta =
0.05 and 0.30), equilibrated for 20 collisions per particle, then run with
``Simulation(stress=True)`` for 4000 (full) or 1000 (quick) mean free times tau (tau = t /
collisions per particle), sampled twice per tau: the slope of <(G(t+s) - G(s))^2> / (2 V T)
over lags 3-8 tau, G the Helfand moments of the five shear components
(``transport.shear_moments``).  Errors: ten blocks of the run (std / sqrt(10)).  Values in
reduced units, eta* = eta sigma^2 / sqrt(m T) and D* = D sqrt(m / T) / sigma.

Self-diffusion (``diffusion.elastic.*``): at n sigma^3 = 0.1 and 0.5 (packings pi / 60 and
pi / 12), two of the densities Pieprzyk, Bannerman, Branka, Chudak & Heyes, Phys. Chem.
Chem. Phys. 21, 6886 (2019) tabulate (``theory.pieprzyk_diffusion``, infinite N, as
transcribed in a public script), 10 independent runs of N = 1372 (full; quick 256) after
50 collisions per particle, each at least 2000 (quick 500) collisions per particle long.
The MSD's slope (``transport.self_diffusion``) is taken over a window past the decay of
the box's slowest shear mode (``diffusion_window``): before it the velocity correlation's
t^-3/2 tail still raises the slope (over 10-20 tau it is 6 % short at n sigma^3 = 0.5).
That is D_L of the box, corrected to infinite N by Yeh & Hummer 2004 with Enskog's
viscosity; the error from the runs' spread.  Speedy's and Enskog's values and Lue's are in
the rows' text.

The NEMD route (``viscosity.elastic.nemd``): sheared runs of the same fluid with no
thermostat (``nemd_run``: N = 1000 full, 500 quick; 8 runs full, 4 quick).  The gas heats,
so its reduced shear rate gamma* = gamma sigma / sqrt(T / m) falls through the run; the
viscosity of each window (``transport.shear_windows``) is extrapolated to gamma* -> 0 by
eta*_0 + c gamma*^2 (``transport.nemd_viscosity``), the error from the runs' spread.  The
row's text gives the sqrt(gamma*) extrapolation too and how far the two routes lie apart
(``viscosity_nemd.png``).

The equation of state and the collision rate (``eos.elastic.*``,
``eos.mean_free_time.*``): equilibrium runs at n sigma^3 = 0.5 (packing 0.2618,
N = 1372) and at packing 0.45 (N = 2000), 10 runs of 1000 collisions per particle
(quick: 100) after 50; Z = P / (n T) from the collision virial, the mean free time in
sigma sqrt(m / T).  The reference is Pieprzyk et al.'s 2019 MD fit of Z
(``theory.pieprzyk_compressibility``), and through its contact value the collision rate,
which equilibrium fixes exactly; Lue's MD mean free time at n sigma^3 = 0.5, N = 1372
(doi:10.1063/1.1834498, as DynamO's tests quote it) is given in the row's text.

The reference for the viscosity is Enskog's theory in the first Sonine approximation
(``theory.enskog_viscosity``), which neglects correlated collisions: near-exact at eta =
0.05 (within its 1.6 % Sonine truncation), while at 0.30 the fluid's correlated collisions
change it by several percent.  Pieprzyk et al.'s viscosities could not be found for this
version (docs/stress.md), so the rows carry Enskog's value as theory and the quantity text
says which deviation is expected.
"""

from __future__ import annotations

import math

import numpy as np

from .. import Scene, Simulation, theory, transport

PACKINGS = (0.05, 0.30)
SAMPLES_PER_TAU = 2
VISCOSITY_FIT = (3.0, 8.0)  # lags in tau: past the stress correlation (1.25 tau dilute)


def _sizes(cfg):
    return (256, 1000.0) if cfg.quick else (500, 4000.0)


def measure(eta, n, taus, seed=29):
    """One equilibrium run at packing ``eta``: (the viscosity's TransportResult, T, sigma,
    the trajectory's tau)."""
    r = (eta / n / (4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sim = Simulation(Scene.random(n, r, dim=3, temperature=1.0, seed=seed), stress=True)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    tau = sim.time / (sim.stats["collisions_per_particle"])
    times = sim.time + tau * np.linspace(0.0, taus, int(taus * SAMPLES_PER_TAU) + 1)
    tr = sim.run(times[-1], sample_times=times, store=())
    temp = float(2.0 * tr.kinetic_energy.mean() / (3 * (n - 1)))
    visc = transport.shear_viscosity(tr, fit=(VISCOSITY_FIT[0] * tau, VISCOSITY_FIT[1] * tau))
    return visc, temp, 2.0 * r, tau


# The self-diffusion runs: at two of the densities n sigma^3 that Pieprzyk et al. 2019
# tabulate (theory.pieprzyk_diffusion), the dilute gas and Lue's state
DIFFUSION_DENSITIES = (0.1, 0.5)
DIFFUSION_LAGS = 32  # samples per fit window's upper end
DIFFUSION_BLOCKS = 2


def _diffusion_sizes(cfg):
    """(N, runs, collisions per particle at least per run)."""
    return (256, 10, 500) if cfg.quick else (1372, 10, 2000)


def diffusion_window(density, n):
    """The lags (lo, hi) in sigma sqrt(m / T) over which the MSD's slope is D_L, the
    self-diffusion coefficient of a periodic cube of ``n`` spheres at ``density`` n sigma^3.

    The running slope d<dx^2>/(2 dt) rises to D_L through the velocity correlation's
    t^-3/2 tail, which a periodic box cuts off: its slowest shear mode, wave number
    k = 2 pi / L, decays with the time t_L = 1 / ((nu + D) k^2), nu = eta / (n m) the
    kinematic viscosity.  What the slope still lacks at lag t is ~4 t_L exp(-t / t_L) / N
    (the six modes of the first shell, two of their three polarisations transverse): past
    lo = 4 t_L that is < 0.2 % of D at the sizes used.  The start also lies past eight
    velocity relaxation times m D / T (the kinetic part of the correlation, exp(-8)).
    Enskog's nu and D are close enough to place the window.  At n sigma^3 = 0.5 the slope
    over 10-20 mean free times, where the tail still raises it, is 6 % short of D_L
    (docs/stress.md)."""
    eta = math.pi * density / 6.0
    box = (n / density) ** (1.0 / 3.0)  # in sigma
    nu = float(theory.enskog_viscosity(eta, radius=0.5, temperature=1.0)) / density
    d = float(theory.enskog_diffusion(eta, radius=0.5, temperature=1.0))
    t_box = box**2 / (4.0 * math.pi**2 * (nu + d))
    lo = max(4.0 * t_box, 8.0 * d)
    return lo, 2.0 * lo


def diffusion_run(density, n, collisions, seed):
    """One equilibrium run of ``n`` elastic spheres at ``density`` n sigma^3 (3D periodic
    cube, 50 collisions per particle to equilibrate), at least ``collisions`` per particle
    and 4 ``DIFFUSION_BLOCKS`` times the window's upper end long: (D_L*, D_inf*, the
    lags, the MSD's running slope at them), in sigma sqrt(m / T) units; D_inf from Yeh &
    Hummer's correction with Enskog's viscosity."""
    sigma = (density / n) ** (1.0 / 3.0)  # the unit box
    eta = math.pi * density / 6.0
    sim = Simulation(Scene.random(n, sigma / 2.0, dim=3, temperature=1.0, seed=seed))
    sim.run(stop_when={"collisions_per_particle": 50}, store=())
    temp = 2.0 * sim.stats["kinetic_energy"] / (3 * (n - 1))  # exact: energy is conserved
    unit = sigma / math.sqrt(temp)  # sigma sqrt(m / T)
    lo, hi = diffusion_window(density, n)
    step = hi * unit / DIFFUSION_LAGS
    tau = sim.time / sim.stats["collisions_per_particle"]
    samples = max(4 * DIFFUSION_BLOCKS * DIFFUSION_LAGS, math.ceil(collisions * tau / step))
    times = sim.time + step * np.arange(samples + 1)
    tr = sim.run(times[-1], sample_times=times, store=("positions",))
    diff = transport.self_diffusion(tr, fit=(lo * unit, hi * unit), blocks=DIFFUSION_BLOCKS)
    d_l = diff.value / (sigma * math.sqrt(temp))
    viscosity = float(theory.enskog_viscosity(eta, radius=0.5, temperature=1.0))
    box = (n / density) ** (1.0 / 3.0)
    d_inf = float(
        theory.diffusion_infinite_system(box, diffusion=d_l, viscosity=viscosity, temperature=1.0)
    )
    return (
        d_l,
        d_inf,
        diff.lags / unit,
        np.gradient(diff.curve, diff.lags) / (sigma * math.sqrt(temp)),
    )


# The equation of state's runs: (packing, N); n sigma^3 = 0.5 is Lue's (2005) state
EOS_CASES = ((math.pi / 12.0, 1372), (0.45, 2000))
# Lue's MD mean free time there (doi:10.1063/1.1834498, quoted by DynamO's tests,
# src/dynamo/tests/hardsphere_test.cpp), in sigma sqrt(m / T)
LUE_MEAN_FREE_TIME = 0.13031


def eos_run(eta, n, collisions, seed):
    """One equilibrium run at packing ``eta``: (Z = P / (n T), the mean free time in
    sigma sqrt(m / T)), over ``collisions`` per particle after 50."""
    r = (eta / n / (4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sim = Simulation(Scene.random(n, r, dim=3, temperature=1.0, seed=seed))
    sim.run(stop_when={"collisions_per_particle": 50}, store=())
    sim = Simulation(sim.scene)  # counters from here
    sim.run(stop_when={"collisions_per_particle": collisions}, store=())
    st = sim.stats
    volume = float(np.prod(sim.scene.upper - sim.scene.lower))
    temp = 2.0 * st["kinetic_energy"] / (3 * n)
    tau = sim.time / st["collisions_per_particle"] * math.sqrt(temp) / (2.0 * r)
    return st["pressure"] / (n / volume * temp), tau


def _eos_rows(cfg, mean_row):
    """The equation of state and the mean free time against Pieprzyk et al. 2019."""
    runs, collisions = (10, 100) if cfg.quick else (10, 1000)
    rows = []
    for eta, n in EOS_CASES:
        out = [eos_run(eta, n, collisions, seed=300 + k) for k in range(runs)]
        z_md = float(theory.pieprzyk_compressibility(eta))
        what = (
            f"elastic hard spheres at packing {eta:.4f} (EDMD, N = {n}, 3D periodic, "
            f"{collisions} collisions per particle after 50, each run)"
        )
        rows.append(
            mean_row(
                f"eos.elastic.eta{eta:.2f}",
                f"compressibility factor Z = P / (n T) of {what}; theory: Pieprzyk, Bannerman, "
                f"Branka, Chudak & Heyes 2019's fit to MD (theory.pieprzyk_compressibility; "
                f"Carnahan-Starling {float(theory.compressibility_factor(eta)):.4f})",
                [z for z, _ in out],
                theory_value=z_md,
            )
        )
        if n != 1372:
            continue
        density = 6.0 * eta / math.pi  # n sigma^3
        g = (z_md - 1.0) / (4.0 * eta)
        rows.append(
            mean_row(
                f"eos.mean_free_time.eta{eta:.2f}",
                f"mean free time tau sqrt(T / m) / sigma of {what}; theory: 1 / (4 sqrt(pi) "
                f"n sigma^3 g(sigma)), exact in equilibrium, with the contact value of "
                f"Pieprzyk et al. 2019's Z (Lue's MD at N = 1372, doi:10.1063/1.1834498 as "
                f"DynamO's tests quote it: {LUE_MEAN_FREE_TIME})",
                [tau for _, tau in out],
                theory_value=1.0 / (4.0 * math.sqrt(math.pi) * density * g),
            )
        )
    return rows


# The NEMD route: each packing's sweep of the reduced shear rate gamma* (start, end) and the
# largest gamma* fitted.  In the dilute gas gamma* = 0.78 gamma tau (tau the mean free
# time), so the fit stays at gamma tau < 0.25; at 0.30 gamma tau = 0.1 gamma*, where the
# viscosity hardly thins over the sweep (docs/shear.md, "Viscosity").
NEMD_SWEEP = {0.05: (0.5, 0.04, 0.3), 0.30: (1.0, 0.1, 0.6)}
NEMD_WINDOWS = 48


def _nemd_sizes(cfg):
    return (500, 4) if cfg.quick else (1000, 8)


def nemd_run(eta, n, start, end, seed, windows=NEMD_WINDOWS):
    """One sheared run of elastic spheres at packing ``eta`` (3D periodic cube, N = ``n``,
    T = 1 at the start with the linear flow profile already in place): the reduced shear
    rate falls from ``start`` to about ``end`` as the gas heats.  Sampled in ``windows``
    windows of equal growth of sqrt(T) as predicted by Enskog's viscosity (d sqrt(T)/dt
    = eta*_E gamma^2 / (3 n sigma^2) is constant, from d T / dt = 2 eta gamma^2 / (3 n)).
    Returns ``transport.shear_windows`` of the run."""
    r = (eta / n / (4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sigma = 2.0 * r
    rate = start / sigma
    scene = transport.with_shear_profile(
        Scene.random(n, r, dim=3, temperature=1.0, seed=seed), rate
    )
    density = n / float(np.prod(scene.upper - scene.lower))
    eta_e = float(theory.enskog_viscosity(eta, radius=r, temperature=1.0)) * sigma**2
    growth = eta_e * rate**2 / (3.0 * density * sigma**2)  # d sqrt(T) / dt
    times = (np.geomspace(1.0, start / end, windows + 1) - 1.0) / growth
    sim = Simulation(scene, stress=True)
    tr = sim.run(float(times[-1]), sample_times=times, store=())
    return transport.shear_windows(tr)


def measure_nemd(eta, n, runs, seed=2900):
    """The NEMD viscosity at packing ``eta`` from ``runs`` independent sheared runs:
    (the gamma*^2 extrapolation, the sqrt(gamma*) one, the runs' windows)."""
    start, end, fit = NEMD_SWEEP[eta]
    windows = [nemd_run(eta, n, start, end, seed + k) for k in range(runs)]
    quad = transport.nemd_viscosity(windows, max_rate=fit, power=2.0)
    root = transport.nemd_viscosity(windows, max_rate=fit, power=0.5)
    return quad, root, windows


def _nemd_rows(cfg, out, save, fig, row, green_kubo):
    """The NEMD rows and ``viscosity_nemd.png`` (eta* against gamma*, the fits)."""
    n, runs = _nemd_sizes(cfg)
    rows = []
    f, axes = fig(2)
    for ax, eta in zip(axes, PACKINGS, strict=True):
        quad, root, windows = measure_nemd(eta, n, runs)
        ens = float(theory.enskog_viscosity(eta, radius=0.5, temperature=1.0))  # sigma = 1
        gk, gk_err = green_kubo[eta]
        apart = abs(quad.value - gk) / math.hypot(quad.error, gk_err)
        start, end, fit = NEMD_SWEEP[eta]
        rows.append(
            row(
                f"viscosity.elastic.nemd.eta{eta:.2f}",
                f"shear viscosity eta* of elastic hard spheres at packing {eta} from sheared "
                f"runs (EDMD, Lees-Edwards, N = {n}, {runs} runs, no thermostat: the gas "
                f"heats and gamma* falls from {start:g} to {end:g}), eta* = eta*_0 + c "
                f"gamma*^2 fitted over gamma* <= {fit:g} (c = {quad.slope:.3f}; the "
                f"sqrt(gamma*) form gives {root.value:.4f} +- {root.error:.4f}), error from "
                f"the runs' spread; Green-Kubo row {gk:.4f} +- {gk_err:.4f}, "
                f"{apart:.1f} combined sigma apart; theory: Enskog",
                quad.value,
                quad.error,
                runs,
                None,
                ens,
            )
        )
        g = np.concatenate([w.shear_rate for w in windows])
        e = np.concatenate([w.viscosity for w in windows])
        ax.plot(g, e, ".", color="0.6", ms=3, label="windows (all runs)")
        grid = np.linspace(0.0, fit, 50)
        for res, colour, what in (
            (quad, "C0", r"$\propto \dot\gamma^{*2}$"),
            (root, "C1", r"$\propto \sqrt{\dot\gamma^*}$"),
        ):
            ax.plot(grid, res.value + res.slope * grid**res.power, colour,
                    label=f"fit {what}: {res.value:.4f} +- {res.error:.4f}")  # fmt: skip
        ax.errorbar([0.0], [gk], yerr=[gk_err], fmt="s", color="C2", capsize=3,
                    label="Green-Kubo (Einstein-Helfand)")  # fmt: skip
        ax.axhline(ens, color="k", ls="--", lw=0.8, label="Enskog (first Sonine)")
        ax.axvline(fit, color="0.8", lw=0.8)
        ax.set_xlabel(r"reduced shear rate $\dot\gamma^* = \dot\gamma\sigma/\sqrt{T/m}$")
        ax.set_ylabel(r"$\eta^* = -P_{xy}\sigma^2 / (\dot\gamma\sqrt{mT})$")
        ax.set_title(f"NEMD, packing {eta}")
        ax.set_xlim(0.0, start)
        ax.legend(fontsize=7)
    return save(f, out, "viscosity_nemd.png"), rows


# Lue's MD self-diffusion coefficient at n sigma^3 = 0.5, N = 1372 (doi:10.1063/1.1834498,
# quoted by DynamO's tests, src/dynamo/tests/hardsphere_test.cpp), D* in the box
LUE_DIFFUSION = 0.247


def _diffusion_rows(cfg, out, save, fig, mean_row):
    """The self-diffusion rows against Pieprzyk et al. 2019 and ``diffusion_elastic.png``
    (the running slope against the lag, the windows)."""
    n, runs, collisions = _diffusion_sizes(cfg)
    rows = []
    f, ax = fig(1, size=(6.5, 4.5))
    for k, density in enumerate(DIFFUSION_DENSITIES):
        eta = math.pi * density / 6.0
        out_runs = [
            diffusion_run(density, n, collisions, seed=500 + 17 * k + j) for j in range(runs)
        ]
        d_l = np.array([o[0] for o in out_runs])
        d_inf = np.array([o[1] for o in out_runs])
        lo, hi = diffusion_window(density, n)
        box = (n / density) ** (1.0 / 3.0)
        correction = float(np.mean(d_inf - d_l))
        pieprzyk = float(theory.pieprzyk_diffusion(eta, radius=0.5, temperature=1.0))
        speedy = float(theory.speedy_diffusion(eta, radius=0.5, temperature=1.0))
        enskog = float(theory.enskog_diffusion(eta, radius=0.5, temperature=1.0))
        visc = float(theory.enskog_viscosity(eta, radius=0.5, temperature=1.0))
        lue = (
            f"; Lue's MD at N = 1372 in the box, doi:10.1063/1.1834498: {LUE_DIFFUSION}"
            if density == 0.5
            else ""
        )
        rows.append(
            mean_row(
                f"diffusion.elastic.eta{eta:.4f}",
                f"self-diffusion D* = D sqrt(m / T) / sigma of elastic hard spheres at n sigma^3 "
                f"= {density:g}, packing {eta:.4f} (EDMD, N = {n}, 3D periodic cube of side "
                f"{box:.2f} sigma, {runs} runs), the MSD's slope over lags {lo:.1f}-{hi:.1f} "
                f"sigma sqrt(m / T), past the box's slowest shear mode (D_L* = "
                f"{d_l.mean():.4f} +- {d_l.std(ddof=1) / math.sqrt(runs):.4f}{lue}), "
                f"corrected to infinite N by Yeh & Hummer with Enskog's viscosity eta* = "
                f"{visc:.3f}: +{correction:.4f}; theory: Pieprzyk, Bannerman, Branka, Chudak & "
                f"Heyes 2019's MD, infinite N, as transcribed in a public script "
                f"(theory.pieprzyk_diffusion; Speedy's 1987 N ~ 500 representation "
                f"{speedy:.4f}, Enskog first Sonine {enskog:.4f})",
                list(d_inf),
                theory_value=pieprzyk,
            )
        )
        colour = f"C{k}"
        running = np.mean([o[3] for o in out_runs], axis=0)  # the same reduced lags
        ax.plot(out_runs[0][2], (running + correction) / pieprzyk, colour,
                label=rf"$n\sigma^3 = {density:g}$: running slope + Yeh-Hummer")  # fmt: skip
        ax.errorbar(
            [(1.4 + 0.1 * k) * lo], [d_inf.mean() / pieprzyk],
            yerr=[d_inf.std(ddof=1) / math.sqrt(runs) / pieprzyk],
            fmt="o", color=colour, capsize=3,
            label=rf"$n\sigma^3 = {density:g}$: slope over the window",
        )  # fmt: skip
        ax.axvspan(lo, hi, color=colour, alpha=0.12)
        ax.axhline(enskog / pieprzyk, color=colour, lw=0.8, ls=":",
                   label=rf"$n\sigma^3 = {density:g}$: Enskog (first Sonine)")  # fmt: skip
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="Pieprzyk et al. 2019 (MD, infinite N)")
    ax.set_xscale("log")
    ax.set_ylim(0.6, 1.1)
    ax.set_xlabel(r"lag / $\sigma\sqrt{m/T}$")
    ax.set_ylabel(r"$D^*$ / Pieprzyk et al.")
    ax.set_title(f"self-diffusion, N = {n}: the MSD's running slope")
    ax.legend(fontsize=7)
    return save(f, out, "diffusion_elastic.png"), rows


def _fig_transport(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run both packings, write ``transport_elastic.png``, return (file names, rows)."""
    n, taus = _sizes(cfg)
    rows = []
    green_kubo = {}
    f, ax_v = fig(1)
    for k, eta in enumerate(PACKINGS):
        visc, temp, sigma, tau = measure(eta, n, taus)
        r = sigma / 2.0
        green_kubo[eta] = (
            visc.value * sigma**2 / math.sqrt(temp),
            visc.error * sigma**2 / math.sqrt(temp),
        )
        ens_v = float(theory.enskog_viscosity(eta, radius=r, temperature=temp))
        red_v = sigma**2 / math.sqrt(temp)  # eta* = eta sigma^2 / sqrt(m T), m = 1
        expect = (
            "Enskog near-exact here (first Sonine: 1.6 % low)"
            if eta < 0.1
            else "correlated collisions expected to raise it above Enskog (Pieprzyk et al. "
            "2019 tabulate by how much; not found for this version)"
        )
        suffix = f".eta{eta:.2f}"
        rows.append(
            row(
                "viscosity.elastic.green_kubo" + suffix,
                f"shear viscosity eta* = eta sigma^2 / sqrt(m T) of elastic hard spheres at "
                f"packing {eta} (EDMD, N = {n}, 3D periodic, {taus:g} tau, Einstein-Helfand "
                f"slope over {VISCOSITY_FIT[0]:g}-{VISCOSITY_FIT[1]:g} tau, 5 shear "
                f"components, error from 10 blocks); theory: Enskog ({expect})",
                visc.value * red_v,
                visc.error * red_v,
                None,
                None,
                ens_v * red_v,
            )
        )
        colour = f"C{k}"
        lags = visc.lags / tau
        ax_v.plot(lags, visc.curve / visc.lags / ens_v, colour, label=f"packing {eta}: ratio")
        ax_v.errorbar(
            [np.mean(VISCOSITY_FIT) + 0.2 * k], [visc.value / ens_v], yerr=[visc.error / ens_v],
            fmt="o", color=colour, capsize=3, label=f"packing {eta}: slope over the window",
        )  # fmt: skip
    ax_v.axvspan(*VISCOSITY_FIT, color="0.9")
    ax_v.axhline(1.0, color="k", lw=0.8, ls="--")
    ax_v.set_xlabel(r"lag / mean free time $\tau$")
    ax_v.set_ylabel(r"$\langle \Delta G^2 \rangle / (2 V T t)$ / Enskog")
    ax_v.legend(fontsize=7)
    ax_v.set_title("shear viscosity (Einstein-Helfand)")
    names = [save(f, out, "transport_elastic.png")]
    diffusion_name, diffusion = _diffusion_rows(cfg, out, save, fig, mean_row)
    nemd_name, nemd = _nemd_rows(cfg, out, save, fig, row, green_kubo)
    return [*names, diffusion_name, nemd_name], rows + diffusion + nemd + _eos_rows(cfg, mean_row)
