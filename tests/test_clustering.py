"""granular.clustering (S(k), current correlations, flow energy), the critical box size of
the shear instability in granular.theory, and the ClusteringWarning of Simulation.run.

Every diagnostic is checked on a configuration whose answer is known in closed form; the
tolerances are a few standard deviations of the estimator, derived in the comments."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import granular
from granular import clustering, theory

RNG = np.random.default_rng(20261126)


# -- structure factor -----------------------------------------------------------------------


def test_wave_vectors_one_of_each_pair_and_shells():
    kvecs, shells, idx = clustering.wave_vectors([2.0, 2.0, 2.0], n_max=2.0)
    n = np.rint(kvecs * 2.0 / (2 * np.pi)).astype(int)
    # |n|^2 = 1, 2, 3, 4 in 3D: 6, 12, 8, 6 vectors, half of each +-pair kept
    assert np.bincount(idx).tolist() == [3, 6, 4, 3]
    assert np.allclose(shells, np.pi * np.sqrt([1, 2, 3, 4]))
    assert not any((-v == n).all(1).any() for v in n)  # never both n and -n
    with pytest.raises(ValueError, match="box_lengths"):
        clustering.wave_vectors([1.0, -1.0])
    with pytest.raises(ValueError, match="n_max"):
        clustering.wave_vectors([1.0, 1.0], n_max=0.5)


def test_structure_factor_of_a_lattice():
    """A simple cubic lattice of 6^3 particles filling a periodic box: the phases of a row
    are the 6th roots of unity raised to n, which sum to 0 unless 6 divides n, so S = 0 at
    every |n| < 6 and S = N on the reciprocal lattice vectors (all components divisible by
    6); in the |n| = 6 shell, which also holds (4, 4, 2) and the like, the average is N
    times their share.  Exact up to rounding (1e-12 against N = 216)."""
    m, box = 6, 3.0
    grid = np.stack(np.meshgrid(*[np.arange(m)] * 3, indexing="ij"), -1).reshape(-1, 3) + 0.5
    x = grid * box / m + np.array([5.0, -2.0, 1.0]) * box  # whole periodic images: same S
    sf = clustering.structure_factor(x, [box] * 3, n_max=6.0)
    assert sf.values.shape == (1, len(sf.k))
    assert np.allclose(sf.n, np.sqrt(np.unique(np.rint(sf.n**2))))
    assert np.all(sf.values[0, :-1] < 1e-12)
    kvecs, _, idx = clustering.wave_vectors([box] * 3, n_max=6.0)
    last = np.rint(kvecs[idx == idx.max()] * box / (2 * np.pi)).astype(int)
    share = np.mean((last % m == 0).all(1))
    assert 0 < share < 1
    assert sf.values[0, -1] == pytest.approx(m**3 * share, rel=1e-12)


def test_structure_factor_of_an_ideal_gas():
    """N independent uniform positions: each S(k) is |sum of N random unit phasors|^2 / N,
    mean 1 exactly and variance 1 - 1/N (close to exponential); the |n| = sqrt(2) shell
    averages 6 nearly independent ones (cross-correlations O(1/N)), so its mean over T
    samples has standard error sqrt(1/6 / T), and its sample variance (about 1/6) a relative
    error sqrt((kurtosis - 1) / T) with the Gamma(6) kurtosis 3 + 6/6: sqrt(3 / T).
    Tolerances: 4 standard errors."""
    t_count, n = 1000, 200
    x = RNG.uniform(0, 1.5, (t_count, n, 3))
    sf = clustering.structure_factor(x, [1.5] * 3, n_max=2.0)
    s2 = sf.values[:, 1]
    assert sf.vectors[1] == 6
    assert abs(s2.mean() - 1) < 4 * math.sqrt(1 / 6 / t_count)
    assert abs(s2.var() / (1 / 6) - 1) < 4 * math.sqrt(3 / t_count)
    for s in range(len(sf.k)):  # every shell: mean 1 within 4 standard errors
        assert abs(sf.values[:, s].mean() - 1) < 4 * math.sqrt(1 / sf.vectors[s] / t_count)


def test_structure_factor_of_a_gas_in_one_half():
    """N uniform positions in x < L/2 only: <exp(i 2 pi x / L)> = 2i/pi, so the (1, 0, 0)
    vector has <S> = 1 + (N - 1) 4/pi^2, the (0, 1, 0) and (0, 0, 1) vectors 1; the |n| = 1
    shell averages the three.  Tolerance: 4 standard errors of the mean over the samples,
    from their own spread."""
    t_count, n, box = 60, 2000, 2.0
    x = RNG.uniform(0, box, (t_count, n, 3))
    x[..., 0] *= 0.5
    values = clustering.structure_factor(x, [box] * 3, n_max=1.0).values[:, 0]
    expected = (1 + (n - 1) * 4 / math.pi**2 + 2) / 3
    assert abs(values.mean() - expected) < 4 * values.std(ddof=1) / math.sqrt(t_count)


# -- flow energy --------------------------------------------------------------------------------


def _maxwellian(shape, temperature, masses):
    return RNG.normal(size=shape) * np.sqrt(temperature / masses)[..., None]


def test_flow_energy_of_a_gas_without_flow_is_its_noise_level():
    """Velocities independent of each other and of the positions (any masses): each occupied
    cell holds d T / 2 of flow energy on average, so the ratio flow / thermal averages
    (C - 1) / (N - C) with the centre of mass removed.  Its spread is the chi-squared one
    of d (C - 1) squared Gaussians (``noise_std``); the thermal energy's own relative
    spread sqrt(2 / (d N)) = 3% adds 0.2% to it.  Checked: the mean over T = 300 samples
    within 4 standard errors, the sample spread against noise_std within 4 times its
    relative standard error sqrt(1 / (2 (T - 1))) plus the 0.2%."""
    t_count, n, d = 300, 1000, 3
    masses = RNG.uniform(0.5, 2.0, n)
    x = RNG.uniform(-1, 1, (t_count, n, d))
    v = _maxwellian((t_count, n, d), 0.7, masses) + 3.0  # a drift: removed with the c.o.m.
    fe = clustering.flow_energy(x, v, masses, [-1] * 3, [1] * 3, cells=4)
    assert np.all(fe.cells == 64)  # every cell occupied (about 16 particles each)
    assert fe.noise[0] == pytest.approx(63 / 936)
    assert fe.noise_std[0] == pytest.approx(63 / 936 * math.sqrt(2 / (3 * 63)))
    assert abs(fe.excess.mean()) < 4 * fe.noise_std[0] / math.sqrt(t_count)
    assert (
        abs(fe.ratio.std(ddof=1) / fe.noise_std[0] - 1)
        < 4 * math.sqrt(1 / (2 * (t_count - 1))) + 0.002
    )
    assert np.allclose(
        fe.flow + fe.thermal, 0.5 * (masses[:, None] * (v - _com(v, masses)) ** 2).sum((1, 2))
    )


def _com(v, masses):
    return (masses[None, :, None] * v).sum(1, keepdims=True) / masses.sum()


def test_flow_energy_of_a_planted_shear_flow():
    """u = U sin(2 pi y / L) x + Maxwellian noise (T, m = 1), positions uniform.  A cell of
    height h = L / m holds the flow's cell average, s sin(2 pi y_c / L) U with
    s = sin(pi h / L) / (pi h / L); over the cell centres <sin^2> = 1/2 (m >= 3), so the
    planted part of E_flow is N U^2 s^2 / 4, on top of the noise (C - 1) d T / 2, and the
    thermal energy holds the rest, N U^2 (1 - s^2) / 4 + (N - C) d T / 2.  So the excess is
    known.  Its error: the cross term between planted and noise momenta, variance
    2 T E_planted, over the thermal energy (4 standard errors of the mean over T = 10
    samples), and the spread of sin within a cell (h 2 pi / L)^2 / 24 per particle of the
    cell's planted momentum, under 0.5% of E_planted here (added as a margin)."""
    t_count, n, d, big_u, temp, m = 10, 20000, 3, 0.5, 1.0, 4
    x = RNG.uniform(0, 2.0, (t_count, n, d))
    v = _maxwellian((t_count, n, d), temp, np.ones(n))
    v[..., 0] += big_u * np.sin(2 * np.pi * x[..., 1] / 2.0)
    fe = clustering.flow_energy(x, v, 1.0, [0] * 3, [2] * 3, cells=m)
    s = math.sin(math.pi / m) / (math.pi / m)
    planted = n * big_u**2 * s**2 / 4
    c = m**3
    thermal = n * big_u**2 * (1 - s**2) / 4 + (n - c) * d * temp / 2
    expected = (planted + (c - 1) * d * temp / 2) / thermal - (c - 1) / (n - c)
    error = math.sqrt(2 * temp * planted) / thermal / math.sqrt(t_count)
    assert abs(fe.excess.mean() - expected) < 4 * error + 0.005 * planted / thermal
    assert expected > 20 * fe.noise_std[0]  # a flow this size stands far above the noise


