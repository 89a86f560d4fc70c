"""Each formula of granular.theory against an independent evaluation: numerical
integration of the velocity autocorrelation function it comes from, a differential
equation solved numerically, or a known limit."""

import math

import numpy as np
import pytest
from scipy import integrate

from granular import theory

# a call in the old positional form fails here: nothing in the repository may use it
pytestmark = pytest.mark.filterwarnings("error::FutureWarning")

D0, G0, TAU0 = 0.07, 9.0, 1.5


def msd_from_vacf(vacf, t, dim=3, start=0.0):
    """MSD over [start, t] = 2 int_start^t dt1 int_t1^t dt2 <v(t1) v(t2)> (2.59), per
    dimension times dim; adaptive quadrature, relative accuracy ~1e-10."""

    def inner(t1):
        return integrate.quad(lambda t2: vacf(t1, t2), t1, t, epsabs=0, epsrel=1e-12, limit=200)[0]

    return dim * 2 * integrate.quad(inner, start, t, epsabs=0, epsrel=1e-11, limit=200)[0]


@pytest.mark.parametrize("t", [1e-3, 0.05, 0.7, 6.0])
def test_msd_formulas_are_the_double_integrals_of_their_vacf(t):
    T0_m = D0 * G0  # T0 / m = D0 gamma0 (2.55)
    a = G0 * TAU0

    def langevin(t1, t2):  # (2.66)
        return T0_m * math.exp(-G0 * (t2 - t1))

    def granular(t1, t2):  # (2.77)
        return T0_m * (1 + t2 / TAU0) ** (-a - 1) * (1 + t1 / TAU0) ** (a - 1)

    def udsbm(t1, t2):  # (2.111)
        return T0_m * a / (a - 1) * (1 + t1 / TAU0) ** (a - 2) * (1 + t2 / TAU0) ** (-a)

    assert theory.msd_langevin(t, D0=D0, gamma0=G0) == pytest.approx(
        msd_from_vacf(langevin, t), rel=1e-8
    )
    assert theory.msd_granular(t, D0=D0, gamma0=G0, tau0=TAU0) == pytest.approx(
        msd_from_vacf(granular, t), rel=1e-8
    )
    assert theory.msd_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0) == pytest.approx(
        msd_from_vacf(udsbm, t), rel=1e-8
    )


@pytest.mark.parametrize("t", [0.01, 0.5, 4.0])
def test_msd_with_other_initial_speeds(t):
    """A start with <v0^2> differing from the stationary value adds the decaying part of
    the VACF: (v0^2 - v_s^2) Phi(t1) Phi(t2) with Phi = exp(-int gamma) (2.101)."""
    v0 = 0.3
    a = G0 * TAU0
    vs_l = D0 * G0
    vs_u = theory.udsbm_v0_sq(D0=D0, gamma0=G0, tau0=TAU0)

    def lang(t1, t2):
        return vs_l * math.exp(-G0 * (t2 - t1)) + (v0 - vs_l) * math.exp(-G0 * (t1 + t2))

    def phi(s):
        return (1 + s / TAU0) ** (-a)

    def uds(t1, t2):
        stationary = vs_u * (1 + t1 / TAU0) ** (a - 2) * (1 + t2 / TAU0) ** (-a)
        return stationary + (v0 - vs_u) * phi(t1) * phi(t2)

    assert theory.msd_langevin(t, D0=D0, gamma0=G0, v0_sq=v0) == pytest.approx(
        msd_from_vacf(lang, t), rel=1e-8
    )
    assert theory.msd_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v0) == pytest.approx(
        msd_from_vacf(uds, t), rel=1e-8
    )


