"""Ensembles: identical results on every backend, independent runs, 1/sqrt(K) errors,
failures reported without losing the other runs, sweeps in one call, bounded memory."""

import functools
import math
import os
import signal
import subprocess
import sys
import time
import weakref

import numpy as np
import pytest

import granular
from granular import Scene

from helpers import ensemble_tasks

RUN = dict(t_stop=1.0, sample_times=np.linspace(0.0, 1.0, 6))


@pytest.fixture(scope="module")
def dask_client():
    """Worker processes, so that tasks and results really travel pickled through Dask."""
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        yield client


class CountingClient:
    """A Dask client that records how many of the futures it handed out are alive at once
    (a live future keeps its result on the cluster)."""

    def __init__(self, client):
        self._client = client
        self._live = weakref.WeakSet()
        self.peak = 0

    def submit(self, *args, **kwargs):
        future = self._client.submit(*args, **kwargs)
        self._live.add(future)
        self.peak = max(self.peak, len(self._live))
        return future

    def __getattr__(self, name):
        return getattr(self._client, name)


def _assert_identical(x, y):
    """Two EnsembleResults agree bit for bit: every run's arrays, the means and errors."""
    assert len(x.runs) == len(y.runs) and x.mean.keys() == y.mean.keys()
    for a, b in zip(x.runs, y.runs, strict=True):
        assert a.keys() == b.keys()
        for k in a:
            np.testing.assert_array_equal(a[k], b[k])
    for k in x.mean:
        np.testing.assert_array_equal(x.mean[k], y.mean[k])
        np.testing.assert_array_equal(x.error[k], y.error[k])


def test_same_seed_same_results_on_every_backend(dask_client):
    kw = dict(runs=4, seed=7, quantities=("temperature", "collisions_per_particle"), **RUN)
    serial = granular.ensemble(ensemble_tasks.small_gas, backend="serial", **kw)
    for backend in ("processes", "threads", dask_client):
        other = granular.ensemble(ensemble_tasks.small_gas, backend=backend, workers=2, **kw)
        assert other.count == 4
        _assert_identical(serial, other)
    np.testing.assert_array_equal(serial.times, RUN["sample_times"])


def test_runs_are_distinct_and_scene_runs_shuffle_velocities():
    scene = Scene.random(200, 0.03, restitution=0.8, seed=1)
    res = granular.ensemble(
        scene, 3, seed=2, backend="serial", quantities=("temperature", "pair_collisions"), **RUN
    )
    counts = [r["pair_collisions"][-1] for r in res.runs]
    assert len(set(counts)) == 3
    # velocity shuffling keeps the energy: T(0) equal in every run
    t0 = [r["temperature"][0] for r in res.runs]
    assert np.ptp(t0) < 1e-14 * t0[0]
    res = granular.ensemble(
        functools.partial(Scene.random, 200, 0.03),
        3,
        seed=2,
        backend="serial",
        quantities=("temperature",),
        **RUN,
    )
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
    res = granular.ensemble(
        ensemble_tasks.fails_for_run_2, 5, seed=3, backend="processes", workers=2
    )
    assert res.count == 4 and len(res.runs) == 4
    (fail,) = res.failures
    assert fail.index == 2 and fail.seed["spawn_key"] == (2,)
    assert "InelasticCollapseError" in fail.error and "collapse in run 2" in fail.traceback


def test_run_r_uses_child_r_of_the_seed():
    res = granular.ensemble(ensemble_tasks.gaussian, 3, seed=5, backend="serial")
    for run, child in zip(res.runs, np.random.SeedSequence(5).spawn(3), strict=True):
        np.testing.assert_array_equal(run["x"], ensemble_tasks.gaussian(child)["x"])


def test_a_sweep_gives_each_point_as_run_alone_with_its_child_seed():
    points = [
        Scene.random(100, 0.03, restitution=1.0, seed=1),
        functools.partial(Scene.random, 100, 0.03, restitution=0.8),
    ]
    kw = dict(quantities=("temperature", "pair_collisions"), **RUN)
    sweep = granular.ensemble(points, 3, seed=11, backend="processes", workers=2, **kw)
    assert isinstance(sweep, list) and len(sweep) == 2
    for point, child, res in zip(points, np.random.SeedSequence(11).spawn(2), sweep, strict=True):
        alone = granular.ensemble(point, 3, seed=child, backend="serial", **kw)
        assert res.count == alone.count == 3 and not res.failures
        _assert_identical(alone, res)
    elastic, inelastic = (res.mean["temperature"] for res in sweep)
    np.testing.assert_allclose(elastic, elastic[0], rtol=1e-9)
    assert inelastic[-1] < 0.99 * inelastic[0]