def test_flow_energy_checks_its_input():
    x = np.zeros((2, 5, 3))
    with pytest.raises(ValueError, match="cells"):
        clustering.flow_energy(x, x, 1.0, [0] * 3, [1] * 3, cells=1)
    with pytest.raises(ValueError, match="shape"):
        clustering.flow_energy(x, x[:, :4], 1.0, [0] * 3, [1] * 3)
    with pytest.raises(ValueError, match="masses"):
        clustering.flow_energy(x, x, -1.0, [0] * 3, [1] * 3)
    with pytest.raises(ValueError, match="box"):
        clustering.flow_energy(x, x, 1.0, [0] * 3, [1, 1, 0])


def test_onset_interpolates_the_first_crossing():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    assert clustering.onset(t, [0.0, 0.01, 0.05, 0.02], 0.03) == pytest.approx(1.5)
    assert math.isnan(clustering.onset(t, [0.0, 0.01, 0.02, 0.0], 0.03))


# -- current correlations -----------------------------------------------------------------------


def test_current_correlations_of_an_uncorrelated_gas_are_one():
    """No flow: <|j(k)|^2> = sum m^2 v^2, split (d-1)/d transverse, 1/d longitudinal, so
    both normalised correlations average 1; the |n| = 1 shell in 2D holds 2 vectors, each
    transverse or longitudinal part one complex Gaussian (exponential, variance 1): the
    mean over T samples has standard error sqrt(1 / (2 T)).  4 of them."""
    t_count, n = 400, 300
    x = RNG.uniform(0, 1, (t_count, n, 2))
    v = _maxwellian((t_count, n, 2), 1.0, np.ones(n))
    cc = clustering.current_correlations(x, v, 1.0, [1.0, 1.0], n_max=1.0)
    for part in (cc.transverse, cc.longitudinal):
        assert abs(part[:, 0].mean() - 1) < 4 * math.sqrt(1 / (2 * t_count))


