"""The viscoelastic gas end to end: the engine's law and granular.theory speak of the same
material number (a_kappa = A kappa^(2/5)), the Langevin side builds its power-law UDSBM from
a viscoelastic Scene, and an EDMD viscoelastic gas cools as the theory says.

Statistical checks pass when ``|ours - theory| <= t * error + margin * |theory|``: error the
standard error over K independent runs, t Student's quantile for a two-sided false-alarm
rate of 1e-4 per check, margin the theory's own accuracy, stated where it is set."""

import math

import numpy as np
import pytest
from scipy import stats

import granular
from granular import (
    Scene,
    Simulation,
    TabulatedRestitution,
    Viscoelastic,
    clustering,
    langevin,
    theory,
)

from helpers.margins import diffusion_margin

FALSE_ALARM = 1e-4
DENSITY, R = 1000.0, 0.025  # the thesis' 3D gas (eta = 0.065)
N = 250  # a periodic box of side 0.63, well below the critical size (checked below)
DELTA0 = 0.1  # delta(T0) = a_kappa (4 T0 / m)^(1/10): 1 - eps ~ 11% at T0


def _student(runs):
    return stats.t.ppf(1 - FALSE_ALARM / 2, runs - 1)


# -- one material number ----------------------------------------------------------------------


def test_law_and_theory_share_a_kappa():
    """Viscoelastic.a_kappa is the A kappa^(2/5) theory takes: the engine's eps at the
    impact speed g is 1 - C1 a_kappa g^(1/5) + C2 (a_kappa g^(1/5))^2, and the theory's
    delta at T is a_kappa (4T/m)^(1/10); the theory functions take the law itself too."""
    law = Viscoelastic.from_material(young=1e7, poisson=0.3, damping=1e-5, radius=0.025, mass=1)
    # Brilliantov & Poeschel's kappa = (3/2)^(3/2) Y sqrt(R_eff) / (m_eff (1 - nu^2)), with
    # R_eff = R / 2 and m_eff = m / 2 for two equal spheres, written out here
    kappa = 1.5**1.5 * 1e7 * math.sqrt(0.025 / 2) / (0.5 * (1 - 0.3**2))
    assert law.kappa == pytest.approx(kappa, rel=1e-14)
    assert law.a_kappa == pytest.approx(1e-5 * kappa**0.4, rel=1e-14)
    g = 0.7
    d = law.a_kappa * g**0.2
    assert law(g) == pytest.approx(
        1 - theory.VISCOELASTIC_C1 * d + theory.VISCOELASTIC_C2 * d * d, rel=1e-15
    )
    T = 0.5
    assert theory.viscoelastic_delta(T, a_kappa=law) == theory.viscoelastic_delta(
        T, a_kappa=law.a_kappa
    )
    assert theory.viscoelastic_delta(T, a_kappa=law) == pytest.approx(law.a_kappa * (4 * T) ** 0.1)
    box = dict(n=N, radius=R, volume=N / DENSITY, temperature0=T)
    assert theory.viscoelastic_langevin_coefficients(
        a_kappa=law, **box
    ) == theory.viscoelastic_langevin_coefficients(a_kappa=law.a_kappa, **box)
    gas = dict(density=DENSITY, radius=R, temperature0=T)
    assert theory.viscoelastic_tau0(a_kappa=law, **gas) == theory.viscoelastic_tau0(
        a_kappa=law.a_kappa, **gas
    )
    with pytest.raises(TypeError, match="Viscoelastic"):
        theory.viscoelastic_tau0(
            a_kappa=TabulatedRestitution([0, 1], [1, 0.9]),
            density=DENSITY,
            radius=R,
            temperature0=T,
        )


def test_from_scene_gives_the_powerlaw_udsbm_of_a_viscoelastic_scene():
    """A Scene with a Viscoelastic restitution stands for the power-law UDSBM with exponent
    5/6 and tau0' of theory; a tabulated law has no model and says what is supported."""
    law = Viscoelastic(0.09, 1.0)
    scene = Scene.random(N, R, box=(np.zeros(3), np.full(3, 0.63)), restitution=law, seed=1)
    c = langevin.coefficients_from_scene(scene)
    assert c == theory.viscoelastic_langevin_coefficients(
        n=N, radius=R, volume=scene.volume, a_kappa=law.a_kappa, temperature0=scene.temperature
    )
    assert c.tau0 == theory.viscoelastic_tau0(
        a_kappa=law, density=N / scene.volume, radius=R, temperature0=scene.temperature
    )
    res = langevin.from_scene(scene, dt=0.01, t_stop=1.0, n=50, seed=1)
    assert res.exponent == pytest.approx(5 / 6) and res.tau0 == c.tau0
    assert res.model == "udsbm"
    with pytest.raises(TypeError, match=r"TabulatedRestitution.*support a number xi.*Viscoelastic"):
        langevin.from_scene(
            scene.replace(restitution=TabulatedRestitution([0, 1], [1, 0.9])), dt=0.01, t_stop=1
        )
    # a number keeps the thesis' models
    assert langevin.from_scene(scene.replace(restitution=0.8), dt=0.01, t_stop=0.1).exponent == 1


