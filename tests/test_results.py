"""One verb for an MSD: ``msd()`` and ``tamsd()`` take the same arguments and give the same
shapes on a Trajectory (EDMD), a LangevinResult and an EnsembleResult, agree with each
other where they measure the same thing, and refuse by name what cannot apply."""

import dataclasses
import functools

import numpy as np
import pytest

import granular
from granular import analysis, langevin
from granular.ensemble import RunFailure

N, DIM, T = 20, 3, 41  # particles, dimensions, samples (uniform: every step)
DT = 0.01
LAG_STEPS = [1, 3, 10]  # the engine's TAMSD over every window (tamsd_estimator="all")
LAGS = [k * DT for k in LAG_STEPS]


@pytest.fixture(scope="module")
def traj():
    scene = granular.Scene.random(N, 0.03, dim=DIM, restitution=0.9, seed=1)
    return granular.Simulation(scene).run(
        t_stop=0.4, sample_times=np.linspace(0, 0.4, T), store=("positions",)
    )


def _langevin(seed=None, store_positions=True):
    return langevin.run(
        N,
        gamma0=9.26,
        D0=0.072,
        dt=DT,
        t_stop=(T - 1) * DT,
        dim=DIM,
        sample_times=np.arange(T) * DT,
        tamsd_lags=LAGS,
        tamsd_estimator="all",
        store_positions=store_positions,
        seed=seed,
    )


@pytest.fixture(scope="module")
def sde():
    return _langevin(seed=2)


@pytest.fixture(scope="module")
def ens():
    return granular.ensemble(_langevin, 3, seed=3, backend="serial", progress=False)


@pytest.fixture(scope="module")
def edmd_ens():
    scene = granular.Scene.random(N, 0.03, dim=DIM, seed=4)
    return granular.ensemble(
        scene,
        2,
        seed=5,
        backend="serial",
        progress=False,
        t_stop=0.4,
        sample_times=np.linspace(0, 0.4, T),
        quantities=("msd", "msd_per_dimension"),
    )


def test_msd_has_the_same_shapes_on_all_three(traj, sde, ens, edmd_ens):
    for result in (traj, sde, ens, edmd_ens):
        assert result.msd().shape == (T,)
        assert result.msd(per_dimension=True).shape == (T, DIM)
        np.testing.assert_allclose(result.msd(per_dimension=True).sum(1), result.msd(), rtol=1e-12)
    for result in (traj, sde):
        assert result.msd(particles=[0, 4]).shape == (T,)
        assert result.msd(per_dimension=True, particles=[0, 4]).shape == (T, DIM)


def test_tamsd_has_the_same_shapes_on_all_three(traj, sde, ens):
    L = len(LAGS)
    for result in (traj, sde, ens):
        assert result.tamsd(LAGS).shape == (L,)
        assert result.tamsd(lag_samples=LAG_STEPS[1:]).shape == (L - 1,)
        np.testing.assert_allclose(
            result.tamsd(lag_samples=LAG_STEPS), result.tamsd(LAGS), rtol=1e-12
        )
    for result in (traj, sde):
        assert result.tamsd(LAGS, per_particle=True).shape == (N, L)
        assert result.tamsd(LAGS, particles=[1, 2]).shape == (L,)
        assert result.tamsd(LAGS, particles=[1, 2], per_particle=True).shape == (2, L)
    # the engine's results default to the lags they accumulated
    assert sde.tamsd().shape == ens.tamsd().shape == (L,)


def test_the_engine_tamsd_is_the_trajectory_tamsd_of_its_positions(sde):
    """With tamsd_estimator="all" the engine averages over a window at every step: exactly
    what ``analysis.tamsd`` does with the positions at every step (to rounding: other
    sums)."""
    direct = analysis.tamsd(
        sde.positions, lag_samples=LAG_STEPS, method="direct", per_particle=True
    )
    np.testing.assert_allclose(sde.tamsd(per_particle=True), direct, rtol=1e-12)
    np.testing.assert_allclose(sde.tamsd(LAGS, particles=[3]), direct[3], rtol=1e-12)


def test_particle_choices_agree(traj, sde):
    mask = np.zeros(N, dtype=bool)
    mask[[2, 5]] = True
    for result in (traj, sde):
        np.testing.assert_array_equal(result.msd(particles=mask), result.msd(particles=[2, 5]))
    # all particles from the stored positions: the accumulated MSD, to rounding
    np.testing.assert_allclose(sde.msd(particles=np.arange(N)), sde.msd(), rtol=1e-12)
    np.testing.assert_allclose(
        sde.msd(particles=[7]), (sde.positions[:, 7] ** 2).sum(1), rtol=1e-15
    )
    np.testing.assert_allclose(
        traj.msd(particles=[7]),
        ((traj.positions[:, 7] - traj.positions[0, 7]) ** 2).sum(1),
        rtol=1e-12,
    )


