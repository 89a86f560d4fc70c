"""Data reduction on synthetic trajectories with known answers."""

import math

import numpy as np
import pytest
from scipy import stats

from granular import analysis, theory


def random_walk(T=400, N=300, d=3, D=0.5, dt=0.1, seed=0):
    rng = np.random.default_rng(seed)
    steps = rng.normal(scale=math.sqrt(2 * D * dt), size=(T - 1, N, d))
    x = np.concatenate([np.zeros((1, N, d)), np.cumsum(steps, axis=0)]) + rng.random((1, N, d))
    return np.arange(T) * dt, x


def test_msd_of_ballistic_motion_is_exact():
    rng = np.random.default_rng(1)
    v = rng.normal(size=(50, 3))
    t = np.logspace(-2, 2, 17)
    x = rng.random((1, 50, 3)) + t[:, None, None] * v[None]
    expected = np.mean(np.sum(v * v, axis=1)) * (t - t[0]) ** 2  # from the first sample
    np.testing.assert_allclose(analysis.msd(x), expected, rtol=1e-12)
    per = analysis.msd(x, per_dimension=True)
    np.testing.assert_allclose(per.sum(1), expected, rtol=1e-12)
    # TAMSD of ballistic motion (any lag): v^2 lag^2
    tu = np.linspace(0, 10, 101)
    xu = tu[:, None, None] * v[None]
    np.testing.assert_allclose(
        analysis.tamsd(xu, [0.1, 2.5, 10.0], times=tu),
        np.mean(np.sum(v * v, 1)) * np.array([0.01, 6.25, 100.0]),
        rtol=1e-9,
    )


def test_random_walk_msd_and_tamsd_give_2dDt():
    """Gaussian random walk, D = 0.5: MSD = 2 d D t.  The ensemble MSD at time t averages N
    independent chi-square variables: relative standard error sqrt(2 / (d N)); 5 sigma."""
    t, x = random_walk()
    N, d = x.shape[1], x.shape[2]
    m = analysis.msd(x)
    k = [10, 100, 399]
    np.testing.assert_allclose(m[k], 2 * d * 0.5 * t[k], rtol=5 * math.sqrt(2 / (d * N)))
    lags = np.array([0.1, 1.0, 10.0])
    tam = analysis.tamsd(x, lags, times=t)
    # the TAMSD averages more windows: smaller error than the ensemble MSD's
    np.testing.assert_allclose(tam, 2 * d * 0.5 * lags, rtol=5 * math.sqrt(2 / (d * N)))


def test_fft_and_direct_tamsd_agree():
    t, x = random_walk(T=257, N=40)
    lags = t[[1, 2, 7, 64, 200, 256]]
    fft = analysis.tamsd(x, lags, times=t, method="fft", per_particle=True)
    direct = analysis.tamsd(x, lags, times=t, method="direct", per_particle=True)
    np.testing.assert_allclose(fft, direct, rtol=1e-10)
    # in samples when no times are given
    np.testing.assert_allclose(analysis.tamsd(x, [1, 2, 7]), fft.mean(0)[:3], rtol=1e-12)


def test_direct_tamsd_on_log_spaced_samples():
    """Non-uniform sampling: only pairs exactly `lag` apart count.  Samples at 0, 1, 2, 4, 8:
    lag 1 has the pairs (0,1), (1,2); lag 4 has (0,4)... of a ballistic x = v t."""
    t = np.array([0.0, 1.0, 2.0, 4.0, 8.0])
    x = t[:, None, None] * np.array([[[2.0, 0.0]]])
    assert analysis.tamsd(x, [1.0, 4.0], times=t) == pytest.approx([4.0, 64.0])
    with pytest.raises(ValueError, match="uniformly spaced"):
        analysis.tamsd(x, [1.0], times=t, method="fft")
    with pytest.raises(ValueError, match="no pair"):
        analysis.tamsd(x, [5.0], times=t)


