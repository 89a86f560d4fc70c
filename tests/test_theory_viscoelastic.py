"""granular.theory's viscoelastic gas and power-law UDSBM formulas against independent
numerical solutions of the equations they come from (scipy's ODE solver and quadrature),
their limits, and closed forms where those exist.  No sampling: tolerances are the
numerical methods' (stated at each assertion)."""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from granular import Viscoelastic, theory
from granular.theory import _numerics

from helpers import eb_reference

# a call in the old positional form fails here: nothing in the repository may use it
pytestmark = pytest.mark.filterwarnings("error::FutureWarning")

# the thesis' gas (N = 1000, r = 0.025, unit box) at T0 = 1, m = 1
N, R, T0 = 1000.0, 0.025, 1.0
DELTA = 0.05  # delta(T0) = a_kappa (4 T0 / m)^(1/10): 1 - eps ~ C1 delta ~ 6%
A_KAPPA = DELTA / 4.0**0.1
G0, D0, TAU0 = 9.26, 0.072, 0.972  # the UDSBM of tests/test_langevin.py
VISCO = 5 / 6


def _ode_temperature(t, a_kappa, order, dim=3, radius=R):
    """dT/dt = -zeta(T) T integrated by scipy (LSODA, rtol 1e-12) as d ln T / dt = -zeta,
    zeta from theory.viscoelastic_cooling_rate: the law the closed forms claim to solve."""

    def rhs(_, y):
        T = math.exp(y[0])
        return [
            -theory.viscoelastic_cooling_rate(
                T, a_kappa=a_kappa, density=N, radius=radius, dim=dim, order=order
            )
        ]

    sol = solve_ivp(
        rhs, (0, t[-1]), [math.log(T0)], t_eval=t, method="LSODA", rtol=1e-12, atol=1e-13
    )
    assert sol.success
    return np.exp(sol.y[0])


@pytest.mark.parametrize("dim,radius", [(2, 0.01), (3, R)])  # packing 0.31 and 0.065
def test_cooling_law_solves_its_ode(dim, radius):
    """T0 (1 + t/tau0')^(-5/3) with tau0' = 5/(3 zeta_1(T0)) against the ODE with the
    first-order rate, from t = 0 to 10^4 tau0' (T down by 6.7 decades): relative 1e-8 (the
    solver's rtol 1e-12 on ln T accumulated over ~10^3 steps)."""
    tau = theory.viscoelastic_tau0(
        a_kappa=A_KAPPA, density=N, radius=radius, temperature0=T0, dim=dim
    )
    t = tau * np.logspace(-3, 4, 30)
    np.testing.assert_allclose(
        theory.viscoelastic_temperature(t, temperature0=T0, tau0=tau),
        _ode_temperature(t, A_KAPPA, 1, dim, radius),
        rtol=1e-8,
    )


def test_second_order_cooling_solves_its_ode():
    """viscoelastic_temperature_second_order (inverting the exact partial-fraction cooling
    time) against the ODE with zeta_1 + zeta_2: relative 1e-8 (solver), from 10^-3 to 10^4
    tau0'; and it cools more slowly than the leading order (zeta_2 < 0: the series'
    second term makes collisions more elastic), but not more slowly than the leading order
    with the smaller rate zeta_1 + zeta_2 at T0 (zeta >= that times (T/T0)^(3/5)): T / T_lead
    <= (zeta_1 / (zeta_1 + zeta_2))^(5/3) at T0 (12% at delta = 0.05)."""
    tau = theory.viscoelastic_tau0(a_kappa=A_KAPPA, density=N, radius=R, temperature0=T0)
    t = tau * np.logspace(-3, 4, 30)
    second = theory.viscoelastic_temperature_second_order(
        t, temperature0=T0, a_kappa=A_KAPPA, density=N, radius=R
    )
    np.testing.assert_allclose(second, _ode_temperature(t, A_KAPPA, 2), rtol=1e-8)
    lead = theory.viscoelastic_temperature(t, temperature0=T0, tau0=tau)
    assert np.all(second > lead)
    z1 = theory.viscoelastic_cooling_rate(T0, a_kappa=A_KAPPA, density=N, radius=R)
    z12 = theory.viscoelastic_cooling_rate(T0, a_kappa=A_KAPPA, density=N, radius=R, order=2)
    assert np.max(second / lead) < (z1 / z12) ** (5 / 3)