def test_a_sweep_reports_failures_per_point_with_their_seeds():
    ok, failing = granular.ensemble(
        [ensemble_tasks.gaussian, ensemble_tasks.fails_for_run_2],
        4,
        seed=3,
        backend="threads",
        workers=2,
    )
    assert ok.count == 4 and not ok.failures
    (fail,) = failing.failures
    assert failing.count == 3 and fail.index == 2 and fail.seed["spawn_key"] == (1, 2)


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
    with pytest.raises(TypeError, match="a Scene, a function of seed"):
        granular.ensemble(42, 2)
    with pytest.raises(TypeError, match="a Scene, a function of seed"):
        granular.ensemble([ensemble_tasks.gaussian, 42], 2)
    with pytest.raises(ValueError, match="at least one model"):
        granular.ensemble([], 2)
    with pytest.raises(ValueError, match="unknown quantities"):
        granular.ensemble(ensemble_tasks.small_gas, 2, quantities=("colour",), **RUN)
    with pytest.raises(ValueError, match="backend must be"):
        granular.ensemble(ensemble_tasks.gaussian, 2, backend="gpu")
    # run options for a model that returns no Scene fail every run alike: that error
    with pytest.raises(TypeError, match="apply to EDMD scenes only") as info:
        granular.ensemble(ensemble_tasks.gaussian, 2, backend="serial", t_stop=1.0)
    assert "every one of this ensemble's 2 runs failed with TypeError" in "".join(
        getattr(info.value, "__notes__", [])
    )


def test_finished_runs_are_not_kept_when_only_means_are_asked_for():
    """40 runs on 2 threads: submitting them all at once keeps most of the 40 results alive
    (in their futures, or waiting for an earlier run to be reduced).  The window, 2 per
    worker, lets at most 4 runs be submitted and not yet reduced; the last one reduced is
    referenced until the next result arrives: 5 at most."""
    ensemble_tasks.reset_tracking()
    lean = granular.ensemble(
        ensemble_tasks.tracked_result, 40, seed=9, backend="threads", workers=2, keep_runs=False
    )
    assert lean.runs == [] and lean.count == 40
    assert ensemble_tasks.peak_live_results <= 4 + 1
    serial = granular.ensemble(ensemble_tasks.tracked_result, 40, seed=9, backend="serial")
    np.testing.assert_array_equal(lean.mean["x"], serial.mean["x"])
    np.testing.assert_array_equal(lean.error["x"], serial.error["x"])


def test_dask_submission_is_windowed(dask_client):
    """2 worker threads: at most 2 x 2 futures alive at once, never all 24 of the sweep."""
    client = CountingClient(dask_client)
    models = [ensemble_tasks.gaussian, ensemble_tasks.gaussian]
    lean = granular.ensemble(models, 12, seed=4, backend=client, keep_runs=False)
    assert 1 < client.peak <= 4
    serial = granular.ensemble(models, 12, seed=4, backend="serial")
    for a, b in zip(lean, serial, strict=True):
        assert a.runs == [] and a.count == 12
        np.testing.assert_array_equal(a.mean["x"], b.mean["x"])
        np.testing.assert_array_equal(a.error["x"], b.error["x"])


# Runs constant across the ensemble keep their value, inf included.


def test_langevin_ensemble_keeps_infinite_tau0():
    """The Langevin model has tau0 = inf in every run: the mean is inf with error 0, like any
    parameter equal in every run, while the MSD is the plain mean over runs."""
    model = functools.partial(
        granular.langevin.run, 20, gamma0=2.0, D0=0.5, dt=0.05, t_stop=2.0, model="langevin"
    )
    res = granular.ensemble(model, 4, seed=3, backend="serial")
    assert res.mean["tau0"] == math.inf and res.error["tau0"] == 0
    assert res.mean["gamma0"] == 2.0 and res.error["gamma0"] == 0
    msd = np.array([r["msd"] for r in res.runs])
    np.testing.assert_allclose(res.mean["msd"], msd.mean(0), rtol=1e-13)
    np.testing.assert_allclose(res.error["msd"], msd.std(0, ddof=1) / 2, rtol=1e-12)
    assert np.all(res.error["msd"][1:] > 0)