def test_diffusivity_of_a_straight_line_and_a_parabola():
    t = np.logspace(-2, 2, 40)
    np.testing.assert_allclose(analysis.diffusivity(t, 6 * 0.3 * t, dim=3), 0.3, rtol=1e-12)
    # forward/backward mean of t^2 on a non-uniform grid: (t_{i+1} + 2 t_i + t_{i-1}) / 2 / (2d)
    d = analysis.diffusivity(t, t**2, dim=2)
    expected = 0.5 * ((t[2:] + t[1:-1]) + (t[1:-1] + t[:-2])) / 4
    np.testing.assert_allclose(d[1:-1], expected, rtol=1e-12)
    slope, intercept, err = analysis.fit_slope(t, 3 * np.log(t) + 1, log=True)
    assert slope == pytest.approx(3) and intercept == pytest.approx(1) and err < 1e-10


def speed_std_standard_error(dim, T, n):
    """Sampling standard error of the standard deviation s of n independent
    Maxwell-Boltzmann speeds (a chi distribution with dim degrees of freedom, scale
    sqrt(T/m), m = 1), by the delta method: Var(s) = sigma^2 (kurtosis - 1) / (4 n), with
    the exact speed distribution's variance and kurtosis (for a normal variable this is
    the familiar sigma / sqrt(2n); the speed's kurtosis is different: 3.11 in 3D, 3.25 in
    2D)."""
    var, excess = stats.chi(dim, scale=math.sqrt(T)).stats(moments="vk")
    return math.sqrt(var * (excess + 2) / (4 * n))


def test_speed_statistics_of_maxwell_boltzmann_samples():
    """Velocities drawn from Maxwell-Boltzmann at T: the mean speed agrees with theory
    within 5 standard errors std(speed) / sqrt(N), the standard deviation of the speed
    within 5 of its exact sampling standard errors (``speed_std_standard_error``:
    0.16% relative in 3D, 0.17% in 2D for N = 2e5; a Monte Carlo of 4000 samples agrees
    to 2%)."""
    rng = np.random.default_rng(3)
    for dim in (2, 3):
        T, n = 0.8, 200_000
        v = rng.normal(scale=math.sqrt(T), size=(n, dim))
        st = analysis.speed_statistics(v, temperature=T)
        mb = theory.maxwell_boltzmann_moments(temperature=T, dim=dim)
        assert abs(st["mean"]["relative_error"]) < 5 * mb["std"] / math.sqrt(n) / mb["mean"]
        std_se = speed_std_standard_error(dim, T, n)
        assert abs(st["std"]["relative_error"]) < 5 * std_se / mb["std"]
        centres, dens, err = analysis.speed_histogram(v, bins=40, range=(0, 4))
        pdf = theory.maxwell_boltzmann_pdf(centres, temperature=T, dim=dim)
        # bin-centre evaluation of a curved density: the midpoint rule's error is
        # ~ w^2 f'' / 24, a few 1e-4 here; plus 5 Poisson sigma
        assert np.all(np.abs(dens - pdf) < 5 * err + 2e-3)
    assert analysis.temperature(v) == pytest.approx(T, rel=5 * math.sqrt(2 / (3 * n)))


def test_fit_haff_tau0_recovers_tau0():
    t = np.linspace(0, 50, 101)
    T = theory.haff_temperature(t, temperature0=1.3, tau0=2.5)
    tau0, err = analysis.fit_haff_tau0(t, T)
    assert tau0 == pytest.approx(2.5, rel=1e-12) and err < 1e-10


def test_ensemble_mean_error_scales_with_sqrt_m():
    rng = np.random.default_rng(4)
    for m in (10, 1000):
        mean, err = analysis.ensemble_mean(rng.normal(2.0, 3.0, size=(m, 200)))
        assert np.mean(err) == pytest.approx(3 / math.sqrt(m), rel=5 / math.sqrt(2 * (m - 1) * 200))
        assert abs(np.mean(mean) - 2.0) < 5 * 3 / math.sqrt(m * 200)


def test_bad_input():
    with pytest.raises(ValueError, match="shape \\(T, N, d\\)"):
        analysis.msd(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="strictly increasing"):
        analysis.tamsd(np.zeros((3, 2, 2)), [1.0], times=[0, 2, 1])
    with pytest.raises(ValueError, match="lags must be positive"):
        analysis.tamsd(np.zeros((3, 2, 2)), [5])
    with pytest.raises(ValueError, match="at least two runs"):
        analysis.ensemble_mean(np.zeros((1, 3)))