def test_cooling_time_is_the_inverse():
    tau = theory.viscoelastic_tau0(a_kappa=A_KAPPA, density=N, radius=R, temperature0=T0)
    t = tau * np.array([0.0, 0.1, 3.0, 500.0])
    T = theory.viscoelastic_temperature_second_order(
        t, temperature0=T0, a_kappa=A_KAPPA, density=N, radius=R
    )
    back = theory.viscoelastic_cooling_time(
        T, temperature0=T0, a_kappa=A_KAPPA, density=N, radius=R
    )
    np.testing.assert_allclose(back, t, rtol=1e-9, atol=1e-12 * tau)


def test_limits_of_small_dissipation():
    """delta -> 0: tau0' grows like 1/a_kappa (zeta_1 is linear in it); the second-order
    correction to T vanishes linearly in delta (ratio of the corrections at delta/10 and
    delta/100 is 10 within 2%: the next order adds (c2/c1) delta, measured 6.7% at
    delta = 0.05, so 0.6% at delta/10); a_kappa = 0 is elastic (no
    cooling, tau0' = inf); the rate is zeta_1 ~ T^(3/5)."""
    t1 = theory.viscoelastic_tau0(a_kappa=A_KAPPA, density=N, radius=R, temperature0=T0)
    t2 = theory.viscoelastic_tau0(a_kappa=A_KAPPA / 10, density=N, radius=R, temperature0=T0)
    assert t2 / t1 == pytest.approx(10, rel=1e-12)

    def correction(a_kappa):
        tau = theory.viscoelastic_tau0(a_kappa=a_kappa, density=N, radius=R, temperature0=T0)
        t = 3.0 * tau
        lead = theory.viscoelastic_temperature(t, temperature0=T0, tau0=tau)
        return (
            theory.viscoelastic_temperature_second_order(
                t, temperature0=T0, a_kappa=a_kappa, density=N, radius=R
            )
            / lead
            - 1
        )

    assert correction(A_KAPPA / 10) / correction(A_KAPPA / 100) == pytest.approx(10, rel=0.02)
    assert theory.viscoelastic_tau0(a_kappa=0.0, density=N, radius=R, temperature0=T0) == math.inf
    assert (
        theory.viscoelastic_temperature_second_order(
            5.0, temperature0=T0, a_kappa=0.0, density=N, radius=R
        )
        == T0
    )
    z = [
        theory.viscoelastic_cooling_rate(T, a_kappa=A_KAPPA, density=N, radius=R)
        for T in (1.0, 0.01)
    ]
    assert z[0] / z[1] == pytest.approx(100 ** (3 / 5), rel=1e-12)


def test_first_order_rate_is_the_constant_xi_rate_at_the_effective_restitution():
    """Cross-check with Haff's tau0 (thesis 2.45): the loss (1 - xi^2) T per collision of
    constant xi, with 1 - xi^2 replaced by its viscoelastic average over collisions
    2 C1 a_kappa <g^(11/5)> / <g^2>, is the first-order rate; so the viscoelastic rate
    equals 2 / haff_tau0 (dT/dt = -2 T / tau0 for Haff) at that xi.  Quadrature of the
    collision-weighted speed density (g / s^2) exp(-g^2 / 2 s^2), s^2 = 2 T0."""
    s2 = 2 * T0

    def moment(p):
        return quad(lambda g: g**p * g / s2 * math.exp(-g * g / (2 * s2)), 0, np.inf)[0]

    one_minus_xi2 = 2 * theory.VISCOELASTIC_C1 * A_KAPPA * moment(2.2) / moment(2)
    xi = math.sqrt(1 - one_minus_xi2)
    haff = theory.haff_tau0(density=N, radius=R, restitution=xi, temperature0=T0)
    zeta = theory.viscoelastic_cooling_rate(T0, a_kappa=A_KAPPA, density=N, radius=R)
    assert zeta == pytest.approx(2 / haff, rel=1e-9)