# -- EDMD against the cooling law ----------------------------------------------------------------


@pytest.fixture(scope="module")
def cooling_runs():
    """20 runs of the viscoelastic gas from one equilibrated molecular gas (velocities
    shuffled, the thesis' method 3.8) to t = 1000 tau0' (T falls by about 5 decades, ~400
    collisions per particle; about 4 s in all)."""
    side = (N / DENSITY) ** (1 / 3)
    box = (np.zeros(3), np.full(3, side))
    sim = Simulation(Scene.random(N, R, box=box, seed=2020))
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    eq = sim.scene
    law = Viscoelastic(DELTA0 / (4 * eq.temperature) ** 0.1, 1.0)
    tau = theory.viscoelastic_tau0(
        a_kappa=law, density=DENSITY, radius=R, temperature0=eq.temperature, eta=eq.packing_fraction
    )
    times = np.concatenate([[0.0], np.geomspace(0.1 * tau, 1000 * tau, 25)])
    rng = np.random.default_rng(15)
    temps, msds, clamped, collisions = [], [], 0, 0
    for _ in range(20):
        s = eq.replace(restitution=law, velocities=eq.velocities[rng.permutation(N)])
        run = Simulation(s)
        traj = run.run(t_stop=times[-1], sample_times=times, store=("positions",))
        temps.append(traj.temperature)
        msds.append(traj.msd())
        clamped += run.stats["law_clamped_collisions"]
        collisions += run.stats["pair_collisions"]
    return dict(
        eq=eq, law=law, tau=tau, times=times, T=np.array(temps), msd=np.array(msds), clamped=clamped
    )


def test_viscoelastic_gas_is_in_range_and_below_the_critical_box(cooling_runs):
    """The runs stay where the law and the cooling theory hold: no collision beyond the
    series' delta = 0.25 (max_speed = 160 against a thermal speed of 1.4: a Maxwellian
    pair exceeds it with probability exp(-160^2 / (4 T0)), i.e. never), and the box is
    below the critical size of the shear instability even at its most inelastic, at T0:
    L_c at the law's effective restitution there (the constant xi that cools as fast,
    0.888) is 2.07, and L_c only grows as the gas cools and grows more elastic.  So the
    ClusteringWarning has nothing to say."""
    r = cooling_runs
    assert r["clamped"] == 0
    eq = r["eq"]
    xi_eff = clustering.effective_restitution(r["law"], eq.temperature)
    lc = theory.critical_box_size(
        density=DENSITY, radius=R, restitution=xi_eff, eta=eq.packing_fraction
    )
    assert eq.upper[0] - eq.lower[0] < 0.5 * lc
    assert clustering.unstable_box(eq.replace(restitution=r["law"])) is None


def test_viscoelastic_gas_cools_as_the_second_order_theory(cooling_runs):
    """<T(t)> over 20 runs against theory.viscoelastic_temperature_second_order at every
    sample, t = 0.1 ... 1000 tau0'.  Margin 2% of theory: the next term of the restitution
    series changes the cooling rate by a relative (1.34 delta)^2 <= 1.8% (zeta_2 / zeta_1 =
    -1.34 delta, and the series' terms fall geometrically while delta <= 0.25); the
    neglected Sonine a2 and the short-range velocity correlations (tests/test_cli's
    cluster.haff.small) are of percent order.  Measured: within 1%."""
    r = cooling_runs
    eq, times = r["eq"], r["times"]
    mean = r["T"].mean(axis=0)
    err = r["T"].std(axis=0, ddof=1) / math.sqrt(len(r["T"]))
    second = theory.viscoelastic_temperature_second_order(
        times,
        temperature0=eq.temperature,
        a_kappa=r["law"],
        density=DENSITY,
        radius=R,
        eta=eq.packing_fraction,
    )
    tol = _student(len(r["T"])) * err + 0.02 * second
    bad = np.flatnonzero(np.abs(mean - second) > tol)
    assert bad.size == 0, (times[bad] / r["tau"], mean[bad] / second[bad] - 1)