@pytest.mark.parametrize("start,lag", [(0.0, 0.5), (0.3, 0.05), (2.0, 0.7), (10.0, 4.0)])
def test_udsbm_increment_msd_is_the_double_integral_over_its_window(start, lag):
    """What a time average of UDSBM collects: the displacement over [start, start + lag],
    against the VACF (2.111) plus a start's transient integrated over that window; with
    App. C's start the increments scale, msd_udsbm(lag / (1 + start/tau0)); at start 0 it
    is msd_udsbm."""
    v0 = 0.3
    a = G0 * TAU0
    vs = theory.udsbm_v0_sq(D0=D0, gamma0=G0, tau0=TAU0)

    def phi(s):
        return (1 + s / TAU0) ** (-a)

    def uds(t1, t2):
        stationary = vs * (1 + t1 / TAU0) ** (a - 2) * (1 + t2 / TAU0) ** (-a)
        return stationary + (v0 - vs) * phi(t1) * phi(t2)

    got = theory.udsbm_increment_msd(lag, start=start, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v0)
    assert got == pytest.approx(msd_from_vacf(uds, start + lag, start=start), rel=1e-8)
    assert theory.udsbm_increment_msd(
        lag, start=start, D0=D0, gamma0=G0, tau0=TAU0
    ) == pytest.approx(
        theory.msd_udsbm(lag / (1 + start / TAU0), D0=D0, gamma0=G0, tau0=TAU0), rel=1e-10
    )
    assert theory.udsbm_increment_msd(
        lag, start=0.0, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v0
    ) == pytest.approx(theory.msd_udsbm(lag, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v0), rel=1e-10)


def test_udsbm_increment_msd_at_lags_short_against_the_start():
    """Lags down to 1e-10 of tau0 + start, where differences of powers of 1 + t/tau0 would
    cancel to nothing: the increments still scale as msd_udsbm(lag / w) (which has no such
    difference) and are ballistic, <v^2>(start) lag^2, to the leading order (relative
    error ~ lag gamma0)."""
    for start in (10.0, 1e3):
        w = 1 + start / TAU0
        for lag in (1e-8, 1e-6, 1e-4):
            got = theory.udsbm_increment_msd(lag, start=start, D0=D0, gamma0=G0, tau0=TAU0)
            assert got == pytest.approx(
                theory.msd_udsbm(lag / w, D0=D0, gamma0=G0, tau0=TAU0), rel=1e-12
            )
            v2 = theory.udsbm_v0_sq(D0=D0, gamma0=G0, tau0=TAU0) / w**2
            assert got == pytest.approx(3 * v2 * lag**2, rel=2 * G0 * lag / w)