def test_diffusion_and_msd():
    """D(t) = D0 (1 + t/tau0')^(-5/6); the MSD is 2 d int D (quadrature, 1e-10), and its
    late-time power law 12 d D0 tau0'^(5/6) t^(1/6) is approached as the formula's factor
    (1 + tau/t)^(1/6) - (tau/t)^(1/6) says; the local exponent d ln MSD / d ln t is
    (1/6) x / (x - 1) (t / (t + tau)), x = (1 + t/tau)^(1/6): 1/6 only as x grows, within
    1.1% once x = 100, t = 10^12 tau0' (numerical derivative: 1e-6)."""
    D, tau = 0.3, 2.0
    for t in (0.5, 10.0, 1e4):
        want = 2 * 3 * quad(lambda s: theory.viscoelastic_diffusion(s, D0=D, tau0=tau), 0, t)[0]
        assert theory.msd_viscoelastic(t, D0=D, tau0=tau) == pytest.approx(want, rel=1e-10)
    t = np.array([1e2, 1e6, 1e12]) * tau
    ratio = theory.msd_viscoelastic(t, D0=D, tau0=tau) / theory.msd_viscoelastic_asymptote(
        t, D0=D, tau0=tau
    )
    np.testing.assert_allclose(ratio, (1 + tau / t) ** (1 / 6) - (tau / t) ** (1 / 6), rtol=1e-9)
    h = 1e-4
    lt = math.log(1e12 * tau)
    slope = (
        math.log(theory.msd_viscoelastic(math.exp(lt + h), D0=D, tau0=tau))
        - math.log(theory.msd_viscoelastic(math.exp(lt - h), D0=D, tau0=tau))
    ) / (2 * h)
    x = (1 + 1e12) ** (1 / 6)
    assert slope == pytest.approx(x / (x - 1) / 6, rel=1e-6)
    assert slope == pytest.approx(1 / 6, rel=0.011)


def test_langevin_coefficients_of_the_viscoelastic_gas():
    """The power-law UDSBM with these coefficients and a = 5/6 has D gamma = T(t)/m of the
    cooling law and D(t) of viscoelastic_diffusion (identities of the parametrisation)."""
    c = theory.viscoelastic_langevin_coefficients(
        n=N, radius=R, volume=1.0, a_kappa=A_KAPPA, temperature0=T0
    )
    assert c.gamma0 * c.D0 == pytest.approx(T0, rel=1e-14)
    assert c.tau0 == theory.viscoelastic_tau0(a_kappa=A_KAPPA, density=N, radius=R, temperature0=T0)
    assert c.D0 == theory.diffusion_d0(density=N, radius=R, restitution=1.0, temperature0=T0)
    t = np.array([0.3, 30.0]) * c.tau0
    w = 1 + t / c.tau0
    np.testing.assert_allclose(
        c.gamma0 * w**-VISCO * c.D0 * w**-VISCO,
        theory.viscoelastic_temperature(t, temperature0=T0, tau0=c.tau0),
        rtol=1e-14,
    )


# -- power-law UDSBM -----------------------------------------------------------------------


@pytest.mark.parametrize("v0_sq", [None, 0.3, "udsbm"])
def test_moments_at_exponent_one_are_the_thesis_closed_forms(v0_sq):
    """a = 1: the numerical moments equal (2.113) and its transient (msd_udsbm) and the
    increment MSD of udsbm_increment_msd, to 1e-10 (the ODE's rtol 1e-12 accumulated);
    tau0 = inf: the Langevin (2.68)."""
    v0 = theory.udsbm_v0_sq(D0=D0, gamma0=G0, tau0=TAU0) if v0_sq == "udsbm" else v0_sq
    v = D0 * G0 if v0 is None else v0
    t = np.array([1e-3, 0.1, 1.0, 10.0, 100.0])
    got = theory.msd_powerlaw_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0, exponent=1.0, v0_sq=v)
    np.testing.assert_allclose(
        got, theory.msd_udsbm(t, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v), rtol=1e-10
    )
    lag, start = np.array([0.01, 0.5, 3.0, 0.2]), np.array([0.0, 2.0, 20.0, 50.0])
    np.testing.assert_allclose(
        theory.powerlaw_udsbm_increment_msd(
            lag, start=start, D0=D0, gamma0=G0, tau0=TAU0, exponent=1.0, v0_sq=v
        ),
        theory.udsbm_increment_msd(lag, start=start, D0=D0, gamma0=G0, tau0=TAU0, v0_sq=v),
        rtol=1e-8,  # the increment at lag 0.01 from t = 0 is a difference: 1e-10 / it
    )
    np.testing.assert_allclose(
        theory.msd_powerlaw_udsbm(t, D0=D0, gamma0=G0, tau0=math.inf, exponent=1.0, v0_sq=v),
        theory.msd_langevin(t, D0=D0, gamma0=G0, v0_sq=v),
        rtol=1e-10,
    )