def test_current_correlations_see_a_planted_shear_flow_as_transverse():
    """u = U sin(2 pi y / L) x in 2D: at k = (0, 1) 2 pi / L the current is transverse,
    j = U sum sin(k y) exp(i k y) x, mean N U i / 2, so |j_perp|^2 ~ N^2 U^2 / 4 against the
    normalisation (1/2) N (U^2 / 2 + 2 T); averaged with the (1, 0) vector (1 for noise):
    shell = (N U^2 / 2 / (U^2 / 2 + 2 T) + 1) / 2.  The (relative) error, the cross term of
    the mean current with the noise, is about 2 / sqrt(N U^2 / (U^2 + 4 T)): 3% at N = 4000;
    tolerance 10%.  The longitudinal part stays at its noise level 1 (4 standard errors of
    one sample's shell mean over 2 exponentials, sqrt(1/2))."""
    n, big_u, temp = 4000, 1.0, 1.0
    x = RNG.uniform(0, 1, (1, n, 2))
    v = _maxwellian((1, n, 2), temp, np.ones(n))
    v[..., 0] += big_u * np.sin(2 * np.pi * x[..., 1])
    cc = clustering.current_correlations(x, v, 1.0, [1.0, 1.0], n_max=1.0)
    expected = (n * big_u**2 / 2 / (big_u**2 / 2 + 2 * temp) + 1) / 2
    assert cc.transverse[0, 0] == pytest.approx(expected, rel=0.1)
    assert abs(cc.longitudinal[0, 0] - 1) < 4 * math.sqrt(1 / 2)


