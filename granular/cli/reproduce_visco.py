"""The reproduction's viscoelastic experiment: the thesis' "further work" gas whose
restitution grows towards 1 as collisions slow down (``granular.Viscoelastic``).

Three parts, each against ``granular.theory``:

- **Cooling and diffusion (EDMD).**  The thesis' 3D density (n = 1000, r = 0.025,
  eta = 0.065) in a periodic box of N = 250 (side 0.63, below the critical size of the
  shear instability even at the gas' most inelastic, its start: the gas only grows more
  elastic), started from a molecular gas equilibrated for 20 collisions per particle whose
  velocities each run shuffles (thesis 3.8), with ``delta(T0)`` = ``DELTA0`` = 0.1 (1 - eps
  about 11% at the mean impact speed; the series' clamp at delta = 0.25 is then never
  reached: max_speed is 159, the thermal speed 1.4).  Runs to ``T_MAX`` tau0' (10^4 full, 10^3
  quick), where T has fallen by 5-7 decades.  The rows fit the local exponents d ln T /
  d ln t and d ln MSD / d ln t per run over the last decade, [T_MAX / 10, T_MAX] tau0', and
  compare them with the same fit of the **full second-order expressions**
  (``viscoelastic_temperature_second_order``, ``msd_viscoelastic_second_order``): the
  asymptotes -5/3 and 1/6 are approached so slowly (the MSD's within 10% only from
  ~10^6 tau0') that a late fit against them would measure the approach, not the physics;
  the quantity texts state the leading-order expressions' exponents and the asymptotes
  beside them.
- **Power-law UDSBM** (``langevin.from_scene`` of the same scene: exponent 5/6, tau0' of
  theory), its MSD exponent over [10^2, 10^3] tau0' against ``msd_powerlaw_udsbm``'s.
- **No inelastic collapse.**  2D disks between walls (N = 1000, area fractions 0.4 and
  0.6, xi = 0.8): the seeds whose constant-xi run collapses within 400 collisions per
  particle are run again with the viscoelastic law whose eps, averaged over the collisions
  of the initial Maxwellian gas, is 0.8 (as tests/test_restitution.py): slow collisions
  are nearly elastic, so the collapse's geometric series of ever faster collisions cannot
  close (Schwager & Poeschel 1998; Brilliantov & Poeschel 2004, ch. 6).  The row counts
  those that collapse anyway: 0 expected.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np

from .. import Scene, Simulation, Viscoelastic, analysis, langevin, plot, theory
from ..errors import InelasticCollapseError

DENSITY, RADIUS, N = 1000.0, 0.025, 250  # the thesis' density; a box below L_c
DELTA0 = 0.1  # delta(T0): 1 - eps ~ 11% at the start, the law's clamp never reached
UDSBM_T_MAX = 1e3  # tau0': the power-law UDSBM's run (its window [1e2, 1e3] tau0')
COLLAPSE_N, COLLAPSE_XI, COLLAPSE_ETAS = 1000, 0.8, (0.4, 0.6)
COLLAPSE_CPP = 400  # collisions per particle each collapse run aims at


def _t_max(cfg):
    return 1e3 if cfg.quick else 1e4


def _equilibrated(seed=2020):
    side = (N / DENSITY) ** (1 / 3)
    sim = Simulation(Scene.random(N, RADIUS, box=(np.zeros(3), np.full(3, side)), seed=seed))
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    return sim.scene


def _slope(times, values, window):
    """Least-squares slope of ln values against ln t over the times in ``window``."""
    return analysis.fit_power_law(times, values, t_min=window[0], t_max=window[1])[0]


@functools.lru_cache(maxsize=8)
def matched_law(xi, temperature, mass=1.0):
    """The Viscoelastic law whose eps averaged over the collisions of a Maxwellian gas at
    ``temperature`` is ``xi``: eps(g) weighted by the density of the normal impact speed
    g of colliding pairs, (g / s^2) exp(-g^2 / 2 s^2), s^2 = 2 T / m, bisected in the
    damping (kappa = 1)."""
    sd = math.sqrt(2.0 * temperature / mass)
    g = np.linspace(0.0, 12 * sd, 20_001)  # trapezoid error ~1e-8
    weight = g / sd**2 * np.exp(-(g**2) / (2 * sd**2))

    def mean_eps(damping):
        return np.trapezoid(Viscoelastic(damping, 1.0)(g) * weight, g)

    lo, hi = 1e-4, 1.0  # mean_eps falls with the damping
    for _ in range(40):  # to 1e-12 in the damping
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mean_eps(mid) > xi else (lo, mid)
    return Viscoelastic(lo, 1.0)


def _collapse_case(eta, seed):
    """One walled 2D scene: (collapse time with constant xi or None, the viscoelastic
    run's (time reached, collapsed?, clamped collisions) or None if xi did not collapse)."""
    r = math.sqrt(eta / (COLLAPSE_N * math.pi))
    s = Scene.random(
        COLLAPSE_N, r, dim=2, boundary="walls", restitution=COLLAPSE_XI, temperature=1.0,
        seed=seed,
    )  # fmt: skip
    goal = {"collisions_per_particle": COLLAPSE_CPP}
    try:
        Simulation(s).run(stop_when=goal, store=())
        return None, None
    except InelasticCollapseError as e:
        collapse_at = e.time
    sim = Simulation(s.replace(restitution=matched_law(COLLAPSE_XI, s.temperature)))
    with warnings.catch_warnings():
        # the hot start's few fastest collisions exceed max_speed (counted: reported)
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            sim.run(stop_when=goal, store=())
            collapsed = False
        except InelasticCollapseError:
            collapsed = True
    return collapse_at, (sim.time, collapsed, sim.stats["law_clamped_collisions"])


def _fig_visco(cfg, out, *, ensemble, save, fig, row, mean_row):
    """Run the three parts, write ``visco_cooling_msd.png`` and ``visco_collapse.png``,
    return (file names, rows)."""
    # quick: 60 runs, so that the cooling exponent resolves the second order from the leading
    # one (1% apart in the quick window; standard error ~0.15%: tests/test_cli.py)
    runs = 2 * cfg.runs_few if not cfg.quick else 60  # 40 (full): ~0.15 s each
    eq = _equilibrated()
    T0, eta = eq.temperature, eq.packing_fraction
    law = Viscoelastic(DELTA0 / (4 * T0) ** 0.1, 1.0)
    scene = eq.replace(restitution=law)
    c = langevin.coefficients_from_scene(scene)
    tau = c.tau0
    t_max = _t_max(cfg)
    times = np.concatenate([[0.0], np.geomspace(0.01 * tau, t_max * tau, 51)])
    window = (0.099 * t_max * tau, t_max * tau * 1.0001)
    res = ensemble(
        scene, runs, seed=15, t_stop=times[-1], sample_times=times,
        quantities=("temperature", "msd"),
    )  # fmt: skip
    gas = dict(temperature0=T0, a_kappa=law, density=DENSITY, radius=RADIUS, eta=eta)
    # theory gives an array for an array of times (its annotation says float or array)
    T2 = np.asarray(theory.viscoelastic_temperature_second_order(times, **gas))
    T1 = np.asarray(theory.viscoelastic_temperature(times, temperature0=T0, tau0=tau))
    m2 = np.asarray(theory.msd_viscoelastic_second_order(times, **gas))
    m1 = np.asarray(theory.msd_viscoelastic(times, D0=c.D0, tau0=tau))
    names, rows = [], []

    # the box against the critical size at the gas' most inelastic moment, its start
    eps_eff = 1 - theory.VISCOELASTIC_C1 * math.gamma(2.1) * DELTA0
    l_over_lc = float(eq.upper[0] - eq.lower[0]) / float(
        theory.critical_box_size(density=DENSITY, radius=RADIUS, restitution=eps_eff, eta=eta)
    )
    t_slopes = [_slope(times, r["temperature"], window) for r in res.runs]
    s1, s2 = _slope(times, T1, window), _slope(times, T2, window)
    rows.append(
        mean_row(
            "visco.haff.exponent",
            f"d ln T / d ln t of the viscoelastic gas (EDMD, N = {N}, 3D periodic, "
            f"delta(T0) = {DELTA0}, L / L_c = {l_over_lc:.2f} at the start), fitted over "
            f"t / tau0' = {t_max / 10:g} ... {t_max:g}; "
            f"theory: the same fit of the second-order law "
            f"(viscoelastic_temperature_second_order); the leading order gives {s1:.4f} there, "
            f"its asymptote -5/3",
            t_slopes,
            None,
            s2,
        )
    )
    m_slopes = [_slope(times, r["msd"], window) for r in res.runs]
    q1, q2 = _slope(times, m1, window), _slope(times, m2, window)
    rows.append(
        mean_row(
            "visco.msd.exponent",
            f"d ln MSD / d ln t of the viscoelastic gas (EDMD, as visco.haff.exponent), "
            f"t / tau0' = {t_max / 10:g} ... {t_max:g}; theory: the same fit of "
            f"msd_viscoelastic_second_order; the leading order (msd_viscoelastic) gives "
            f"{q1:.4f} there, the asymptote 1/6 = 0.1667 (the MSD within 10% of its asymptote only "
            f"from ~1e6 tau0')",
            m_slopes,
            None,
            q2,
        )
    )

    # power-law UDSBM of the same scene
    u_times = np.concatenate([[0.0], np.geomspace(0.01 * tau, UDSBM_T_MAX * tau, 41)])
    u_window = (0.099 * UDSBM_T_MAX * tau, UDSBM_T_MAX * tau * 1.0001)
    ures = ensemble(
        functools.partial(
            langevin.from_scene, scene, dt=0.04 * tau, t_stop=u_times[-1],
            sample_times=u_times, n=300 if not cfg.quick else 100,
        ),
        10 if cfg.quick else 20,
        seed=16,
    )  # fmt: skip
    ut = ures.times
    n_u = ures.runs[0]["final_positions"].shape[0]
    u_slopes = [_slope(ut, r["msd"], u_window) for r in ures.runs]
    u_th = np.asarray(
        theory.msd_powerlaw_udsbm(
            ut, D0=c.D0, gamma0=c.gamma0, tau0=tau, exponent=langevin.VISCOELASTIC_EXPONENT
        )
    )
    rows.append(
        mean_row(
            "visco.udsbm.msd.exponent",
            f"d ln MSD / d ln t of the power-law UDSBM (langevin.from_scene of the viscoelastic "
            f"scene: a = 5/6, exact scheme, dt = 0.04 tau0', {n_u} particles per run), "
            f"t / tau0' = {UDSBM_T_MAX / 10:g} ... {UDSBM_T_MAX:g}; theory: the same fit of "
            f"msd_powerlaw_udsbm; asymptote 1/6",
            u_slopes,
            None,
            _slope(ut, u_th, u_window),
        )
    )

    # no collapse
    seeds = range(1, 6 if cfg.quick else 11)
    etas = COLLAPSE_ETAS[:1] if cfg.quick else COLLAPSE_ETAS
    cases = [(eta_, seed, *_collapse_case(eta_, seed)) for eta_ in etas for seed in seeds]
    collapsing = [k for k in cases if k[2] is not None]
    visco_collapsed = sum(k[3][1] for k in collapsing)
    clamped = sum(k[3][2] for k in collapsing)
    # how far past its constant-xi collapse each viscoelastic run went, in time
    beyond = min((k[3][0] / k[2] for k in collapsing), default=math.nan)
    rows.append(
        row(
            "visco.collapse.2d",
            f"runs that collapse with the viscoelastic law (mean eps {COLLAPSE_XI} over the "
            f"initial collisions), out of the {len(collapsing)} of {len(cases)} walled 2D "
            f"scenes (N = {COLLAPSE_N}, area fractions {', '.join(map(str, etas))}) that "
            f"collapse with xi = {COLLAPSE_XI} within {COLLAPSE_CPP} collisions per particle; "
            f"each viscoelastic run reaches at least {beyond:.1f} times its constant-xi "
            f"collapse time; {clamped} collisions past the law's max_speed; theory: 0",
            visco_collapsed,
            None,
            len(collapsing),
            None,
            0.0,
        )
    )

    # figure: cooling, MSD, local exponents
    f, axes = fig(3, size=(5.0, 4.2))
    s = times[1:] / tau
    T, Te = res.mean["temperature"], res.error["temperature"]
    ax = axes[0]
    ax.errorbar(s, T[1:] / T0, yerr=Te[1:] / T0, fmt=".", color="C0", label=f"EDMD ({runs} runs)")
    ax.plot(s, T2[1:] / T0, "-", color="C1", label="theory, second order")
    ax.plot(s, T1[1:] / T0, "--", color="C2", label=r"leading order $(1 + t/\tau_0')^{-5/3}$")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$t / \tau_0'$ (dimensionless)")
    ax.set_ylabel(r"$T / T_0$ (dimensionless)")
    ax.set_title(rf"Cooling, viscoelastic gas, $\delta(T_0)$ = {DELTA0}")
    ax.legend(fontsize="small")
    ax = axes[1]
    m, me = res.mean["msd"], res.error["msd"]
    ax.errorbar(s, m[1:], yerr=me[1:], fmt=".", color="C0", label="EDMD")
    ax.plot(s, m2[1:], "-", color="C1", label="theory, second order")
    ax.plot(s, m1[1:], "--", color="C2", label=r"leading order ($\propto t^{1/6}$ late)")
    ax.plot(
        s, theory.msd_viscoelastic_asymptote(times[1:], D0=c.D0, tau0=tau), ":", color="0.4",
        label=r"asymptote $\propto t^{1/6}$",
    )  # fmt: skip
    um = ures.mean["msd"]
    ax.plot(ut[1:] / tau, um[1:], "x", ms=4, color="C3", label="power-law UDSBM (a = 5/6)")
    ax.plot(ut[1:] / tau, u_th[1:], "-", lw=0.8, color="C3", label="its theory")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"$t / \tau_0'$ (dimensionless)")
    ax.set_ylabel(plot.MSD)
    ax.set_title("Mean squared displacement")
    ax.legend(fontsize="x-small")
    ax = axes[2]
    mid = np.sqrt(times[1:-1] * times[2:]) / tau
    for y, th2, th1, colour, label in (
        (T, T2, T1, "C0", "T"),
        (m, m2, m1, "C4", "MSD"),
    ):
        lt = np.log(times[1:])
        ax.plot(
            mid, np.diff(np.log(y[1:])) / np.diff(lt), ".", color=colour, label=f"EDMD, {label}"
        )
        ax.plot(mid, np.diff(np.log(th2[1:])) / np.diff(lt), "-", color=colour, lw=1)
        ax.plot(mid, np.diff(np.log(th1[1:])) / np.diff(lt), "--", color=colour, lw=1)
    ax.axhline(-5 / 3, color="0.4", ls=":", lw=1)
    ax.axhline(1 / 6, color="0.4", ls=":", lw=1)
    ax.axvspan(window[0] / tau, window[1] / tau, color="0.9")
    ax.set_xscale("log")
    ax.set_xlabel(r"$t / \tau_0'$ (dimensionless)")
    ax.set_ylabel(r"local exponent $d \ln y / d \ln t$ (dimensionless)")
    ax.set_title("Exponents: second order (-), leading (--),\nasymptotes -5/3, 1/6 (:)")
    ax.legend(fontsize="x-small")
    names.append(save(f, out, "visco_cooling_msd.png"))

    # figure: collapse against no collapse
    f2, ax2 = fig(1)
    constant = rf"constant $\xi$ = {COLLAPSE_XI}: collapse"
    visco = r"viscoelastic, mean $\varepsilon$ = $\xi$: end of run (o) or collapse (x)"
    for k, (eta_, seed, t_c, v) in enumerate(collapsing):
        ax2.plot([k, k], [t_c, v[0]], "-", color="0.7", lw=1)
        ax2.plot(k, t_c, "x", color="C3", label=constant if k == 0 else None)
        marker, colour = ("x", "C3") if v[1] else ("o", "C2")
        ax2.plot(
            k, v[0], marker, color=colour, mfc="none",
            label=visco if k == 0 else None,
        )  # fmt: skip
        ax2.annotate(f"{eta_:g}/{seed}", (k, t_c), fontsize=6, xytext=(2, -8),
                     textcoords="offset points")  # fmt: skip
    ax2.set_yscale("log")
    ax2.set_xlabel(r"scene (label: area fraction / seed) that collapses at constant $\xi$")
    ax2.set_ylabel(plot.TIME)
    ax2.set_title(
        rf"2D walls, N = {COLLAPSE_N}: collapse at $\xi$ = {COLLAPSE_XI}, not viscoelastic"
    )
    ax2.legend(fontsize="small")
    names.append(save(f2, out, "visco_collapse.png"))
    return names, rows


def notes(by_id):
    """Sentences for report.md's viscoelastic section, conditional on the rows."""
    text = []
    col = by_id.get("visco.collapse.2d")
    if col is not None:
        text.append(
            f"Of the {col['runs']} walled 2D scenes that collapse at constant xi, "
            f"{col['ours']:.0f} collapse with the viscoelastic law of the same mean restitution"
            + (": slow collisions are nearly elastic, so no collapse." if not col["ours"] else ".")
        )
    text.append(
        "The exponents are compared with the second-order expressions over the same late window, "
        "not with the asymptotes -5/3 and 1/6, which the gas approaches as delta(T(t)) ~ t^(-1/6): "
        "far beyond any affordable run for the MSD (visco_cooling_msd.png, right)."
    )
    return text
