"""The Langevin engine against theory.  Statistical tolerances are five standard errors
of the estimate, from the ensemble size (stated at each assertion)."""
import math

import numpy as np
import pytest

import granular
from granular import langevin, theory

G0, D0 = 9.26, 0.072          # the thesis' standard gas, xi = 0.8 (theory.langevin_coefficients)
TAU0 = 0.972
VT = G0 * D0                  # T0 / m


def rel_se_msd(n, dim=3):
    """Relative standard error of a mean of |x|^2 over n particles when each component is
    Gaussian: sqrt(2 / (dim n))."""
    return math.sqrt(2 / (dim * n))


@pytest.mark.parametrize("model,tau0,initial", [("langevin", math.inf, "thermal"),
                                                ("udsbm", TAU0, "udsbm"),
                                                ("udsbm", TAU0, "thermal")])
def test_exact_scheme_msd_matches_theory(model, tau0, initial):
    """Ensemble MSD vs (2.68) for Langevin and (2.113) for UDSBM with App. C's initial
    speed (and the transient term for a thermal start), from the ballistic to the
    diffusive / logarithmic regime; 5 standard errors at every sample."""
    n = 20000
    r = langevin.run(n, gamma0=G0, D0=D0, tau0=tau0, dt=0.01, t_stop=50.0, scheme="exact",
                     initial=initial, seed=1)
    th = r.theory_msd()
    ok = r.times > 0
    np.testing.assert_array_less(np.abs(r.msd[ok] / th[ok] - 1), 5 * rel_se_msd(n))
    assert r.msd[0] == 0.0
    # regimes: ballistic at the first step, logarithmic/diffusive at the end
    assert r.times[-1] * G0 > 100


def test_euler_maruyama_msd_matches_theory_at_small_steps():
    """EM at gamma0 dt = 0.009: its velocity bias 2/(2 - gamma0 dt) - 1 = 0.47% adds to
    the statistical tolerance."""
    n = 20000
    for tau0 in (math.inf, TAU0):
        r = langevin.run(n, gamma0=G0, D0=D0, tau0=tau0, dt=0.001, t_stop=5.0, scheme="em",
                         initial="udsbm" if tau0 < math.inf else "thermal", seed=2)
        ok = r.times > 0
        bias = 2 / (2 - G0 * 0.001) - 1
        np.testing.assert_array_less(np.abs(r.msd[ok] / r.theory_msd()[ok] - 1),
                                     5 * rel_se_msd(n) + bias)


def test_ballistic_start_is_exact():
    """Fixed speed, first Euler step: x = v0 dt exactly, so MSD(dt) = speed^2 dt^2."""
    r = langevin.run(100, gamma0=G0, D0=D0, dt=1e-4, t_stop=1e-3, speed=1.5, initial="fixed",
                     sample_times=[0, 1e-4], seed=3)
    assert r.msd[1] == pytest.approx(1.5**2 * 1e-8, rel=1e-13)
    assert r.v0_sq == pytest.approx(0.75)


@pytest.mark.parametrize("gdt", [0.5, 1.0, 1.5])
def test_euler_maruyama_velocity_bias(gdt):
    """Stationary <v^2> of EM is (T/m) 2 / (2 - gamma0 dt) (2.92 iterated); relative standard
    error of the mean over 3N Gaussian components, sqrt(2 / (3 N))."""
    n = 100_000
    r = langevin.run(n, gamma0=G0, D0=D0, dt=gdt / G0, t_stop=60 / G0, scheme="em", seed=4,
                     sample_times=[60 / G0])
    assert r.v2[-1] / (3 * VT) == pytest.approx(2 / (2 - gdt), rel=5 * rel_se_msd(n))
    exact = langevin.run(n, gamma0=G0, D0=D0, dt=gdt / G0, t_stop=60 / G0, scheme="exact",
                         seed=4, sample_times=[60 / G0])
    assert exact.v2[-1] / (3 * VT) == pytest.approx(1.0, rel=5 * rel_se_msd(n))


def test_exact_step_moments():
    """One exact step from x = 0, v = 0: v' ~ N(0, D g (1 - c^2)), x' Gaussian with the OU
    variance (2D/g)(h - 2(1-c) + (1-c^2)/2) and covariance D (1-c)^2, c = exp(-h), h = g dt.
    Checked with 10^6 particles in 1D: variances to 5 sqrt(2/N), the correlation coefficient
    to 5 (1 - rho^2)/sqrt(N), kurtosis 3 to 5 sqrt(24/N) (which also tests the Gaussian
    generator)."""
    n, g, D, dt = 1_000_000, 2.0, 0.5, 0.3
    r = langevin.run(n, gamma0=g, D0=D, dt=dt, t_stop=dt, scheme="exact", dim=1,
                     initial="fixed", speed=1e-300, sample_times=[dt], store_positions=True, seed=5)
    x = r.positions[0, :, 0]
    v = r.final_velocities[:, 0]
    h, c = g * dt, math.exp(-g * dt)
    var_v = D * g * (1 - c * c)
    var_x = 2 * D / g * (h - 2 * (1 - c) + (1 - c * c) / 2)
    cov = D * (1 - c) ** 2
    tol = 5 * math.sqrt(2 / n)
    assert np.var(v) == pytest.approx(var_v, rel=tol)
    assert np.var(x) == pytest.approx(var_x, rel=tol)
    rho = cov / math.sqrt(var_v * var_x)
    assert np.corrcoef(x, v)[0, 1] == pytest.approx(rho, abs=5 * (1 - rho**2) / math.sqrt(n))
    for a in (x, v):
        assert abs(np.mean(a)) < 5 * math.sqrt(np.var(a) / n)
        kurt = np.mean((a - a.mean()) ** 4) / np.var(a) ** 2
        assert abs(kurt - 3) < 5 * math.sqrt(24 / n)