def test_msd_limits_and_numerical_stability():
    t = np.array([1e-12, 1e-9, 1e-6])
    T0_m = D0 * G0
    for f in (
        lambda t: theory.msd_langevin(t, D0=D0, gamma0=G0),
        lambda t: theory.msd_granular(t, D0=D0, gamma0=G0, tau0=TAU0),
        lambda t: theory.msd_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=T0_m),
    ):
        np.testing.assert_allclose(f(t), theory.msd_ballistic(t, temperature=T0_m), rtol=1e-5)
        assert f(0.0) == 0.0
    big = 1e6
    # the asymptotes with their offsets, reached to exp(-gamma0 t) and
    # (t/tau0)^(-gamma0 tau0) -- far below rounding at t = 1e6
    assert theory.msd_langevin(big, D0=D0, gamma0=G0) == pytest.approx(
        theory.msd_diffusive(big, D0=D0, gamma0=G0), rel=1e-13
    )
    assert theory.msd_granular(big, D0=D0, gamma0=G0, tau0=TAU0) == pytest.approx(
        theory.msd_logarithmic(big, D0=D0, tau0=TAU0, gamma0=G0), rel=1e-13
    )
    assert theory.msd_langevin(big, D0=D0, gamma0=G0) == pytest.approx(
        theory.msd_diffusive(big, D0=D0), rel=1e-6
    )
    assert theory.msd_granular(3.0, D0=D0, gamma0=G0, tau0=math.inf) == theory.msd_langevin(
        3.0, D0=D0, gamma0=G0
    )
    assert theory.msd_langevin(2.0, D0=D0, gamma0=G0, dim=2) == pytest.approx(
        theory.msd_langevin(2.0, D0=D0, gamma0=G0) * 2 / 3
    )
    with pytest.raises(ValueError, match="gamma0 \\* tau0 > 1"):
        theory.msd_udsbm(1.0, D0=D0, gamma0=0.5, tau0=1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_maxwell_boltzmann_density_and_moments(dim):
    T, m = 1.7, 2.0

    def pdf(v):
        return theory.maxwell_boltzmann_pdf(v, temperature=T, mass=m, dim=dim)

    norm = integrate.quad(pdf, 0, np.inf)[0]
    mean = integrate.quad(lambda v: v * pdf(v), 0, np.inf)[0]
    mean_sq = integrate.quad(lambda v: v * v * pdf(v), 0, np.inf)[0]
    mom = theory.maxwell_boltzmann_moments(temperature=T, mass=m, dim=dim)
    assert norm == pytest.approx(1, rel=1e-10)
    assert mom["mean"] == pytest.approx(mean, rel=1e-10)
    assert mom["mean_sq"] == pytest.approx(mean_sq, rel=1e-10) == pytest.approx(dim * T / m)
    assert mom["std"] == pytest.approx(math.sqrt(mean_sq - mean**2), rel=1e-10)
    v = np.linspace(0.01, 5, 20001)
    assert mom["most_probable"] == pytest.approx(v[np.argmax(pdf(v))], abs=3e-4)


def test_pieprzyk_equation_of_state():
    """Pieprzyk et al.'s 2019 MD fit: its low-density expansion carries the exact virial
    coefficients Z = 1 + 4 eta + 10 eta^2 + 18.3648 eta^3 (B4 / b^3 = 18.3648, Ree & Hoover
    1964), read off at eta = 1e-4 where the next term is 1e-4 of the last; it lies above
    Carnahan-Starling (whose B4 is 18) by 0.1-1 % at the fluid's moderate packings; bad
    packing fractions are refused."""
    z = theory.pieprzyk_compressibility
    eta = 1e-4
    assert (z(eta) - 1 - 4 * eta - 10 * eta**2) / eta**3 == pytest.approx(18.3648, rel=2e-3)
    ratio = z(np.array([0.3, 0.45])) / theory.compressibility_factor(np.array([0.3, 0.45]))
    assert np.all((ratio > 1.001) & (ratio < 1.01))
    for bad in (-0.1, 1.0):
        with pytest.raises(ValueError, match="packing fraction"):
            z(bad)


def test_contact_value_and_equation_of_state():
    assert theory.contact_value(0.0) == 1.0 and theory.contact_value(0.0, dim=2) == 1.0
    # Carnahan-Starling: 1 + 4 eta g2 = (1 + eta + eta^2 - eta^3) / (1 - eta)^3
    for eta in (0.1, 0.3, 0.45):
        assert theory.compressibility_factor(eta) == pytest.approx(
            (1 + eta + eta**2 - eta**3) / (1 - eta) ** 3, rel=1e-14
        )
        # second virial coefficients: g2 -> 1 + 5/2 eta (3D), 1 + 25/16... low density slopes
    eps = 1e-7
    assert (theory.contact_value(eps) - 1) / eps == pytest.approx(2.5, rel=1e-5)  # exact B3 term
    assert (theory.contact_value(eps, dim=2) - 1) / eps == pytest.approx(
        25 / 16, rel=1e-5
    )  # 2 - 7/16
    with pytest.raises(ValueError):
        theory.contact_value(1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_haff_law_solves_its_cooling_equation(dim):
    """dT/dt = -(1 - xi^2) omega(T) T / d integrated numerically gives T0 / (1 + t/tau0)^2.
    This is self-consistency of haff_tau0 with collision_frequency; the 2D frequency itself
    is checked against EDMD in test_physics_edmd.test_two_dimensional_enskog_collision_rate."""
    n, xi, T0 = 1000.0, 0.7, 0.9
    r = 0.02 if dim == 3 else 0.01

    def rhs(t, T):
        return (
            -(1 - xi**2)
            * theory.collision_frequency(density=n, radius=r, temperature=T, dim=dim)
            * T
            / dim
        )

    ts = np.linspace(0, 5, 11)
    sol = integrate.solve_ivp(rhs, (0, 5), [T0], t_eval=ts, rtol=1e-11, atol=1e-14)
    tau0 = theory.haff_tau0(density=n, radius=r, restitution=xi, temperature0=T0, dim=dim)
    np.testing.assert_allclose(
        sol.y[0], theory.haff_temperature(ts, temperature0=T0, tau0=tau0), rtol=1e-8
    )
    assert theory.haff_tau0(density=n, radius=r, restitution=1.0, temperature0=T0) == math.inf


def test_thesis_standard_system_numbers():
    """The thesis' standard gas: N = 1000, r = 0.025, unit box, T0 = 2/3 (speed sqrt 2):
    eta = 0.0654 (2.44), and (2.45), (2.52), (2.55) evaluated by hand."""
    n, r, T0, xi = 1000, 0.025, 2 / 3, 0.8
    eta = theory.packing_fraction(n=n, radius=r, volume=1.0)
    assert eta == pytest.approx(0.06545, rel=1e-3)
    g2 = (2 - eta) / (2 * (1 - eta) ** 3)
    sigma = 0.05
    tau0 = 1 / (2 / 3 * (1 - xi**2) * math.sqrt(math.pi) * g2 * n * sigma**2 * math.sqrt(T0))
    d0 = 1.5 / (n * g2 * sigma**2 * (1 + xi) ** 2) * math.sqrt(T0 / math.pi)
    c = theory.langevin_coefficients(n=n, radius=r, volume=1.0, restitution=xi, temperature0=T0)
    assert c.tau0 == pytest.approx(tau0, rel=1e-12)
    assert c.D0 == pytest.approx(d0, rel=1e-12)
    assert c.gamma0 == pytest.approx(T0 / d0, rel=1e-12)
    assert (
        theory.langevin_coefficients(
            n=n, radius=r, volume=1.0, restitution=1.0, temperature0=T0
        ).tau0
        == math.inf
    )


def _mean_force_on_slow_tracer(dim, sigma, n_chi, m, T, V=1e-3):
    """Slow reference for tracer_friction: the mean impulse per time that a Maxwellian gas
    (mass m, temperature T, contact density n_chi) gives an infinitely heavy disk/sphere of
    contact radius sigma moving at V along x, summed by brute force over a grid of gas
    velocities and contact normals (Rayleigh's collision integral: rate n chi sigma^(d-1)
    |g.e| dOmega, impulse 2 m (g.e) e, g = v - V, approaching when g.e < 0)."""
    s = math.sqrt(T / m)
    if dim == 2:
        u = np.linspace(-7 * s, 7 * s, 141)
        vx, vy = np.meshgrid(u, u, indexing="ij")
        v = np.stack([vx.ravel(), vy.ravel()], 1)
        weight = np.exp(-(v**2).sum(1) / (2 * s * s)) / (2 * math.pi * s * s) * (u[1] - u[0]) ** 2
        phi = (np.arange(360) + 0.5) * 2 * math.pi / 360
        e = np.stack([np.cos(phi), np.sin(phi)], 1)
        dA = sigma * (2 * math.pi / 360)  # sigma^(d-1) dOmega
    else:
        u = np.linspace(-6 * s, 6 * s, 33)
        g3 = np.meshgrid(u, u, u, indexing="ij")
        v = np.stack([g.ravel() for g in g3], 1)
        weight = np.exp(-(v**2).sum(1) / (2 * s * s)) / (2 * math.pi * s * s) ** 1.5
        weight *= (u[1] - u[0]) ** 3
        k = 16  # Gauss-Legendre in cos(theta) times uniform in phi
        c, wc = np.polynomial.legendre.leggauss(k)
        phi = (np.arange(2 * k) + 0.5) * math.pi / k
        C, P = np.meshgrid(c, phi, indexing="ij")
        S = np.sqrt(1 - C**2)
        e = np.stack([(S * np.cos(P)).ravel(), (S * np.sin(P)).ravel(), C.ravel()], 1)
        dA = sigma**2 * np.repeat(wc, 2 * k) * (math.pi / k)
    force = np.zeros(dim)
    for sign in (1.0, -1.0):  # central difference in V: the O(V^2) terms cancel
        for start in range(0, len(v), 4096):  # in blocks: velocities x normals is large
            g = v[start : start + 4096] - sign * V * np.eye(dim)[0]
            ge = g @ e.T  # (velocities, normals)
            rate = n_chi * np.where(ge < 0, -ge, 0.0) * dA
            impulse = weight[start : start + 4096, None] * rate * 2 * m * ge
            force += sign * (impulse @ e).sum(0)
    return -force[0] / (2 * V)  # M gamma: the force is -M gamma V


@pytest.mark.parametrize("dim", [2, 3])
def test_tracer_friction_is_the_collision_integral(dim):
    """The closed form (2D: 2 n chi sigma sqrt(2 pi m T), 3D Epstein's (8/3) n chi sigma^2
    sqrt(2 pi m T)) against the collision integral summed by brute force on a grid, for a
    tracer so heavy that mu = m.  The grid sums are good to ~1e-3."""
    n, r, R, T, m, M, chi = 3.0, 0.1, 0.7, 0.8, 1.3, 1e12, 1.25
    sigma = R + r
    closed = (
        theory.tracer_friction(
            density=n,
            radius=r,
            tracer_radius=R,
            tracer_mass=M,
            temperature=T,
            mass=m,
            dim=dim,
            chi=chi,
        )
        * M
    )
    brute = _mean_force_on_slow_tracer(dim, sigma, n * chi, m, T)
    assert closed == pytest.approx(brute, rel=1e-3)
    literal = (2.0 if dim == 2 else 8 / 3 * sigma) * n * chi * sigma
    assert closed == pytest.approx(literal * math.sqrt(2 * math.pi * m * T), rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_tracer_friction_of_a_gas_particle_is_self_diffusion(dim):
    """A 'tracer' equal to the gas particles (mu = m/2, z = 1) diffuses as Enskog's D_E
    (diffusion_d0 at xi = 1): D = T / (M gamma)."""
    n, r, T = (3.0, 0.05, 0.7) if dim == 2 else (20.0, 0.05, 0.7)
    c = theory.tracer_langevin_coefficients(
        density=n, radius=r, tracer_radius=r, tracer_mass=1.0, temperature=T, mass=1.0, dim=dim
    )
    assert c.D0 == pytest.approx(
        theory.diffusion_d0(
            density=n, radius=r, restitution=1.0, temperature0=T, mass=1.0, dim=dim
        ),
        rel=1e-12,
    )
    assert c.gamma0 * c.D0 == pytest.approx(T, rel=1e-12) and c.tau0 == math.inf


@pytest.mark.parametrize("dim", [2, 3])
def test_tracer_contact_value_limits(dim):
    """Santos-Yuste-Lopez de Haro's G(eta, z) meets its three exact limits: a point tracer
    (z = 0) 1 / (1 - eta), a tracer like the gas (z = 1) the gas' contact value, a flat wall
    (R -> inf, z -> 2) the compressibility factor; and it is 1 in an empty gas."""
    eta, r = 0.3, 0.1
    assert theory.tracer_contact_value(
        eta, tracer_radius=1e-12, radius=r, dim=dim
    ) == pytest.approx(1 / (1 - eta))
    assert theory.tracer_contact_value(eta, tracer_radius=r, radius=r, dim=dim) == pytest.approx(
        theory.contact_value(eta, dim=dim), rel=1e-12
    )
    assert theory.tracer_contact_value(eta, tracer_radius=1e9, radius=r, dim=dim) == pytest.approx(
        theory.compressibility_factor(eta, dim=dim), rel=1e-8
    )
    assert theory.tracer_contact_value(0.0, tracer_radius=0.5, radius=r, dim=dim) == pytest.approx(
        1.0, rel=1e-14
    )
    with pytest.raises(ValueError, match="positive"):
        theory.tracer_friction(
            density=-1.0, radius=r, tracer_radius=0.5, tracer_mass=25.0, temperature=0.5, dim=dim
        )
    with pytest.raises(ValueError, match=r"tracer_radius .* got 0 "):
        theory.tracer_contact_value(eta, tracer_radius=0.0, radius=r, dim=dim)
