"""UDSBM with power-law coefficients gamma0 (1 + t/tau0)^-a, D0 (1 + t/tau0)^-a
(``langevin.run(..., exponent=a)``): the engine against the slow reference, against the
theory of ``granular.theory`` (ensemble MSD, TAMSD, ergodicity breaking) and the schemes'
own error, computed without noise.

Statistical tolerances are five standard errors of the estimate (stated at each assertion):
a false alarm has probability 5.7e-7 per comparison (two-sided Gaussian tail at 5 sigma), so
even a test comparing at all its ~60 sample times fails by chance less than once in 10^4
runs."""

import math

import numpy as np
import pytest

from granular import _core, langevin, theory

from helpers import sde_reference

G0, D0 = 9.26, 0.072  # the thesis' standard gas at xi = 0.8 (as tests/test_langevin.py)
TAU0 = 0.972
VISCO = 5 / 6  # the viscoelastic gas: T ~ t^(-5/3), D ~ t^(-5/6)


def rel_se_msd(n, dim=3):
    """Relative standard error of a mean of |x|^2 over n particles whose components are
    Gaussian (true at every time: a linear SDE from Gaussian velocities): sqrt(2/(dim n))."""
    return math.sqrt(2 / (dim * n))


# -- the default is today's UDSBM; the engine is the reference integrator ------------------


@pytest.mark.parametrize("scheme", ["em", "exact"])
def test_exponent_one_is_the_thesis_udsbm_to_the_bit(scheme):
    """exponent=1.0 given explicitly takes the same code path as before (a division, no
    pow): every stored number equals the default run's.  tests/test_golden.py checks the
    default against the recorded hashes."""
    kw = dict(
        gamma0=G0,
        D0=D0,
        tau0=TAU0,
        dt=0.01,
        t_stop=2.0,
        scheme=scheme,
        tamsd_lags=[0.1, 1.0],
        store_positions=True,
        seed=3,
    )
    a = langevin.run(40, **kw)
    b = langevin.run(40, exponent=1.0, **kw)
    for name, value in a.arrays().items():
        np.testing.assert_array_equal(b.arrays()[name], value, err_msg=name)
    assert b.exponent == 1.0


def _assert_rounding_close(got, want):
    """1e-12 of the largest magnitude: the two differ by a few ulps a step (other
    rounding, pow against the reference's **), see tests/test_langevin.py."""
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * float(np.max(np.abs(want))))


@pytest.mark.parametrize(
    "scheme,dim,exponent",
    [("em", 3, VISCO), ("exact", 3, VISCO), ("exact", 2, 0.5), ("em", 1, 1.7)],
)
def test_the_engine_is_the_reference_integrator_for_any_exponent(scheme, dim, exponent):
    """Every position at every step, the final velocities and the TAMSD sums (lags 1, 33,
    60 steps) of the C engine against tests/helpers/sde_reference.py, which draws the same
    random numbers and integrates from the equations with (1 + t/tau0)**-a."""
    v0 = np.random.default_rng(2).normal(scale=0.8, size=(4, dim))
    kw = dict(
        model="udsbm",
        scheme=scheme,
        gamma0=G0,
        D0=D0,
        tau0=TAU0,
        dt=0.05,
        n_steps=60,
        exponent=exponent,
    )
    key, lags = 0x0123456789ABCDEF, [1, 33, 60]
    pos, v, x2, tamsd = sde_reference.engine(v0, key, lags=lags, **kw)
    xs, vs = sde_reference.run(v0, key, **kw)
    _assert_rounding_close(pos, xs)
    _assert_rounding_close(v, vs[-1])
    _assert_rounding_close(x2, (xs * xs).sum(axis=1))
    for m, lag in enumerate(lags):
        stride = _core.sde_lag_stride(lag)
        windows = len(range(0, 61 - lag, stride))
        _assert_rounding_close(
            tamsd[:, m] / windows, sde_reference.tamsd_per_particle(xs, lag, stride)
        )
    # and the exponent changes the path (a test that could not see it would pass anyway)
    other = dict(kw, exponent=1.0)
    assert np.max(np.abs(sde_reference.engine(v0, key, **other)[0] - pos)) > 1e-6