def test_the_ensemble_verbs_are_the_means_of_the_runs(ens):
    stacked = np.array([r["msd"] for r in ens.runs])
    np.testing.assert_allclose(ens.msd(), stacked.mean(0), rtol=1e-13)
    tamsd = np.array([r["tamsd"] for r in ens.runs])
    np.testing.assert_allclose(ens.tamsd(), tamsd.mean(0), rtol=1e-13)
    np.testing.assert_array_equal(ens.tamsd([LAGS[2]]), ens.tamsd()[[2]])
    np.testing.assert_array_equal(ens.tamsd_lags, LAGS)


def test_what_cannot_apply_is_refused_by_name(sde, ens, edmd_ens):
    with pytest.raises(ValueError, match="not accumulated"):
        sde.tamsd([0.05])  # a whole number of steps, but not one of tamsd_lags
    with pytest.raises(ValueError, match="not accumulated"):
        ens.tamsd(lag_samples=[2])
    with pytest.raises(ValueError, match="not accumulated"):
        sde.tamsd([0.0105])  # not a whole number of steps
    # the lags on either side of the one asked for, in its unit
    with pytest.raises(ValueError, match=r"nearest of those: 0\.03 and 0\.1 \(all: \[0\.01, "):
        sde.tamsd([0.05])
    with pytest.raises(ValueError, match=r"nearest of those: 3 and 10 steps"):
        ens.tamsd(lag_samples=[4])
    with pytest.raises(TypeError, match="at most one"):
        sde.tamsd(LAGS, lag_samples=LAG_STEPS)
    with pytest.raises(ValueError, match="store_positions=True"):
        _langevin(seed=1, store_positions=False).msd(particles=[0])
    with pytest.raises(TypeError, match="particles= cannot apply"):
        ens.msd(particles=[0])
    with pytest.raises(TypeError, match="cannot apply"):
        ens.tamsd(per_particle=True)
    with pytest.raises(ValueError, match="collected no 'tamsd'"):
        edmd_ens.tamsd(LAGS)
    lean = granular.ensemble(
        granular.Scene.random(N, 0.03, seed=4),
        1,
        seed=5,
        backend="serial",
        progress=False,
        t_stop=0.1,
        quantities=("msd",),
    )
    with pytest.raises(ValueError, match="msd_per_dimension"):
        lean.msd(per_dimension=True)


def test_the_old_array_attributes_still_work_with_a_deprecation(sde):
    with pytest.warns(DeprecationWarning, match=r"call result\.msd\(\)"):
        last = sde.msd[-1]
    assert last == sde.msd()[-1]
    with pytest.warns(DeprecationWarning, match=r"result\.tamsd\(\)"):
        doubled = sde.tamsd * 2
    assert type(doubled) is np.ndarray
    np.testing.assert_array_equal(doubled, 2 * sde.tamsd())
    with pytest.warns(DeprecationWarning):
        assert np.max(sde.msd) == np.max(sde.msd())
    # an ensemble of Langevin runs collects them under their old names
    assert set(langevin.LangevinResult.arrays(sde)) >= {"msd", "tamsd", "tamsd_lags", "v2"}


def test_results_are_frozen_dataclasses(sde, ens):
    for result in (sde, ens):
        assert dataclasses.is_dataclass(result)
        with pytest.raises(dataclasses.FrozenInstanceError):
            result.count = 0
    failure = RunFailure(
        1, {"entropy": 5, "spawn_key": (1,)}, "ValueError('x')", "tb", "ValueError"
    )
    assert failure.error_type == "ValueError" and "run 1" in repr(failure)


def test_a_failed_run_names_its_error_type():
    # a sweep whose other point succeeds: a call whose every run fails raises instead
    good = functools.partial(langevin.run, 1, gamma0=1.0, D0=1.0, dt=0.5, t_stop=1.0)
    with pytest.warns(RuntimeWarning, match="point 1: every one of its 1 runs failed"):
        _, res = granular.ensemble(
            [good, functools.partial(good, dt=-1.0)], 1, backend="serial", progress=False
        )
    (failure,) = res.failures
    assert failure.error_type == "ValueError" and "dt must be positive" in failure.error