def test_reducer_with_infinite_and_varying_entries():
    """The running reduction equals numpy's mean and std(ddof=1)/sqrt(K) for varying
    entries (rtol 1e-13 / 1e-12: Welford against two-pass rounding), keeps constant entries
    exactly, +-inf included, with error 0, and gives error NaN for K = 1."""
    from granular.ensemble import _Accumulator

    rng = np.random.default_rng(0)
    k = 7
    runs = [
        {
            "v": rng.normal(size=5) * 1e3 + 1e6,
            "c": np.array([math.inf, -math.inf, 1.5, 0.0]),
            "tau0": math.inf,
        }
        for _ in range(k)
    ]
    acc = _Accumulator()
    for r in runs:
        acc.add(r)
    mean, error = acc.result()
    v = np.array([r["v"] for r in runs])
    np.testing.assert_allclose(mean["v"], v.mean(0), rtol=1e-13)
    np.testing.assert_allclose(error["v"], v.std(0, ddof=1) / math.sqrt(k), rtol=1e-12)
    np.testing.assert_array_equal(mean["c"], [math.inf, -math.inf, 1.5, 0.0])
    np.testing.assert_array_equal(error["c"], 0.0)
    assert mean["tau0"] == math.inf and error["tau0"] == 0
    one = _Accumulator()
    one.add(runs[0])
    assert math.isnan(one.result()[1]["tau0"]) and one.result()[0]["tau0"] == math.inf


# A script without `if __name__ == "__main__":`.  The process backend
# starts its workers with forkserver (Linux) or spawn, which re-run the main script: an
# unguarded ensemble call there broke the pool (BrokenProcessPool).  These tests run real
# scripts in a fresh interpreter, as a user would.

MODEL = """import functools
import granular

model = functools.partial(granular.langevin.run, 5, gamma0=1.0, D0=1.0, dt=0.1, t_stop=1.0)
"""