@pytest.mark.parametrize("scheme", ["em", "exact"])
def test_same_result_whatever_the_chunking(monkeypatch, scheme):
    """a = 5/6: bit-identical results whether the particles go to C together (the step
    coefficients from the per-call table) or one at a time in segments of 7 steps (computed
    inline per step): the table holds the same numbers."""
    kw = dict(
        gamma0=G0,
        D0=D0,
        tau0=TAU0,
        exponent=VISCO,
        scheme=scheme,
        dt=0.01,
        t_stop=1.0,
        tamsd_lags=[0.07, 0.3],
        store_positions=True,
        seed=9,
    )
    a = langevin.run(12, **kw)
    monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", 7)
    b = langevin.run(12, **kw)
    for name in ("positions", "final_velocities", "tamsd_per_particle", "v2"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


# -- against theory ------------------------------------------------------------------------


@pytest.mark.parametrize("exponent", [VISCO, 0.5])
def test_exact_scheme_msd_matches_theory(exponent):
    """Ensemble MSD at 60 log-spaced times up to t = 30 (30 tau0, gamma0 t = 278) against
    theory.msd_powerlaw_udsbm (the moment ODEs), thermal start.  Tolerance: 5 relative
    standard errors, 5 sqrt(2 / (3 * 10000)) = 4.1%, plus the scheme's own bias, below
    1e-5 at dt = 0.01 (test_scheme_errors_without_noise)."""
    n = 10000
    r = langevin.run(
        n, gamma0=G0, D0=D0, tau0=TAU0, exponent=exponent, dt=0.01, t_stop=30.0, seed=11
    )
    th = r.theory_msd()
    ok = r.times > 0
    np.testing.assert_array_less(np.abs(r.msd()[ok] / th[ok] - 1), 5 * rel_se_msd(n) + 1e-5)
    # the temperature: <v^2>(t) of the same moments, same tolerance
    _, _, vv = theory.powerlaw_udsbm_moments(
        r.times, D0=D0, gamma0=G0, tau0=TAU0, exponent=exponent, v0_sq=r.v0_sq
    )
    np.testing.assert_array_less(np.abs(r.v2 / (3 * vv) - 1), 5 * rel_se_msd(n) + 1e-5)


def _scheme_moments(scheme, exponent, dt, n_steps, v0_sq):
    """The exact expectation of a scheme's <x^2>, <xv>, <v^2> per dimension after each step
    (no noise: each step is linear, (x, v) -> M (x, v) + noise of covariance Q, so the
    second moments go S -> M S M^T + Q), from the equations as sde_reference writes them."""
    S = np.array([[0.0, 0.0], [0.0, v0_sq]])
    out = np.zeros((n_steps + 1, 3))
    out[0] = 0.0, 0.0, v0_sq
    for k in range(1, n_steps + 1):
        if scheme == "em":
            g, D = sde_reference.coefficients("udsbm", G0, D0, TAU0, (k - 1) * dt, exponent)
            M = np.array([[1.0, dt], [0.0, 1.0 - g * dt]])
            Q = np.array([[0.0, 0.0], [0.0, 2 * D * g * g * dt]])
        else:
            g, D = sde_reference.coefficients("udsbm", G0, D0, TAU0, (k - 0.5) * dt, exponent)
            c, drift, L = sde_reference.ou_step(g, D, dt)
            M = np.array([[1.0, drift], [0.0, c]])
            P = np.array([[0.0, 1.0], [1.0, 0.0]])  # L is ordered (v, x)
            Q = P @ L @ L.T @ P
        S = M @ S @ M.T + Q
        out[k] = S[0, 0], S[0, 1], S[1, 1]
    return out


def test_scheme_errors_without_noise():
    """What is exact and what is approximated, measured without sampling noise: the
    expected <x^2> of each scheme after 5 time units (2 gamma0 tau0 / a relaxation times)
    against the moment ODEs.  Exact scheme (OU step exact, coefficients frozen at the
    step's midpoint): error O(dt^2), so it falls 100-fold when dt falls 10-fold (between
    60 and 160 allowed: higher orders at dt = 0.05); Euler-Maruyama: O(gamma0 dt), falling
    10-fold (8 to 12).  At dt = 0.01 the exact scheme is within 1e-5 relative (measured
    9e-7; docs/powerlaw_udsbm.md)."""
    t = 5.0
    th_xx, _, _ = theory.powerlaw_udsbm_moments(t, D0=D0, gamma0=G0, tau0=TAU0, exponent=VISCO)
    err = {}
    for scheme in ("em", "exact"):
        for dt in (0.05, 0.005):
            xx = _scheme_moments(scheme, VISCO, dt, round(t / dt), D0 * G0)[-1, 0]
            err[scheme, dt] = abs(xx / th_xx - 1)
    assert 60 < err["exact", 0.05] / err["exact", 0.005] < 160
    assert 8 < err["em", 0.05] / err["em", 0.005] < 12
    exact_01 = _scheme_moments("exact", VISCO, 0.01, 500, D0 * G0)[-1, 0]
    assert abs(exact_01 / th_xx - 1) < 1e-5


def test_exact_scheme_against_euler_maruyama_at_small_steps():
    """Both schemes sampled at dt = 0.001 (EM's bias 2/(2 - gamma0 dt) - 1 = 0.47%) agree
    with each other within the statistics: their difference at each sample time within
    5 standard errors of a difference of two independent means, sqrt(2) rel_se, plus the
    bias."""
    n = 10000
    kw = dict(gamma0=G0, D0=D0, tau0=TAU0, exponent=VISCO, dt=0.001, t_stop=3.0)
    ex = langevin.run(n, scheme="exact", seed=21, **kw)
    em = langevin.run(n, scheme="em", seed=22, **kw)
    ok = ex.times > 0
    tol = 5 * math.sqrt(2) * rel_se_msd(n) + (2 / (2 - G0 * 0.001) - 1)
    np.testing.assert_array_less(np.abs(em.msd()[ok] / ex.msd()[ok] - 1), tol)


def _tamsd_run(exponent, seed):
    return langevin.run(
        4000,
        gamma0=G0,
        D0=D0,
        tau0=TAU0,
        exponent=exponent,
        dt=0.01,
        t_stop=20.0,
        tamsd_lags=[0.5, 2.0, 5.0],
        seed=seed,
    )


@pytest.mark.parametrize("exponent", [VISCO, 1.0])
def test_tamsd_and_ergodicity_breaking_match_theory(exponent):
    """The particle-averaged TAMSD and the measured EB = Var/mean^2 over particles against
    the theory of the same estimator (the engine's windows; EB at the lags 2 and 5,
    whose theory costs (windows)^2 quadratures).  Tolerances, 5 standard
    errors: for the TAMSD mean, the sample standard deviation of the per-particle TAMSD
    over sqrt(N); for EB, the delta method, SE^2 = (m4 - s^4)/(N mean^4) + 4 EB^2 s^2 /
    (N mean^2) with the sample's own moments (m4 the 4th central moment).  And the time
    average is not the ensemble MSD: the TAMSD lies many standard errors below the MSD at
    t = lag (non-ergodic for a = 1 and 5/6)."""
    r = _tamsd_run(exponent, seed=31 if exponent == 1.0 else 32)
    per = r.tamsd(per_particle=True)
    n = per.shape[0]
    mean, sd = per.mean(axis=0), per.std(axis=0)
    np.testing.assert_array_less(np.abs(mean - r.theory_tamsd()), 5 * sd / math.sqrt(n))
    eb_lags = [2.0, 5.0]
    eb = r.ergodicity_breaking(eb_lags)
    per, mean, sd = per[:, 1:], mean[1:], sd[1:]
    m4 = ((per - mean) ** 4).mean(axis=0)
    se = np.sqrt((m4 - sd**4) / (n * mean**4) + 4 * eb**2 * sd**2 / (n * mean**2))
    eb_th = r.theory_ergodicity_breaking(eb_lags)
    np.testing.assert_array_less(np.abs(eb - eb_th), 5 * se)
    msd_at_lag = theory.msd_powerlaw_udsbm(
        r.tamsd_lags[1:], D0=D0, gamma0=G0, tau0=TAU0, exponent=exponent, v0_sq=r.v0_sq
    )
    assert np.all(msd_at_lag - mean > 10 * sd / math.sqrt(n))


# -- bad input -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(exponent=0.0), "exponent must be positive"),
        (dict(exponent=-0.5), "exponent must be positive"),
        (dict(exponent=math.nan), "exponent must be positive"),
        (dict(exponent=math.inf), "exponent must be positive"),
        (dict(exponent=0.5, tau0=math.inf), "exponent is UDSBM's"),
        (dict(exponent=0.5, initial="udsbm"), "initial='udsbm'"),
    ],
)
def test_bad_exponent(kwargs, match):
    kw = dict(gamma0=G0, D0=D0, tau0=TAU0, dt=0.01, t_stop=0.1) | kwargs
    with pytest.raises(ValueError, match=match):
        langevin.run(5, **kw)