# -- theory: the critical box size --------------------------------------------------------------


@pytest.mark.parametrize("phi", [0.01, 0.1, 0.25])
def test_shear_viscosity_is_enskogs_at_xi_1(phi):
    """At xi = 1 Garzo & Dufty's viscosity must be Enskog's first Sonine one, written here
    in its classical forms: 3D eta0 [(1 + 8 phi chi / 5)^2 / chi + 768 phi^2 chi / (25 pi)]
    (Chapman & Cowling), 2D eta0 [1 / chi + 2 phi + (1 + 8 / pi) phi^2 chi] (Gass 1971)."""
    r, temp, mass = 0.01, 1.3, 2.0
    for dim in (2, 3):
        chi = theory.contact_value(phi, dim=dim)
        root = math.sqrt(mass * temp / math.pi)
        if dim == 3:
            eta0 = 5 / (16 * (2 * r) ** 2) * root
            enskog = (1 + 8 * phi * chi / 5) ** 2 / chi + 768 * phi**2 * chi / (25 * math.pi)
        else:
            eta0 = root / (2 * 2 * r)
            enskog = 1 / chi + 2 * phi + (1 + 8 / math.pi) * phi**2 * chi
        visc = theory.shear_viscosity(
            density=1.0, radius=r, restitution=1.0, temperature=temp, mass=mass, dim=dim, eta=phi
        )
        assert visc == pytest.approx(eta0 * enskog, rel=1e-12)


def test_critical_box_size_dilute_against_hand_numbers():
    """Dilute 3D (chi -> 1), xi = 0.5: nu* = (3 - xi)(1 + xi) / 4 = 0.9375, zeta*/2 =
    5 (1 - xi^2) / 24 = 0.15625, eta* = 1 / 0.78125 = 1.28; k_c lambda = sqrt(16 (1 - xi^2)
    / (15 pi eta*)) with lambda = 1 / (sqrt(2) pi n sigma^2), so L_c / lambda = 2 pi
    sqrt(15 pi 1.28 / 12) = 14.087 (by hand)."""
    n, r = 1.0, 1e-4  # packing fraction 4e-12
    sigma = 2 * r
    lam = 1 / (math.sqrt(2) * math.pi * n * sigma**2)
    assert theory.critical_box_size(density=n, radius=r, restitution=0.5) / lam == pytest.approx(
        14.087, rel=1e-4
    )
    # L_c scales as the mean free path, 1 / n, in a dilute gas
    assert theory.critical_box_size(density=2 * n, radius=r, restitution=0.5) == pytest.approx(
        theory.critical_box_size(density=n, radius=r, restitution=0.5) / 2, rel=1e-6
    )