@pytest.mark.parametrize("a", [0.5, VISCO, 1.0, 1.7, 3.0])
def test_propagator_integral_against_quad(a):
    """K(s, h) = int_s^{s+h} exp(-int_s^u gamma) du, behind every covariance here, against
    scipy quad of the same integral written out (tolerance 1e-9: quad's 1e-12 and the
    Gauss-Legendre panels', measured below 2e-13), lags from 1e-3 to 500, a = 3 included
    (gamma's integral converges, the velocity never forgets its start)."""

    def gamma_integral(s, u):
        if a == 1.0:
            return G0 * TAU0 * math.log((TAU0 + u) / (TAU0 + s))
        b = 1 - a
        return G0 * TAU0 * ((1 + u / TAU0) ** b - (1 + s / TAU0) ** b) / b

    for s, h in ((0.0, 1.0), (0.0, 50.0), (5.0, 500.0), (1.0, 1e-3)):
        pts = [s + 1 / G0] if h > 1 / G0 else None
        want = quad(
            lambda u, s=s: math.exp(-gamma_integral(s, u)),
            s,
            s + h,
            epsabs=0,
            epsrel=1e-12,
            limit=500,
            points=pts,
        )[0]
        got = _numerics._powerlaw_propagator_integral(s, h, G0, TAU0, a)
        assert got == pytest.approx(want, rel=1e-9)


def test_msd_is_the_double_integral_of_the_velocity_autocorrelation():
    """a = 5/6, an independent route: MSD(t) = 2 int_0^t dt1 <v^2>(t1) K(t1, t - t1) per
    dimension, K = int_{t1}^{t} exp(-int_{t1}^{u} gamma) du the propagator integral (the
    VACF <v(t1) v(t2)> = <v^2>(t1) exp(-int gamma), thesis 2.58 / 2.111), by scipy quad of
    the inner integral written out independently of theory's quadrature.  Agreement 1e-8
    (quad's tolerance)."""
    a, b = VISCO, 1 - VISCO

    def gamma_integral(t1, u):  # int_{t1}^{u} gamma0 (1 + s/tau0)^-a ds
        return G0 * TAU0 * ((1 + u / TAU0) ** b - (1 + t1 / TAU0) ** b) / b

    for t in (0.3, 4.0):

        def outer(t1, t=t):
            _, _, vv = theory.powerlaw_udsbm_moments(t1, D0=D0, gamma0=G0, tau0=TAU0, exponent=a)
            k = quad(lambda u: math.exp(-gamma_integral(t1, u)), t1, t, epsabs=0, epsrel=1e-12)[0]
            return vv * k

        want = 3 * 2 * quad(outer, 0, t, epsabs=0, epsrel=1e-11, limit=200)[0]
        assert theory.msd_powerlaw_udsbm(
            t, D0=D0, gamma0=G0, tau0=TAU0, exponent=a
        ) == pytest.approx(want, rel=1e-8)


def test_late_msd_approaches_the_overdamped_power_law():
    """a = 5/6: <xv> = (1/2) dMSD/dt per dimension tends to D(t) with a relative excess
    decaying like 1/(gamma(t) (tau0 + t)) = w^(-1/6) / (gamma0 tau0) (the velocity lags
    the cooling), so the ratio excess x gamma0 tau0 w^(1/6) settles (changes by < 5%
    from t = 10^4 to 10^6); the local exponent of dMSD/dt is -5/6 within that excess / 6
    + 1e-3; and MSD / the overdamped asymptote falls towards 1."""
    t = np.array([1e4, 1e5, 1e6])
    _, xv, _ = theory.powerlaw_udsbm_moments(t, D0=D0, gamma0=G0, tau0=TAU0, exponent=VISCO)
    w = 1 + t / TAU0
    excess = xv / (D0 * w**-VISCO) - 1
    settled = excess * G0 * TAU0 * w ** (1 / 6)
    assert abs(settled[-1] / settled[0] - 1) < 0.05
    slope = np.log(xv[2] / xv[1]) / np.log(10)
    assert abs(slope + 5 / 6) < excess[1] / 6 + 1e-3
    ratio = theory.msd_powerlaw_udsbm(
        t, D0=D0, gamma0=G0, tau0=TAU0, exponent=VISCO
    ) / theory.msd_powerlaw_udsbm_asymptote(t, D0=D0, tau0=TAU0, exponent=VISCO)
    assert np.all(np.diff(ratio) < 0) and np.all(ratio > 1)


