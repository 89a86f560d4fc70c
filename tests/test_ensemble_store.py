"""ensemble(..., save_to=directory): runs written as they finish, resumed without being
repeated, and the combined result bit for bit the uninterrupted one (exact equality: the
runs are reduced in run order from the same arrays, so no tolerance applies)."""

import numpy as np
import pytest

from granular import CheckpointError, Scene, ensemble

CALLS = []  # seeds the model below was called with (serial and threads backends)
FAIL_AT = {"interrupt": None, "error": None}


def model(seed):
    """A cheap model: arrays drawn from the run's seed; raises on request, to interrupt
    an ensemble (KeyboardInterrupt passes through ensemble) or to fail one run."""
    rng = np.random.default_rng(seed)
    index = seed.spawn_key[-1]
    if FAIL_AT["interrupt"] is not None and len(CALLS) >= FAIL_AT["interrupt"]:
        raise KeyboardInterrupt
    CALLS.append(index)
    if FAIL_AT["error"] == index:
        raise ValueError(f"run {index} fails")
    return {"times": np.arange(4.0), "msd": rng.random(4), "energy": np.float64(rng.random())}


@pytest.fixture(autouse=True)
def _reset():
    CALLS.clear()
    FAIL_AT.update(interrupt=None, error=None)


def _same(a, b):
    assert a.count == b.count and sorted(a.mean) == sorted(b.mean)
    for k in a.mean:
        assert np.array_equal(a.mean[k], b.mean[k]) and np.array_equal(
            a.error[k], b.error[k], equal_nan=True
        )
    assert np.array_equal(a.times, b.times)
    assert len(a.runs) == len(b.runs)
    for x, y in zip(a.runs, b.runs, strict=True):
        assert sorted(x) == sorted(y)
        for k in x:
            assert np.array_equal(x[k], y[k]) and np.shape(x[k]) == np.shape(y[k])
    assert [(f.index, f.error_type) for f in a.failures] == [
        (f.index, f.error_type) for f in b.failures
    ]


def test_more_runs_later_compute_only_the_new_ones(tmp_path):
    whole = ensemble(model, 7, seed=3, backend="serial")
    CALLS.clear()
    ensemble(model, 3, seed=3, backend="serial", save_to=tmp_path)
    assert CALLS == [0, 1, 2]
    CALLS.clear()
    resumed = ensemble(model, 7, seed=3, backend="serial", save_to=tmp_path)
    assert CALLS == [3, 4, 5, 6], "only the runs not in the directory are computed"
    _same(whole, resumed)
    CALLS.clear()
    again = ensemble(model, 7, seed=3, backend="serial", save_to=tmp_path)
    assert CALLS == [] and len(list(tmp_path.glob("p*-r*.npz"))) == 7
    _same(whole, again)


def test_an_interrupted_ensemble_resumes_where_it_stopped(tmp_path):
    """The model raises KeyboardInterrupt at the fifth run (as Ctrl-C would): the four
    finished runs are on disk, and the next call computes only the other six."""
    whole = ensemble(model, 10, seed=4, backend="serial")
    CALLS.clear()
    FAIL_AT["interrupt"] = 4
    with pytest.raises(KeyboardInterrupt):
        ensemble(model, 10, seed=4, backend="serial", save_to=tmp_path)
    assert len(list(tmp_path.glob("p*-r*.npz"))) == 4
    FAIL_AT["interrupt"] = None
    CALLS.clear()
    resumed = ensemble(model, 10, seed=4, backend="serial", save_to=tmp_path)
    assert CALLS == [4, 5, 6, 7, 8, 9]
    _same(whole, resumed)
    assert not list(tmp_path.glob(".tmp-*")), "no temporary file left"