def test_msd_and_tamsd_of_chosen_particles():
    """A tracer among a gas: each particle moves ballistically with its own velocity, so
    the MSD and TAMSD of a selection are exactly the mean v^2 t^2 of the selection."""
    rng = np.random.default_rng(3)
    v = rng.normal(size=(30, 2))
    v[4] *= 10.0  # the fast tracer
    t = np.linspace(0.0, 5.0, 51)
    x = rng.random((1, 30, 2)) + t[:, None, None] * v[None]
    v2 = np.sum(v * v, axis=1)
    np.testing.assert_allclose(analysis.msd(x, particles=[4]), v2[4] * t**2, rtol=1e-12)
    mask = np.zeros(30, dtype=bool)
    mask[[1, 4, 9]] = True
    np.testing.assert_allclose(analysis.msd(x, particles=mask), v2[mask].mean() * t**2, rtol=1e-12)
    np.testing.assert_allclose(
        analysis.msd(x, per_dimension=True, particles=[4]), v[4] ** 2 * t[:, None] ** 2, rtol=1e-12
    )
    lags = np.array([0.1, 1.0, 4.0])
    np.testing.assert_allclose(
        analysis.tamsd(x, lags, times=t, particles=[4]), v2[4] * lags**2, rtol=1e-9
    )
    np.testing.assert_allclose(
        analysis.tamsd(x, lags, times=t, particles=mask), v2[mask].mean() * lags**2, rtol=1e-9
    )
    with pytest.raises(ValueError, match="one entry per particle"):
        analysis.msd(x, particles=mask[:10])
    with pytest.raises(IndexError, match=r"outside 0\.\.29"):
        analysis.tamsd(x, lags, times=t, particles=[30])
    with pytest.raises(ValueError, match="selects no particle"):
        analysis.msd(x, particles=np.zeros(30, dtype=bool))


def test_tamsd_lags_in_samples_and_a_lag_off_the_grid_named():
    t, x = random_walk(T=101, N=20, dt=0.25)
    in_time = analysis.tamsd(x, [0.25, 2.5, 25.0], times=t)
    np.testing.assert_allclose(
        analysis.tamsd(x, times=t, lag_samples=[1, 10, 100]), in_time, rtol=1e-12
    )
    with pytest.raises(
        ValueError,
        match=r"lag 0\.3 is not a multiple of the sample spacing "
        r"0\.25; the nearest lags that are: 0\.25 and 0\.5",
    ):
        analysis.tamsd(x, [0.3], times=t)
    with pytest.raises(TypeError, match="exactly one of lags"):
        analysis.tamsd(x, [0.25], times=t, lag_samples=[1])
    with pytest.raises(TypeError, match="exactly one of lags"):
        analysis.tamsd(x, times=t)
    with pytest.raises(ValueError, match="between 1 and 100"):
        analysis.tamsd(x, times=t, lag_samples=[0, 101])
    with pytest.raises(ValueError, match="whole numbers"):
        analysis.tamsd(x, times=t, lag_samples=[1.5])


def test_a_lag_no_pair_of_log_spaced_samples_has_names_the_nearest_and_the_way_out():
    """Log-spaced samples have few exact lags: a lag none of their pairs has is refused
    with the nearest lags the samples do have (below and above, found by brute force here)
    and the two ways to get it (uniform samples, or t and t + lag among them)."""
    t = np.array([0.0, 0.1, 0.3, 0.7, 1.5, 3.1])
    x = np.random.default_rng(0).normal(size=(len(t), 4, 2))
    with pytest.raises(ValueError) as info:
        analysis.tamsd(x, [1.0], times=t)
    msg = str(info.value)
    diffs = (t[None, :] - t[:, None]).ravel()
    below, above = diffs[diffs < 1.0].max(), diffs[diffs > 1.0].min()  # 0.8 and 1.2
    assert f"nearest lags these samples have are {below:.12g} and {above:.12g}" in msg
    assert "uniformly spaced" in msg and "t + 1 among the sample times" in msg
    # a lag below the shortest difference has only a nearest above
    with pytest.raises(ValueError, match=r"samples have are 0\.1\.  For a lag of 0\.05"):
        analysis.tamsd(x, [0.05], times=t)