def test_core_refuses_a_bad_exponent():
    args = sde_reference.one_step_args(gamma0=G0, D0=D0, tau0=TAU0)
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="exponent must be positive"):
            _core.sde_run(**args, exponent=bad)


def test_theory_refuses_bad_input():
    with pytest.raises(ValueError, match="exponent must be positive"):
        theory.msd_powerlaw_udsbm(1.0, D0=D0, gamma0=G0, tau0=TAU0, exponent=0.0)
    with pytest.raises(ValueError, match="exponent must be positive"):
        theory.powerlaw_udsbm_increment_msd(
            1.0, start=0.0, D0=D0, gamma0=G0, tau0=TAU0, exponent=-1.0
        )
    with pytest.raises(ValueError, match="gamma0 must be positive"):
        theory.msd_powerlaw_udsbm(1.0, D0=D0, gamma0=-G0, tau0=TAU0, exponent=VISCO)
    with pytest.raises(ValueError, match="t must be >= 0 and finite"):
        theory.msd_powerlaw_udsbm(-1.0, D0=D0, gamma0=G0, tau0=TAU0, exponent=VISCO)
    with pytest.raises(ValueError, match="0 < exponent < 1"):
        theory.msd_powerlaw_udsbm_asymptote(1.0, D0=D0, tau0=TAU0, exponent=1.0)
    with pytest.raises(ValueError, match="lag > 0"):
        theory.udsbm_ergodicity_breaking(0.0, start=[0.0], D0=D0, gamma0=G0)