def test_critical_box_size_limits_and_consistency():
    # more elastic, more stable, from xi = 0.3 up; below, the viscosity's growth with
    # dissipation (eta* = 1 / (nu* - zeta*/2)) wins and L_c turns up again slightly
    xis = np.array([0.3, 0.5, 0.8, 0.95, 0.999])
    lc = theory.critical_box_size(density=1000, radius=0.025, restitution=xis)
    assert np.all(np.diff(lc) > 0)
    assert lc[-1] > 15 * lc[1]  # ~ 1 / sqrt(1 - xi^2) towards xi = 1
    assert theory.critical_box_size(density=1000, radius=0.025, restitution=1.0) == math.inf
    # the cooling rate is Haff's: zeta(T0) = 2 / tau0
    z = theory.cooling_rate(density=1000, radius=0.025, restitution=0.3, temperature=0.6)
    assert z == pytest.approx(
        2 / theory.haff_tau0(density=1000, radius=0.025, restitution=0.3, temperature0=0.6),
        rel=1e-12,
    )
    # the thesis' box (N = 1000, r = 0.025, L = 1) lies just below L_c at xi = 0.5 and 0.3
    assert 1.0 < theory.critical_box_size(density=1000, radius=0.025, restitution=0.3) < 1.15
    with pytest.raises(ValueError, match="xi"):
        theory.critical_box_size(density=1000, radius=0.025, restitution=1.5)
    growth = theory.shear_mode_growth(np.array([0.0, 3.0]), tau0=1.0, box=2.0, critical=1.0)
    assert growth[0] == 1.0 and growth[1] == pytest.approx(4.0**1.5)
    assert theory.shear_mode_growth(3.0, tau0=1.0, box=1.0, critical=2.0) < 1  # below L_c: decays
    # the level the slowest shear mode settles at below L_c: 1 / (1 - 0.25) at L = L_c / 2
    assert theory.shear_mode_level(0.5, critical=1.0) == pytest.approx(4 / 3)
    assert np.all(np.isinf(theory.shear_mode_level(np.array([1.0, 1.5]), critical=1.0)))


# -- the warning --------------------------------------------------------------------------------


def _gas(n, restitution, boundary="periodic", seed=3):
    """n particles of r = 0.025 at the thesis' number density 1000."""
    side = (n / 1000) ** (1 / 3)
    return granular.Scene.random(
        n,
        0.025,
        box=(np.zeros(3), np.full(3, side)),
        boundary=boundary,
        seed=seed,
        restitution=restitution,
    )


def test_clustering_warning_for_a_big_granular_box_once():
    """N = 3000 at the thesis' density: L = 1.44 > L_c = 1.087 at xi = 0.3.  A run that
    stops before the onset t* is not warned; the first run that can reach it is, once."""
    scene = _gas(3000, 0.3)
    message, t_star, cpp = clustering.unstable_box(scene)
    assert 0 < t_star < math.inf and 0 < cpp < math.inf
    sim = granular.Simulation(scene)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(t_stop=1e-3 * t_star)  # ends long before the onset
    with pytest.warns(granular.ClusteringWarning) as record:
        sim.run(t_stop=t_star)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(t_stop=1.1 * t_star)  # once per Simulation
    assert str(record[0].message) == message
    lc = theory.critical_box_size(
        density=1000, radius=0.025, restitution=0.3, eta=scene.packing_fraction
    )
    for number in (
        f"L = {3 ** (1 / 3):.4g}",
        f"L_c = {lc:.4g}",
        "xi = 0.3",
        f"{scene.packing_fraction:.4g}",
    ):
        assert number in message
    assert "Haff's law" in message and "t* =" in message
    assert record[0].filename == __file__  # points at the caller's run
    # in collisions per particle: short of the onset, no warning; past it, a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        granular.Simulation(scene).run(stop_when={"collisions_per_particle": 0.5 * cpp})
    with pytest.warns(granular.ClusteringWarning):
        granular.Simulation(scene).run(stop_when={"collisions_per_particle": cpp + 1})


@pytest.mark.parametrize(
    "n, restitution, boundary",
    [(250, 0.3, "periodic"), (3000, 1.0, "periodic"), (3000, 0.3, "walls")],
    ids=["below L_c", "elastic", "walls"],
)
def test_no_clustering_warning(n, restitution, boundary):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        granular.Simulation(_gas(n, restitution, boundary)).run(t_stop=1e-3)


def _viscoelastic_disks(n, radius, delta0=0.1):
    """2D disks in the unit box with the viscoelastic law of delta(T0) = delta0."""
    gas = granular.Scene.random(n, radius, dim=2, seed=1)
    law = granular.Viscoelastic(delta0 / (4 * gas.temperature) ** 0.1, 1.0)
    return gas.replace(restitution=law)