def test_tamsd_equals_msd_for_langevin_but_not_for_udsbm():
    """Ergodicity (thesis 2.114, Figs 4.21-4.23): for the Langevin model the time-averaged
    MSD equals the ensemble MSD (within 5 standard errors of the particle average of the
    TAMSD); for UDSBM it is far below the ensemble MSD at lags beyond tau0."""
    n = 4000
    lags = np.array([0.05, 0.5, 5.0])
    r = langevin.run(n, gamma0=G0, D0=D0, dt=0.01, t_stop=100.0, scheme="exact", tamsd_lags=lags, seed=6)
    se = r.tamsd_per_particle.std(0, ddof=1) / math.sqrt(n)
    expected = theory.msd_langevin(lags, D0, G0)
    np.testing.assert_array_less(np.abs(r.tamsd - expected), 5 * se)
    u = langevin.run(n, gamma0=G0, D0=D0, tau0=TAU0, dt=0.01, t_stop=100.0, scheme="exact",
                     initial="udsbm", tamsd_lags=lags, seed=6)
    assert np.all(u.tamsd[1:] < 0.5 * u.theory_msd(lags)[1:])


def test_same_seed_same_result_whatever_the_chunking(monkeypatch):
    kw = dict(gamma0=G0, D0=D0, tau0=TAU0, dt=0.01, t_stop=2.0, tamsd_lags=[0.1, 1.0],
              store_positions=True, seed=7)
    a = langevin.run(300, **kw)
    monkeypatch.setattr(langevin, "_CHUNK_PARTICLE_STEPS", 200 * 7)  # 7 particles a call
    b = langevin.run(300, **kw)
    for name in ("msd", "v2", "tamsd", "positions", "final_velocities"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    c = langevin.run(300, **{**kw, "seed": 8})
    assert not np.array_equal(a.positions, c.positions)


def test_refuses_unstable_euler_maruyama():
    with pytest.raises(granular.UnstableStepError, match="gamma0\\*dt >= 2.*exact") as info:
        langevin.run(10, gamma0=10.0, D0=0.1, dt=0.2, t_stop=1.0)
    assert info.value.value == pytest.approx(2.0)
    # the exact scheme takes the same step
    r = langevin.run(1000, gamma0=10.0, D0=0.1, dt=0.2, t_stop=100.0, scheme="exact", seed=1,
                     sample_times=[100.0])
    assert r.v2[-1] / 3 == pytest.approx(1.0, rel=5 * rel_se_msd(1000))


def test_from_scene_uses_the_thesis_coefficients():
    s = granular.Scene.random(1000, 0.025, restitution=0.8, seed=1)
    c = langevin.coefficients_from_scene(s)
    ref = theory.langevin_coefficients(1000, 0.025, 1.0, 0.8, s.temperature)
    assert c == pytest.approx(ref)
    r = langevin.from_scene(s, dt=0.01, t_stop=1.0, n=200, seed=1)
    assert r.model == "udsbm" and r.tau0 == pytest.approx(ref.tau0)
    m = langevin.from_scene(s.replace(restitution=1.0), dt=0.01, t_stop=1.0, n=200, seed=1)
    assert m.model == "langevin"


@pytest.mark.parametrize("kwargs,match", [
    (dict(gamma0=-1.0), "gamma0 must be positive"),
    (dict(dt=0.0), "dt must be positive"),
    (dict(t_stop=float("nan")), "t_stop must be positive"),
    (dict(model="brownian"), "model must be one of"),
    (dict(scheme="rk4"), "scheme must be one of"),
    (dict(dim=4), "dim must be"),
    (dict(sample_times=[0.5, 0.2]), "increasing"),
    (dict(sample_times=[0.5, 5.0]), "past t_stop"),
    (dict(tamsd_lags=[0.0]), "tamsd_lags"),
    (dict(initial="hot"), "initial must be one of"),
    (dict(model="udsbm"), "finite tau0"),
    (dict(initial="udsbm"), "App. C"),
])
def test_bad_input(kwargs, match):
    base = dict(gamma0=G0, D0=D0, dt=0.01, t_stop=1.0)
    base.update(kwargs)
    with pytest.raises(ValueError, match=match):
        langevin.run(10, **base)