def run_script(tmp_path, text, *args):
    """Run ``text`` with the default process backend: (exit code, stdout, stderr).  The
    timeout makes a hang fail the test."""
    import subprocess
    import sys

    if not args:
        (tmp_path / "script.py").write_text(text)
        args = ("script.py",)
    done = subprocess.run(
        [sys.executable, *args], cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    return done.returncode, done.stdout, done.stderr


GUARD_TO_WRITE = 'if __name__ == "__main__":\n        result = granular.ensemble(...)'


@pytest.mark.parametrize(
    "call, line",
    [
        ("res = granular.ensemble(model, 4, seed=1, workers=2)\n", 6),
        (
            "def main():\n    return granular.ensemble(model, 4, seed=1, workers=2)\n\n\n"
            "res = main()\n",
            10,
        ),
    ],
)
def test_unguarded_script_gets_told_to_add_the_guard(tmp_path, call, line):
    """Called at top level, directly or through a function: the error names the script's
    line and shows the guard to write, before any worker starts."""
    code, out, err = run_script(tmp_path, MODEL + "\n" + call + 'print("count", res.count)\n')
    assert code == 1 and "count" not in out
    assert "ProcessBackendError" in err and "BrokenProcessPool" not in err
    assert f'script.py, line {line}, outside an `if __name__ == "__main__":` block' in err
    assert GUARD_TO_WRITE in err


def test_guarded_scripts_and_scripts_without_a_file_run(tmp_path):
    """No false alarm: under the guard (directly or in a function), the reversed test,
    and ``python -c`` (no script to re-run, as in a notebook) all run."""
    for body in (
        'if __name__ == "__main__":\n    res = granular.ensemble(model, 4, seed=1, workers=2)\n'
        '    print("count", res.count)\n',
        "def main():\n    res = granular.ensemble(model, 4, seed=1, workers=2)\n"
        '    print("count", res.count)\n\n\nif "__main__" == __name__:\n    main()\n',
        'if __name__ != "__main__":\n    pass\nelse:\n'
        '    print("count", granular.ensemble(model, 4, seed=1, workers=2).count)\n',
    ):
        code, out, err = run_script(tmp_path, MODEL + "\n" + body)
        assert (code, out) == (0, "count 4\n"), err
    code, out, err = run_script(
        tmp_path,
        None,
        "-c",
        MODEL + "\nres = granular.ensemble("
        "model, 4, seed=1, workers=2)\nprint('count', res.count)\n",
    )
    assert (code, out) == (0, "count 4\n"), err


def _kills_its_worker(seed):
    import os

    os._exit(3)


def test_a_dead_worker_gets_the_same_advice():
    """Any BrokenProcessPool (here a worker that exits mid-run) becomes a
    ProcessBackendError that shows the guard, and says what else kills a worker."""
    from granular import ProcessBackendError

    with pytest.raises(ProcessBackendError, match="died") as info:
        granular.ensemble(_kills_its_worker, 2, seed=1, workers=2)
    assert GUARD_TO_WRITE in str(info.value) and 'backend="serial"' in str(info.value)
    assert isinstance(info.value, granular.GranularError)


# A caller's mistake is an exception before any run starts, not K failed runs.

CALLED = []


def _counting_gas(seed):
    CALLED.append(seed)
    return Scene.random(20, 0.02, dim=2, seed=seed)


SCENE = Scene.random(20, 0.02, dim=2, seed=1)


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        (dict(t_stop=1.0, sample_times=np.linspace(1, 0, 5)), ValueError, "strictly increasing"),
        (dict(sample_times=np.linspace(0, 1, 5)), ValueError, "finite t_stop or a stop_when"),
        (dict(t_stop=1.0, sample_times=np.linspace(0, 2, 5)), ValueError, "past t_stop = 1"),
        (dict(t_stop=1.0, sample_times=[-1.0, 0.5]), ValueError, "before t = 0"),
        (dict(t_stop=1.0, sample_times=[[0.0, 0.5]]), ValueError, "one-dimensional"),
        (dict(t_stop=1.0, sample_times=[0.0, np.nan]), ValueError, "finite"),
        (dict(t_stop=float("nan")), ValueError, "t_stop must be a time >= 0"),
        (dict(t_stop=-1.0), ValueError, "t_stop must be a time >= 0"),
        (dict(t_stop="soon"), TypeError, "t_stop must be a number"),
        (dict(t_stop=1.0, stop_when={"energy": 1.0}), ValueError, "unknown stop_when keys"),
        (dict(stop_when={"collisions_per_particle": "ten"}), TypeError, "must be a number"),
        (dict(stop_when=10), TypeError, "stop_when must be a dict"),
        (
            dict(t_stop=1.0, store=("positions",)),
            TypeError,
            r"unknown keyword arguments \['store'\]",
        ),
        (dict(t_stop=1.0, tstop=2.0), TypeError, r"unknown keyword arguments \['tstop'\]"),
    ],
)
def test_a_callers_mistake_raises_before_any_run(kwargs, error, match):
    CALLED.clear()
    with pytest.raises(error, match=match):
        granular.ensemble(_counting_gas, 3, seed=1, backend="serial", **kwargs)
    assert CALLED == [], "no run started"


def test_a_scene_without_t_stop_and_other_argument_mistakes_raise_at_once():
    with pytest.raises(ValueError, match="finite t_stop or a stop_when"):
        granular.ensemble(SCENE, 3, seed=1, backend="serial")
    with pytest.raises(TypeError, match="runs must be a whole number"):
        granular.ensemble(SCENE, 2.5, seed=1, backend="serial", t_stop=1.0)
    with pytest.raises(ValueError, match="workers must be"):
        granular.ensemble(SCENE, 2, seed=1, workers=0, t_stop=1.0)
    with pytest.raises(TypeError, match=r"list of names, e.g. \('msd',\)"):
        granular.ensemble(SCENE, 2, seed=1, backend="serial", t_stop=1.0, quantities="msd")


@pytest.mark.parametrize("backend", ["serial", "processes"])
def test_every_run_failing_alike_raises_that_error(backend):
    """Every run raises the same error type: that error is raised (unpickled from a worker
    with its attributes), noting how many runs failed and the first run's traceback."""
    with pytest.raises(granular.InelasticCollapseError, match="collapse in run 0") as info:
        granular.ensemble(ensemble_tasks.always_collapses, 3, seed=1, backend=backend, workers=2)
    assert info.value.time == 0.5 and info.value.particles == (1, 2)
    note = "".join(getattr(info.value, "__notes__", []))
    assert "every one of this ensemble's 3 runs failed with InelasticCollapseError" in note
    assert "always_collapses" in note, "the worker's traceback"
    # a model function returning a Scene, called without t_stop: each run refuses
    with pytest.raises(ValueError, match="finite t_stop or a stop_when criterion"):
        granular.ensemble(ensemble_tasks.scene_without_run_options, 2, seed=1, backend="serial")