def test_clustering_warning_for_a_viscoelastic_gas_at_its_effective_restitution():
    """N = 1000 disks of r = 0.005 in the unit box (eta = 0.079), delta(T0) = 0.1: the law
    cools like a constant xi_eff = 0.888, whose L_c = 0.75 < 1 (such a gas runs 5-7 % warmer
    than the cooling law).  The first run is warned at any length (linear theory's onset
    is no bound for a gas whose L_c grows as it cools), with xi_eff and its L_c."""
    scene = _viscoelastic_disks(1000, 0.005)
    xi = clustering.effective_restitution(scene.restitution, scene.temperature)
    lc = theory.critical_box_size(
        density=1000, radius=0.005, restitution=xi, dim=2, eta=scene.packing_fraction
    )
    assert lc < 1
    with pytest.warns(granular.ClusteringWarning) as record:
        granular.Simulation(scene).run(t_stop=1e-3)
    message = str(record[0].message)
    for number in ("L = 1", f"L_c = {lc:.4g}", f"xi = {xi:.4g}", f"T = {scene.temperature:.4g}"):
        assert number in message
    assert "effective restitution" in message and "viscoelastic" in message
    assert record[0].filename == __file__
    # linear theory's outlook: here L_c(T) outgrows the box first; in a box 3.5 L_c the
    # slowest shear modes reach the onset share
    assert "L_c outgrows the box at about t = " in message
    far = clustering.unstable_box(_viscoelastic_disks(4000, 0.0025, delta0=0.2))[0]
    assert "reach 5% of the kinetic energy at about t = " in far