def test_viscoelastic_gas_cooling_exponent_approaches_minus_five_thirds(cooling_runs):
    """The leading order T0 (1 + t/tau0')^(-5/3): its local exponent over the late window
    t = 100 ... 1000 tau0' (fitted per run, ln T against ln t) is -5/3 t/(t + tau0'), within
    0.3% of -5/3 there (-1.662).  The EDMD exponent may differ from the leading order by the
    second-order theory's own difference from it there (|second - leading|, measured 0.01:
    the O(delta) correction that fades like delta(T(t)) ~ t^(-1/6)) plus 0.01 (2% of a
    second-order rate that changes little over the window, see the test above, moves the
    exponent by less than that)."""
    r = cooling_runs
    eq, times, tau = r["eq"], r["times"], r["tau"]
    w = times >= 100 * tau
    lt = np.log(times[w])

    def slope(T):
        return np.polyfit(lt, np.log(T[w]), 1)[0]

    per_run = [slope(T) for T in r["T"]]
    mean, err = np.mean(per_run), np.std(per_run, ddof=1) / math.sqrt(len(per_run))
    lead = slope(theory.viscoelastic_temperature(times, temperature0=eq.temperature, tau0=tau))
    second = slope(
        theory.viscoelastic_temperature_second_order(
            times,
            temperature0=eq.temperature,
            a_kappa=r["law"],
            density=DENSITY,
            radius=R,
            eta=eq.packing_fraction,
        )
    )
    assert lead == pytest.approx(-5 / 3, rel=3e-3)
    tol = _student(len(per_run)) * err + abs(second - lead) + 0.01
    assert abs(mean - lead) <= tol, (mean, err, lead, second)
    print(f"exponent {mean:.4f} +- {err:.4f}; leading {lead:.4f}, second order {second:.4f}")
    # and the second order, the better theory, within the 0.01 alone
    assert abs(mean - second) <= _student(len(per_run)) * err + 0.01, (mean, err, second)


def test_viscoelastic_gas_msd_follows_the_second_order_theory(cooling_runs):
    """<MSD(t)> over the 20 runs against theory.msd_viscoelastic_second_order from
    t = 10 tau0' (past the ballistic start, which the theory's integral of D misses) to
    1000 tau0'.  Margin diffusion_margin(eps_eff) = 7.8% with eps_eff = 0.879 the gas'
    most inelastic (at T0): Enskog's D is ~4% low at this density (tests/helpers/margins.py,
    the thesis' own measurement) plus the O(1 - eps) approximations of the Maxwellian D.
    Measured: 3-5% above.  The leading order, msd_viscoelastic, lies ~20% below EDMD: the
    O(delta) corrections matter."""
    r = cooling_runs
    eq, times = r["eq"], r["times"]
    w = times >= 10 * r["tau"]
    mean = r["msd"].mean(axis=0)[w]
    err = r["msd"].std(axis=0, ddof=1)[w] / math.sqrt(len(r["msd"]))
    theory_msd = theory.msd_viscoelastic_second_order(
        times[w],
        temperature0=eq.temperature,
        a_kappa=r["law"],
        density=DENSITY,
        radius=R,
        eta=eq.packing_fraction,
    )
    eps_eff = 1 - theory.VISCOELASTIC_C1 * math.gamma(2.1) * DELTA0
    tol = _student(len(r["msd"])) * err + diffusion_margin(eps_eff) * theory_msd
    bad = np.flatnonzero(np.abs(mean - theory_msd) > tol)
    assert bad.size == 0, (times[w][bad] / r["tau"], mean[bad] / theory_msd[bad] - 1)


def test_msd_second_order_limits():
    """a_kappa = 0: the elastic gas' 2 d D_E t exactly (no cooling, eps = 1); small a_kappa:
    within O(delta) of the leading order msd_viscoelastic."""
    t = np.geomspace(0.01, 100.0, 9)
    d_e = theory.diffusion_d0(density=DENSITY, radius=R, restitution=1.0, temperature0=0.5)
    elastic = theory.msd_viscoelastic_second_order(
        t, temperature0=0.5, a_kappa=0.0, density=DENSITY, radius=R
    )
    assert elastic == pytest.approx(6 * d_e * t, rel=1e-12)
    law = Viscoelastic(1e-3, 1.0)  # delta(T0) = 1.1e-3
    tau = theory.viscoelastic_tau0(a_kappa=law, density=DENSITY, radius=R, temperature0=0.5)
    ts = np.geomspace(0.1, 100.0, 5) * tau
    ratio = theory.msd_viscoelastic_second_order(
        ts, temperature0=0.5, a_kappa=law, density=DENSITY, radius=R
    ) / (theory.msd_viscoelastic(ts, D0=d_e, tau0=tau))
    # first-order corrections: some delta(T0) (x 1.34 in the rate, 0.6 C1 in D) and the
    # quadrature's 1e-4
    assert np.all(np.abs(ratio - 1) < 5 * 1.1e-3 + 1e-4), ratio


def test_top_level_exports():
    assert granular.Viscoelastic is Viscoelastic