def test_a_sweep_point_whose_runs_all_fail_is_warned_about():
    with pytest.warns(RuntimeWarning, match=r"point 1: every one of its 2 runs failed"):
        ok, failed = granular.ensemble(
            [ensemble_tasks.gaussian, ensemble_tasks.always_collapses],
            2,
            seed=1,
            backend="serial",
        )
    assert ok.count == 2 and failed.count == 0 and len(failed.failures) == 2
    with pytest.raises(ValueError, match="all 2 runs failed"):
        failed.msd()


# Means over the runs that have a quantity; a quantity whose shape differs is named.


def test_a_quantity_missing_from_some_runs_is_the_mean_of_the_runs_that_have_it():
    """Runs 0, 2, 3 carry y = 0, 2, 3: mean 5/3 over 3 runs (not 5/4), error
    std(ddof=1)/sqrt(3)."""
    res = granular.ensemble(ensemble_tasks.y_missing_from_run_1, 4, seed=1, backend="serial")
    y = np.array([0.0, 2.0, 3.0])
    assert res.count == 4 and res.counts == {"x": 4, "y": 3}
    np.testing.assert_allclose(res.mean["y"], 5 / 3, rtol=1e-15)
    np.testing.assert_allclose(res.error["y"], y.std(ddof=1) / math.sqrt(3), rtol=1e-14)
    np.testing.assert_allclose(res.mean["x"], 1.5, rtol=1e-15)
    assert "y (3 runs)" in repr(res)


def test_a_quantity_whose_shape_differs_between_runs_is_warned_about_and_named():
    with pytest.warns(
        RuntimeWarning,
        match=r"'z' has no ensemble mean: its shape differs between runs "
        r"\(\(3,\) in run 0, \(2,\) in run 1\)",
    ):
        res = granular.ensemble(ensemble_tasks.z_shorter_in_run_1, 3, seed=1, backend="serial")
    assert "z" not in res.mean and "z" in res.left_out and res.counts == {"x": 3}
    assert [r["z"].shape for r in res.runs] == [(3,), (2,), (3,)]
    with pytest.raises(ValueError, match="no mean 'z': its shape differs"):
        res._quantity("z", "")


# Workers of the process backend do not outlive the ensemble's process.

ORPHAN_SCRIPT = """import os, sys, time
import granular

def model(seed):
    # tell the test this worker's pid and its parent's (the forkserver), then wait
    with open(os.path.join(sys.argv[1], str(os.getpid())), "w") as f:
        f.write(str(os.getppid()))
    time.sleep(300)

if __name__ == "__main__":
    granular.ensemble(model, 4, seed=1, workers=2, progress=False)
"""


def _alive(pid):
    """True while ``pid`` runs (a zombie, dead but not yet reaped, counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rpartition(")")[2].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_workers_exit_when_the_ensemble_process_is_killed(tmp_path):
    """SIGKILL the process running ensemble(backend="processes") while its workers run:
    the workers and their forkserver are gone within 5 s (they used to wait for tasks
    forever, and kept the forkserver alive)."""
    script = tmp_path / "script.py"
    script.write_text(ORPHAN_SCRIPT)
    pids_dir = tmp_path / "pids"
    pids_dir.mkdir()
    parent = subprocess.Popen([sys.executable, str(script), str(pids_dir)], cwd=tmp_path)
    others = []
    try:
        deadline = time.monotonic() + 60
        while len(list(pids_dir.iterdir())) < 2 and time.monotonic() < deadline:
            assert parent.poll() is None, "the ensemble's process ended early"
            time.sleep(0.05)
        time.sleep(0.2)  # both files written in full
        workers = [int(p.name) for p in pids_dir.iterdir()]
        forkservers = {int(p.read_text()) for p in pids_dir.iterdir()}
        others = workers + sorted(forkservers)
        assert len(workers) == 2 and all(_alive(p) for p in others)
        parent.send_signal(signal.SIGKILL)
        parent.wait(10)
        deadline = time.monotonic() + 5
        while any(_alive(p) for p in others) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [p for p in others if _alive(p)], "processes outlived the ensemble's"
    finally:
        if parent.poll() is None:
            parent.kill()
        for p in others:  # only the processes this test started
            if _alive(p):
                os.kill(p, signal.SIGKILL)