def test_fit_power_law_recovers_an_exact_power_law():
    """MSD = 0.7 t^(1/6) (a viscoelastic gas' late MSD) sampled at log-spaced times: the
    exponent and prefactor to rounding, a standard error of zero to rounding; the window
    picks its samples, t = 0 outside it is ignored."""
    t = np.concatenate([[0.0], np.logspace(-2, 3, 51)])
    msd = 0.7 * t ** (1 / 6)
    exponent, prefactor, err = analysis.fit_power_law(t[1:], msd[1:])
    assert exponent == pytest.approx(1 / 6, rel=1e-12)
    assert prefactor == pytest.approx(0.7, rel=1e-12)
    assert err < 1e-12
    # a ballistic start and a diffusive end: each window sees its own exponent
    bent = np.where(t < 1.0, t**2, t)
    assert analysis.fit_power_law(t, bent, t_min=1e-2, t_max=0.9)[0] == pytest.approx(2, rel=1e-12)
    assert analysis.fit_power_law(t, bent, t_min=1.0)[0] == pytest.approx(1, rel=1e-12)


def test_fit_power_law_on_noisy_data_and_its_standard_error():
    """values = 2 t^0.5 exp(sigma eps), eps independent N(0, 1), sigma = 0.05, at 30
    log-spaced times: ordinary least squares on the logarithms, whose exponent error is
    exactly sigma / sqrt(sum (ln t - mean)^2) = s_a.  Over M = 400 data sets:
    - the mean fitted exponent is within 5 s_a / sqrt(M) of 0.5 (unbiased);
    - the spread of the fitted exponents is s_a to within 5 times the relative sampling
      error of a standard deviation from M values, 1 / sqrt(2 (M - 1)) = 3.5 %, so 18 %;
    - the mean reported standard error is s_a to 5 %: each is s_a times a chi variable
      with 28 degrees of freedom over sqrt(28), mean 0.991 (c4) and relative spread
      0.134, so the mean of 400 sits 0.9 % low with a 0.7 % standard error.
    - the median prefactor is 2 to 0.5 %: each fit's ln(prefactor) has the standard error
      sigma sqrt(1/30 + mean(ln t)^2 / sum (ln t - mean)^2) = 1.05 %, so the median of
      400 (1.25 / sqrt(400) of that, 0.066 %) is five of its errors inside 0.5 % (0.33 %).
    One data set alone lies within 4 reported standard errors of 0.5 (a Student t with
    28 degrees of freedom exceeds 4 with probability 4e-4)."""
    rng = np.random.default_rng(12)
    sigma, M = 0.05, 400
    t = np.logspace(-1, 2, 30)
    lt = np.log(t)
    s_a = sigma / math.sqrt(np.sum((lt - lt.mean()) ** 2))
    fits = np.array(
        [
            analysis.fit_power_law(t, 2 * np.sqrt(t) * np.exp(sigma * rng.normal(size=t.size)))
            for _ in range(M)
        ]
    )
    exponents, prefactors, errors = fits.T
    assert abs(exponents.mean() - 0.5) < 5 * s_a / math.sqrt(M)
    assert exponents.std(ddof=1) == pytest.approx(s_a, rel=0.18)
    assert errors.mean() == pytest.approx(s_a, rel=0.05)
    assert abs(exponents[0] - 0.5) < 4 * errors[0]
    assert np.median(prefactors) == pytest.approx(2, rel=0.005)


def test_fits_refuse_what_has_no_logarithm():
    """ln t of t = 0 would reach the least squares as -inf (LAPACK then printed errors and
    raised LinAlgError): both log fits refuse it by name, saying to start the window later."""
    t = np.linspace(0.0, 10.0, 11)
    with pytest.raises(ValueError, match=r"ln t needs t > 0 in the window, got t = 0 .*t_min > 0"):
        analysis.fit_slope(t, np.log1p(t), log=True)
    with pytest.raises(ValueError, match=r"ln t needs t > 0 .*t_min > 0"):
        analysis.fit_power_law(t, t**2)
    with pytest.raises(ValueError, match=r"ln values needs values > 0 .*got values = -1 at t = 3"):
        analysis.fit_power_law(t, np.where(t == 3, -1.0, t), t_min=1.0)
    with pytest.raises(ValueError, match=r"at least three points in .* got 2"):
        analysis.fit_power_law(t, t, t_min=1.0, t_max=2.0)
    with pytest.raises(ValueError, match="one length"):
        analysis.fit_power_law(t, t[1:])