def test_edmd_runs_resume_bit_for_bit_with_threads(tmp_path):
    """Scene models run by EDMD, in a worker pool whose runs finish in any order; a
    sweep of two points, the second call adding runs to both."""
    scenes = [
        Scene.random(60, 0.02, dim=2, restitution=r, seed=5, temperature=1.0) for r in (0.8, 1.0)
    ]
    opts = dict(seed=6, t_stop=0.2, sample_times=np.linspace(0, 0.2, 5), backend="threads")
    opts["quantities"] = ("msd", "temperature", "pressure")
    whole = ensemble(scenes, 4, workers=2, **opts)
    ensemble(scenes, 2, workers=2, save_to=tmp_path, **opts)
    resumed = ensemble(scenes, 4, workers=2, save_to=tmp_path, **opts)
    for a, b in zip(whole, resumed, strict=True):
        _same(a, b)
    assert len(list(tmp_path.glob("p*-r*.npz"))) == 8


def test_failed_runs_are_stored_and_not_repeated(tmp_path):
    FAIL_AT["error"] = 1
    first = ensemble(model, 3, seed=7, backend="serial", save_to=tmp_path)
    assert [f.index for f in first.failures] == [1] and first.count == 2
    CALLS.clear()
    again = ensemble(model, 3, seed=7, backend="serial", save_to=tmp_path)
    assert CALLS == []
    _same(first, again)
    assert again.failures[0].error == first.failures[0].error


def test_a_directory_of_another_ensemble_is_refused(tmp_path):
    ensemble(model, 2, seed=8, backend="serial", save_to=tmp_path)
    with pytest.raises(CheckpointError, match="seed"):
        ensemble(model, 2, seed=9, backend="serial", save_to=tmp_path)
    with pytest.raises(CheckpointError, match="models"):
        ensemble([model, model], 2, seed=8, backend="serial", save_to=tmp_path)
    scene = Scene.random(20, 0.02, dim=2, seed=1)
    other = tmp_path / "edmd"
    ensemble(scene, 1, seed=8, t_stop=0.1, backend="serial", save_to=other)
    with pytest.raises(CheckpointError, match="run_options"):
        ensemble(scene, 1, seed=8, t_stop=0.2, backend="serial", save_to=other)
    with pytest.raises(CheckpointError, match="quantities"):
        ensemble(scene, 1, seed=8, t_stop=0.1, backend="serial", save_to=other, quantities=["msd"])
    with pytest.raises(CheckpointError, match="models"):
        ensemble(
            scene.replace(restitution=0.5), 1, seed=8, t_stop=0.1, backend="serial", save_to=other
        )


def test_resuming_needs_a_seed_and_a_fresh_seed_sequence(tmp_path):
    with pytest.raises(ValueError, match="needs a seed"):
        ensemble(model, 2, backend="serial", save_to=tmp_path)
    ss = np.random.SeedSequence(10)
    ensemble(model, 2, seed=ss, backend="serial", save_to=tmp_path)
    # the same SeedSequence object has spawned: its new children differ, which is caught
    with pytest.raises(CheckpointError, match="fresh SeedSequence"):
        ensemble(model, 2, seed=ss, backend="serial", save_to=tmp_path)
    with pytest.raises(ValueError, match="pickled"):
        ensemble(
            lambda seed: {"x": np.zeros(1)}, 1, seed=1, backend="serial", save_to=tmp_path / "l"
        )


def test_half_written_and_damaged_run_files(tmp_path):
    """A temporary file left by a killed writer is not taken for a run; a run file damaged
    afterwards is named, with the advice to delete it."""
    ensemble(model, 2, seed=11, backend="serial", save_to=tmp_path)
    (tmp_path / ".tmp-abc.part").write_bytes(b"half a run")
    CALLS.clear()
    ensemble(model, 3, seed=11, backend="serial", save_to=tmp_path)
    assert CALLS == [2]
    victim = tmp_path / "p0000-r000001.npz"
    victim.write_bytes(victim.read_bytes()[:50])
    with pytest.raises(CheckpointError, match=r"p0000-r000001\.npz is unreadable.*delete it"):
        ensemble(model, 3, seed=11, backend="serial", save_to=tmp_path)
    (tmp_path / "ensemble.json").unlink()
    with pytest.raises(CheckpointError, match=r"no ensemble\.json"):
        ensemble(model, 3, seed=11, backend="serial", save_to=tmp_path)