def test_ergodicity_breaking_of_brownian_motion():
    """tau0 = inf and gamma0 lag = 10^4: the TAMSD of Brownian motion, whose increments over
    windows j, k have covariance 2 D (lag - |s_j - s_k|)+ per dimension, so EB = 2 sum
    overlap^2 / (d (M lag)^2) exactly for these windows; the inertial correction is
    O(1 / (gamma0 lag)) = 1e-4, allowed 1e-3 relative.  And it is near He et al.'s
    continuous-time 4 lag / (3 d t_stop) (within 5%: windows every lag/10, lag/t = 1/50)."""
    lag, t_stop = 1.0, 50.0
    starts = np.arange(0, t_stop - lag + 1e-9, lag / 10)
    eb = theory.udsbm_ergodicity_breaking(lag, start=starts, D0=1.0, gamma0=1e4, dim=2)
    overlap = np.maximum(lag - np.abs(starts[:, None] - starts[None, :]), 0)
    want = 2 * np.sum(overlap**2) / (2 * (len(starts) * lag) ** 2)
    assert eb == pytest.approx(want, rel=1e-3)
    assert eb == pytest.approx(4 * lag / (3 * 2 * t_stop), rel=0.05)


@pytest.mark.parametrize(
    "tau0,a", [(math.inf, 1.0), (TAU0, 1.0), (TAU0, VISCO), (TAU0, 1.5), (0.5, 0.3), (20.0, VISCO)]
)
def test_ergodicity_breaking_matches_the_per_pair_reference(tau0, a):
    """The fast EB (the covariance once on the grid of window ends, the propagator integral
    summed over the grid's segments) against the slow per-pair reference
    (tests/helpers/eb_reference.py: the propagator integral by Gauss-Legendre for each pair
    of times) on overlapping windows on a grid, windows at random starts (no shared ends)
    and one window.  Both are exact up to rounding: they agree to ~1e-14; allowed 1e-9
    relative, the brief's 1e-8 with margin, for the cancellation of the four covariances
    in C_jk at short lags (up to <x^2> / increment ~ 1e3 here)."""
    rng = np.random.default_rng(7)
    cases = [
        (1.0, np.arange(0.0, 20.0, 0.25)),
        (0.35, np.sort(rng.uniform(0.0, 15.0, 60))),
        (2.0, np.array([0.0])),
        (0.05, np.arange(0.0, 5.0, 0.05)),
    ]
    for lag, starts in cases:
        got = theory.udsbm_ergodicity_breaking(
            lag, start=starts, D0=1.3, gamma0=2.0, tau0=tau0, exponent=a, dim=2, v0_sq=0.7
        )
        want = eb_reference.ergodicity_breaking(lag, starts, 1.3, 2.0, tau0, a, 2, v0_sq=0.7)
        assert got == pytest.approx(want, rel=1e-9), (lag, len(starts))
    # the covariance is built in blocks of rows and mirrored block by block: blocks of 7
    # (many, unequal) give the very same numbers as one block (per-row arithmetic is the same)
    times = np.unique(np.concatenate([cases[1][1], cases[1][1] + cases[1][0]]))
    sol = _numerics._powerlaw_ode(2.0, tau0, a, 0.7 / 2.6, 2.0 * times[-1])
    one = _numerics._covariance_on_grid(times, sol, 1.3, 2.0, tau0, a, block=times.size)
    many = _numerics._covariance_on_grid(times, sol, 1.3, 2.0, tau0, a, block=7)
    np.testing.assert_array_equal(many, one)
    np.testing.assert_array_equal(one, one.T)


