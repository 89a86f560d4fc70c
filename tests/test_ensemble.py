"""Ensembles: identical results on every backend, independent runs, 1/sqrt(K) errors,
failures reported without losing the other runs."""
import functools
import math

import numpy as np
import pytest

import granular
from granular import Scene

import ensemble_tasks

RUN = dict(t_stop=1.0, sample_times=np.linspace(0.0, 1.0, 6))


@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def test_same_seed_same_results_on_every_backend(dask_client):
    kw = dict(runs=4, seed=7, quantities=("temperature", "collisions_per_particle"), **RUN)
    serial = granular.ensemble(ensemble_tasks.small_gas, backend="serial", **kw)
    for backend in ("processes", "threads", dask_client):
        other = granular.ensemble(ensemble_tasks.small_gas, backend=backend, workers=2, **kw)
        assert other.count == 4
        for a, b in zip(serial.runs, other.runs):
            for k in a:
                np.testing.assert_array_equal(a[k], b[k])
        for k in serial.mean:
            np.testing.assert_array_equal(serial.mean[k], other.mean[k])
            np.testing.assert_array_equal(serial.error[k], other.error[k])
    np.testing.assert_array_equal(serial.times, RUN["sample_times"])


def test_runs_are_distinct_and_scene_runs_shuffle_velocities():
    scene = Scene.random(200, 0.03, restitution=0.8, seed=1)
    res = granular.ensemble(scene, 3, seed=2, backend="serial",
                            quantities=("temperature", "pair_collisions"), **RUN)
    counts = [r["pair_collisions"][-1] for r in res.runs]
    assert len(set(counts)) == 3
    # velocity shuffling keeps the energy: T(0) equal in every run
    t0 = [r["temperature"][0] for r in res.runs]
    assert np.ptp(t0) < 1e-14 * t0[0]
    res = granular.ensemble(functools.partial(Scene.random, 200, 0.03), 3, seed=2,
                            backend="serial", quantities=("temperature",), **RUN)
    assert len({r["temperature"][0] for r in res.runs}) == 3


def test_error_shrinks_like_one_over_sqrt_k():
    """Standard normal data: the standard error of the mean is 1/sqrt(K).  Averaged over 50
    independent quantities, error * sqrt(K) = 1 within the scatter of a sample standard
    deviation, 1 / sqrt(2 (K - 1) * 50), times 5."""
    for k in (10, 40, 160):
        res = granular.ensemble(ensemble_tasks.gaussian, k, seed=k, backend="serial")
        ratio = np.mean(res.error["x"]) * math.sqrt(k)
        assert abs(ratio - 1) < 5 / math.sqrt(2 * (k - 1) * 50)
        assert abs(np.mean(res.mean["x"])) < 5 / math.sqrt(k * 50)


def test_failing_run_is_reported_and_the_others_returned():
    res = granular.ensemble(ensemble_tasks.fails_for_run_2, 5, seed=3, backend="processes",
                            workers=2)
    assert res.count == 4 and len(res.runs) == 4
    (fail,) = res.failures
    assert fail.index == 2 and fail.seed["spawn_key"] == (2,)
    assert "InelasticCollapseError" in fail.error and "collapse in run 2" in fail.traceback


def test_reducing_as_runs_arrive_gives_the_same_means():
    kw = dict(runs=6, seed=5, backend="serial")
    full = granular.ensemble(ensemble_tasks.gaussian, **kw)
    lean = granular.ensemble(ensemble_tasks.gaussian, keep_runs=False, **kw)
    assert lean.runs == []
    np.testing.assert_allclose(lean.mean["x"], full.mean["x"], rtol=1e-14)
    stacked = np.array([r["x"] for r in full.runs])
    np.testing.assert_allclose(full.mean["x"], stacked.mean(0), rtol=1e-13)
    np.testing.assert_allclose(full.error["x"], stacked.std(0, ddof=1) / math.sqrt(6), rtol=1e-12)


def test_bad_arguments():
    with pytest.raises(ValueError, match="runs must be"):
        granular.ensemble(ensemble_tasks.gaussian, 0)
    with pytest.raises(TypeError, match="Scene or a function"):
        granular.ensemble(42, 2)
    with pytest.raises(ValueError, match="unknown quantities"):
        granular.ensemble(ensemble_tasks.small_gas, 2, quantities=("colour",), **RUN)
    with pytest.raises(ValueError, match="backend must be"):
        granular.ensemble(ensemble_tasks.gaussian, 2, backend="gpu")
    res = granular.ensemble(ensemble_tasks.gaussian, 2, backend="serial", t_stop=1.0)
    assert res.count == 0 and "apply to EDMD scenes only" in res.failures[0].error
