"""granular.moments: kurtosis, a2 and the speed tail of sampled velocities, with block and
run errors.  Known distributions first (a Maxwellian: a2 = 0; a scale mixture of
Gaussians: a2 = <s^4>/<s^2>^2 - 1), then an elastic EDMD gas, whose a2 must be 0 within its
error (and its finite-N value -2/(d(N-1)+2), well inside that error)."""

import math

import numpy as np
import pytest

from granular import Scene, Simulation, moments


def test_a_maxwellian_has_a2_zero_within_its_error():
    rng = np.random.default_rng(3)
    v = rng.normal(size=(40, 2000, 3))
    est = moments.velocity_moments(v, blocks=8)
    assert est.method == "blocks" and est.blocks == 8 and est.dim == 3
    assert abs(est.a2) < 5 * est.a2_error
    assert abs(est.kurtosis - 15 / 9) < 5 * est.kurtosis_error
    # the error is that of 80 000 independent speeds: Var(a2) ~ 8 / (d (d+2) n) in 3D ...
    assert est.a2_error == pytest.approx(math.sqrt(8 / (15 * v.shape[0] * v.shape[1])), rel=0.6)


def test_a_scale_mixture_has_its_a2():
    """Gaussian velocities times a random scale s with s^2 = 0.5 or 1.5: a2 =
    <s^4>/<s^2>^2 - 1 = 0.25 (in any d), within 5 sigma; independent runs give it too."""
    rng = np.random.default_rng(4)
    s = np.sqrt(rng.choice([0.5, 1.5], size=(30, 1000, 1)))
    v = rng.normal(size=(30, 1000, 2)) * s
    est = moments.velocity_moments(v, blocks=10)
    assert abs(est.a2 - 0.25) < 5 * est.a2_error and est.a2_error < 0.02
    runs = moments.velocity_moments([v[:10], v[10:20], v[20:]])
    assert runs.method == "runs" and abs(runs.a2 - 0.25) < 5 * runs.a2_error
    assert moments.sonine_a2(v) == pytest.approx(est.a2)
    assert moments.kurtosis(v[0]) == pytest.approx(2 * (1 + moments.sonine_a2(v[0])))


def test_an_elastic_gas_has_a2_zero():
    """An elastic gas (N = 400 disks, packing 0.2, equilibrated) sampled every collision
    time over 400 of them, cut into 10 blocks of 40: a2 within 5 sigma of 0 and of the
    microcanonical -2/(d(N-1)+2) = -0.0025 (their difference is below the error here)."""
    s = Scene.random(400, 0.0126, dim=2, temperature=1.0, seed=7)
    sim = Simulation(s)
    sim.run(stop_when={"collisions_per_particle": 20}, store=())
    t0, per = sim.time, sim.time / 20
    tr = sim.run(t_stop=t0 + 400 * per, sample_times=t0 + per * np.arange(1, 401))
    est = moments.velocity_moments(tr, blocks=10)
    micro = moments.microcanonical_a2(400, 2)
    assert abs(est.a2) < 5 * est.a2_error
    assert abs(est.a2 - micro) < 5 * est.a2_error
    assert est.a2_error < 0.01


def test_the_tail_of_a_maxwellian():
    """Fitting c^(d-1) exp(-A c^2) to Maxwellian speeds gives A = 1 within 5 sigma, and the
    measured density follows the Maxwellian one."""
    v = np.random.default_rng(5).normal(size=(20, 5000, 3))
    tail = moments.speed_tail(v, exponent=2.0, c_min=1.0, c_max=3.0, bins=30)
    assert abs(tail.rate - 1.0) < 5 * tail.rate_error
    assert np.allclose(tail.density, tail.maxwell, atol=0.02)


def test_bad_input_is_refused():
    v = np.zeros((5, 10, 3))
    with pytest.raises(ValueError, match="at rest"):
        moments.sonine_a2(v)
    with pytest.raises(ValueError, match="blocks must be an integer from 2"):
        moments.velocity_moments(np.ones((5, 10, 3)), blocks=6)
    with pytest.raises(ValueError, match="shape"):
        moments.kurtosis(np.ones((10, 4)))
    with pytest.raises(ValueError, match="NaN"):
        moments.kurtosis(np.full((10, 3), np.nan))
    with pytest.raises(ValueError, match="at least 2 independent runs"):
        moments.velocity_moments([np.ones((2, 10, 3))])
    with pytest.raises(ValueError, match="too few speeds"):
        moments.speed_tail(np.random.default_rng(1).normal(size=(20, 2)), c_min=3.0)


def test_each_sample_undoes_a_cooling_gas_temperature():
    """Maxwellian samples at temperatures falling by 100x pooled: a scale mixture with a2
    far above 0; scaled each to its own temperature (each_sample) a2 is 0 within 5 sigma
    (the shell's -2/(d(N-1)+2) taken out)."""
    rng = np.random.default_rng(6)
    scale = np.geomspace(1.0, 0.1, 30)[:, None, None]
    v = rng.normal(size=(30, 500, 3)) * scale
    assert moments.sonine_a2(v) > 0.3
    est = moments.velocity_moments(v, blocks=10, each_sample=True)
    assert abs(est.a2) < 5 * est.a2_error
    assert moments.sonine_a2(v, each_sample=True) == pytest.approx(est.a2)