def _brownian_eb(lag, starts, dim):
    """EB of Brownian motion averaged over windows [s, s + lag], exactly: the window's
    squared displacements are Gaussian quadratic forms, Cov(|X_i|^2, |X_j|^2) = 2 d (2 D
    o_ij)^2 with o_ij the windows' overlap, over the squared mean (2 d D lag)^2."""
    overlap = np.clip(lag - np.abs(starts[:, None] - starts[None, :]), 0.0, None) / lag
    return 2.0 / (dim * starts.size**2) * float(np.sum(overlap**2))


def test_ergodicity_breaking_of_langevin_tends_to_brownian_motions():
    """As gamma0 lag -> oo the Langevin EB becomes Brownian motion's for the same windows
    (the exact sum above, 4 lag / (3 d t_stop) for dense windows, Deng & Barkai, Phys. Rev.
    E 79, 011112 (2009)); the velocity memory adds O(1 / (gamma0 lag)): measured 1.27 /
    (gamma0 lag) here, bound 2 / (gamma0 lag)."""
    starts = np.arange(0.0, 9.0 + 1e-9, 0.25)
    for gamma0 in (1e2, 1e4):
        got = theory.udsbm_ergodicity_breaking(1.0, start=starts, D0=D0, gamma0=gamma0, dim=2)
        assert got == pytest.approx(_brownian_eb(1.0, starts, 2), rel=2.0 / gamma0)


def test_ergodicity_breaking_does_not_vanish_for_udsbm():
    """Non-ergodic: with 4x longer runs at the same lag, EB of Langevin falls as Brownian
    motion's does (ergodic, ~ lag / t_stop: 0.240 here), while UDSBM's (a = 1 and 5/6) falls
    far less (the late windows move ever more slowly than the early ones: the time average
    is dominated by them).  Langevin's velocity memory raises both EBs alike (by 15% at
    gamma0 lag = 9.26, a function of gamma0 lag, not of t_stop; measured: the ratio within
    0.2% of Brownian motion's), bound 1%."""
    lag = 1.0

    def starts_to(t_stop):
        return np.arange(0, t_stop - lag + 1e-9, 0.25)

    def eb(tau0, a, t_stop):
        return theory.udsbm_ergodicity_breaking(
            lag, start=starts_to(t_stop), D0=D0, gamma0=G0, tau0=tau0, exponent=a
        )

    lang = eb(math.inf, 1.0, 40.0) / eb(math.inf, 1.0, 10.0)
    brownian = _brownian_eb(lag, starts_to(40.0), 3) / _brownian_eb(lag, starts_to(10.0), 3)
    assert lang == pytest.approx(brownian, rel=0.01)
    for a in (1.0, VISCO):
        assert eb(TAU0, a, 40.0) / eb(TAU0, a, 10.0) > 0.5