def test_no_clustering_warning_for_a_viscoelastic_gas_below_its_critical_box():
    """N = 500 disks of r = 0.007 (eta = 0.077), delta(T0) = 0.1: L_c(xi_eff) = 1.07 > 1."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        granular.Simulation(_viscoelastic_disks(500, 0.007)).run(t_stop=1e-3)


def test_effective_restitution_is_the_energy_weighted_thermal_mean():
    """1 - xi_eff^2 = <(1 - eps(g)^2) g^2> / <g^2> over a Maxwellian's collisions, g with
    density (g/s^2) exp(-g^2/2s^2), s^2 = 2T/m: against scipy's adaptive quadrature (to
    1e-12), and at small delta against the cooling theory's series, 1 - xi_eff^2 = 2 C1
    Gamma(21/10) delta - (C1^2 + 2 C2) Gamma(11/5) delta^2 + O(delta^3) (the dropped
    terms, ~10 delta^3, stay below 2e-5 at delta = 0.01).  At delta(T) = 0.2 and 0.3 a
    fair share of the collisions is past max_speed (delta = 0.25), where eps is clamped."""
    from scipy import integrate

    mass = 2.0
    for delta, temperature in ((0.01, 0.5), (0.1, 3.0), (0.2, 1.0), (0.3, 1.0)):
        law = granular.Viscoelastic(delta / (4 * temperature / mass) ** 0.1, 1.0)
        xi = clustering.effective_restitution(law, temperature, mass)
        s2 = 2 * temperature / mass

        def weight(g, law=law, s2=s2):
            return (1 - law(g) ** 2) * g**3 * np.exp(-(g**2) / (2 * s2)) / (2 * s2**2)

        top = 40 * math.sqrt(s2)
        kink = [law.max_speed] if law.max_speed < top else None
        loss = integrate.quad(weight, 0, top, epsabs=0, epsrel=1e-13, points=kink)[0]
        assert 1 - xi**2 == pytest.approx(loss, rel=1e-12)
        if delta == 0.01:
            c1, c2 = theory.VISCOELASTIC_C1, theory.VISCOELASTIC_C2
            series = (
                2 * c1 * math.gamma(2.1) * delta - (c1**2 + 2 * c2) * math.gamma(2.2) * delta**2
            )
            assert 1 - xi**2 == pytest.approx(series, abs=2e-5)
    assert clustering.effective_restitution(0.7, 1.0) == 0.7
    np.testing.assert_allclose(
        clustering.effective_restitution(law, [1.0, 2.0]),
        [clustering.effective_restitution(law, 1.0), clustering.effective_restitution(law, 2.0)],
    )
    with pytest.raises(ValueError, match="temperatures > 0"):
        clustering.effective_restitution(law, 0.0)
    # A long series of temperatures is shown by its first entries, not in full.
    with pytest.raises(ValueError, match=r"got T = \[0, 1, .*\(100000 in all\)\]") as err:
        clustering.effective_restitution(law, np.arange(100000.0))
    assert len(str(err.value)) < 300


def test_no_warning_for_a_restitution_that_is_not_a_number():
    """Restitution law objects other than Viscoelastic (a table has no cooling theory here)
    are left alone: a box that is unstable at the constant xi = 0.3 gets no message with a
    table of 0.3 at every speed instead."""
    scene = _gas(3000, 0.3)
    assert clustering.unstable_box_message(scene) is not None
    law = granular.TabulatedRestitution([0.0, 1.0], [0.3, 0.3])
    assert clustering.unstable_box_message(scene.replace(restitution=law)) is None


# -- a short EDMD run below L_c -----------------------------------------------------------------


def test_flow_stays_at_noise_level_below_the_critical_size():
    """N = 250 at the thesis' density (L = 0.63), xi = 0.8: L_c = 1.59, so L / L_c = 0.4 and
    linear theory enhances the slowest shear modes only by 1 / (1 - 0.16) (van Noije et al.
    1997), 0.3% of the kinetic energy.  Over 5-20 collisions per particle of 4 runs the flow
    excess (2^3 cells) must stay at the noise level: each run's time average has a spread
    at most one sample's, noise_std, so the mean of 4 lies within 3 noise_std / 2 of 0."""
    excess = []
    for seed in range(4):
        tr = granular.Simulation(_gas(250, 0.8, seed=seed)).run(
            stop_when={"collisions_per_particle": 20}, sample_times=np.linspace(0, 10, 201)
        )
        late = tr.collisions_per_particle > 5
        fe = tr.flow_energy(cells=2)
        if seed == 0:  # the Trajectory methods are the module's functions on its samples
            box = tr.upper - tr.lower
            sf = clustering.structure_factor(tr.positions, box)
            assert np.array_equal(tr.structure_factor().values, sf.values)
            cc = clustering.current_correlations(tr.positions, tr.velocities, 1.0, box)
            assert np.array_equal(tr.current_correlations().transverse, cc.transverse)
        excess.append(fe.excess[late].mean())
        noise_std = fe.noise_std[0]
    assert abs(np.mean(excess)) < 3 * noise_std / 2


def test_clustering_plots_render(tmp_path):
    """plot.structure_factor and plot.flow_energy draw clustering results onto given axes,
    with units (or 'dimensionless') on every axis."""
    pytest.importorskip("matplotlib")
    import matplotlib.pyplot as plt

    from granular import plot

    t = np.linspace(0, 1, 6)
    x = RNG.uniform(0, 1, (6, 200, 2))
    v = RNG.normal(size=(6, 200, 2))
    sf = clustering.structure_factor(x, [1, 1])
    cc = clustering.current_correlations(x, v, 1.0, [1, 1])
    fe = clustering.flow_energy(x, v, 1.0, [0, 0], [1, 1], cells=3)
    _, (a, b) = plt.subplots(1, 2)
    assert plot.structure_factor(t, sf, ax=a, transverse=cc) is a
    assert plot.flow_energy(t, fe, ax=b, label="run", threshold=0.03) is b
    for ax in (a, b, plot.structure_factor(t, sf)):
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert "[" in label or "dimensionless" in label, label
    a.figure.savefig(tmp_path / "c.png")
    assert (tmp_path / "c.png").stat().st_size > 1000
    plt.close("all")