@pytest.mark.parametrize(
    "call,match",
    [
        (
            lambda: theory.viscoelastic_tau0(a_kappa=-1.0, density=N, radius=R, temperature0=T0),
            "a_kappa",
        ),
        (
            lambda: theory.viscoelastic_tau0(
                a_kappa=math.nan, density=N, radius=R, temperature0=T0
            ),
            "a_kappa",
        ),
        (lambda: theory.viscoelastic_delta(T0, a_kappa=-0.1), "a_kappa"),
        (
            lambda: theory.viscoelastic_cooling_rate(
                T0, a_kappa=A_KAPPA, density=N, radius=R, order=3
            ),
            "order",
        ),
        (
            lambda: theory.viscoelastic_cooling_time(
                2 * T0, temperature0=T0, a_kappa=A_KAPPA, density=N, radius=R
            ),
            r"\(0, T0\]",
        ),
        (
            lambda: theory.viscoelastic_cooling_time(
                0.5, temperature0=T0, a_kappa=5.0, density=N, radius=R
            ),
            "too large",
        ),
        (
            lambda: theory.viscoelastic_temperature_second_order(
                -1.0, temperature0=T0, a_kappa=A_KAPPA, density=N, radius=R
            ),
            "t must",
        ),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


# Each function with the positional arguments of its earlier (unreleased) order, or of
# haff_tau0's: a swapped a_kappa and density, or radius and volume, must not give a number.
POSITIONAL_CALLS = [
    ("viscoelastic_delta", (A_KAPPA, T0)),
    ("viscoelastic_cooling_rate", (T0, A_KAPPA, N, R)),
    ("viscoelastic_tau0", (A_KAPPA, N, R, T0)),
    ("viscoelastic_tau0", (N, R, A_KAPPA, T0)),  # haff_tau0's order with a_kappa for xi
    ("viscoelastic_temperature", (1.0, T0, TAU0)),
    ("viscoelastic_cooling_time", (0.5, T0, A_KAPPA, N, R)),
    ("viscoelastic_temperature_second_order", (1.0, T0, A_KAPPA, N, R)),
    ("viscoelastic_diffusion", (1.0, D0, TAU0)),
    ("msd_viscoelastic", (1.0, D0, TAU0)),
    ("msd_viscoelastic_asymptote", (1.0, D0, TAU0)),
    ("msd_viscoelastic_second_order", (1.0, T0, A_KAPPA, N, R)),
    ("viscoelastic_langevin_coefficients", (N, R, 1.0, A_KAPPA, T0)),
    ("powerlaw_udsbm_moments", (1.0, D0, G0, TAU0, VISCO)),
    ("msd_powerlaw_udsbm", (1.0, D0, G0, TAU0, VISCO)),
    ("msd_powerlaw_udsbm_asymptote", (1.0, D0, TAU0, VISCO)),
    ("powerlaw_udsbm_increment_msd", (1.0, 0.0, D0, G0, TAU0, VISCO)),
    ("udsbm_ergodicity_breaking", (1.0, [0.0], D0, G0)),
]


@pytest.mark.parametrize("name,args", POSITIONAL_CALLS, ids=[c[0] for c in POSITIONAL_CALLS])
def test_parameters_are_keyword_only(name, args):
    """The material and model parameters are keyword-only (at most t, T or the lag is
    positional), so a swap cannot pass silently: the positional call is a TypeError."""
    with pytest.raises(TypeError, match="positional argument"):
        getattr(theory, name)(*args)


def test_ergodicity_breaking_of_many_windows_is_built_from_blocks(monkeypatch):
    """20 000 windows one step apart: the covariance is taken only on the ends of the
    windows that overlap one another, block by block (at most 2 (256 + 5) times here, as
    against all 20 005 ends at once, a 3 GB matrix, which made three lags of an engine run
    take half a minute); disjoint windows come from the one-product recursion.  Checked
    against Brownian motion's exact EB for the same windows (the velocity memory adds
    O(1 / (gamma0 lag)) = 2e-4 here, allowed 1e-3)."""
    from granular.theory import ergodicity

    sizes = []
    real = ergodicity._covariance_on_grid

    def spy(times, *args, **kwargs):
        sizes.append(times.size)
        assert times.size <= 2 * (256 + 5), f"covariance on {times.size} times at once"
        return real(times, *args, **kwargs)

    monkeypatch.setattr(ergodicity, "_covariance_on_grid", spy)
    lag, starts = 0.05, np.arange(0.0, 200.0, 0.01)
    eb = theory.udsbm_ergodicity_breaking(lag, start=starts, D0=1.0, gamma0=1e5, dim=2)
    assert len(sizes) == -(-starts.size // 256)
    # Brownian motion: C_jk = 2 D (lag - |s_j - s_k|)+, only the 9 nearest neighbours overlap
    gaps = np.arange(-4, 5) * 0.01
    counts = starts.size - np.abs(np.arange(-4, 5))
    want = 2 * np.sum(counts * (lag - np.abs(gaps)) ** 2) / (2 * (starts.size * lag) ** 2)
    assert eb == pytest.approx(want, rel=1e-3)


@pytest.mark.parametrize(
    "young, radius, mass",
    [(1e9, 0.01, 5e-324), (1e308, 1e300, 1e-300), (1e-300, 1e-300, 1e300)],
)
def test_from_material_outside_float64_is_refused_by_name(young, radius, mass):
    """Each number positive and finite, but the Hertz constant kappa leaves float64 (the
    smallest mass halves to 0, a huge modulus over a tiny mass overflows, the opposite
    underflows to 0): a ValueError naming the inputs and kappa, not a ZeroDivisionError or
    a law with kappa = inf or 0."""
    with pytest.raises(ValueError, match=r"give the Hertz constant kappa = .*outside float64"):
        Viscoelastic.from_material(young=young, poisson=0.3, damping=1e-4, radius=radius, mass=mass)
