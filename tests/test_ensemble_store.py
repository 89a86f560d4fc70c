"""ensemble(..., save_to=directory): runs written as they finish, resumed without being
repeated, and the combined result bit for bit the uninterrupted one (exact equality: the
runs are reduced in run order from the same arrays, so no tolerance applies)."""

import concurrent.futures
import io
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time
import tracemalloc
import zipfile

import numpy as np
import pytest

from granular import CheckpointError, Scene, ensemble

from helpers import ensemble_tasks

HELPERS_ROOT = pathlib.Path(__file__).parent  # tests/, where `helpers` is a package

CALLS = []  # seeds the model below was called with (serial and threads backends)
FAIL_AT = {"interrupt": None, "error": None, "block": None}


def model(seed):
    """A cheap model: arrays drawn from the run's seed; raises on request, to interrupt
    an ensemble (KeyboardInterrupt passes through ensemble) or to fail one run."""
    rng = np.random.default_rng(seed)
    index = seed.spawn_key[-1]
    if FAIL_AT["block"] is not None:  # tell the test this run started, wait for its go
        started, go = FAIL_AT["block"]
        started.set()
        go.wait(10)
    if FAIL_AT["interrupt"] is not None and len(CALLS) >= FAIL_AT["interrupt"]:
        raise KeyboardInterrupt
    CALLS.append(index)
    if FAIL_AT["error"] == index:
        raise ValueError(f"run {index} fails")
    return {"times": np.arange(4.0), "msd": rng.random(4), "energy": np.float64(rng.random())}


@pytest.fixture(autouse=True)
def _reset():
    CALLS.clear()
    FAIL_AT.update(interrupt=None, error=None, block=None)


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


# One ensemble at a time in a directory, and only its own runs read back.


def test_a_second_ensemble_in_a_directory_in_use_is_refused(tmp_path):
    """While one call runs (its first run waits on an event), a second call on the same
    directory -- same arguments or not, same process or not -- is refused; once the first
    returns, the second resumes from its runs."""
    started, go = threading.Event(), threading.Event()

    def first():
        FAIL_AT["block"] = (started, go)
        return ensemble(model, 3, seed=12, backend="serial", save_to=tmp_path)

    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        done = pool.submit(first)
        assert started.wait(30)
        try:
            for seed in (12, 13):
                in_use = rf"in use by another ensemble \(process {os.getpid()} holds"
                with pytest.raises(CheckpointError, match=in_use):
                    ensemble(model, 3, seed=seed, backend="serial", save_to=tmp_path)
        finally:
            go.set()
        whole = done.result(30)
    CALLS.clear()
    FAIL_AT["block"] = None
    _same(whole, ensemble(model, 3, seed=12, backend="serial", save_to=tmp_path))
    assert CALLS == []


def test_a_run_file_of_another_ensemble_is_refused(tmp_path):
    """A run file copied in from another ensemble's directory (same seed and run, another
    model: its seed alone cannot tell) is refused, not mixed in."""
    ensemble(model, 3, seed=14, backend="serial", save_to=tmp_path / "a")
    ensemble(ensemble_tasks.gaussian, 3, seed=14, backend="serial", save_to=tmp_path / "b")
    (tmp_path / "a" / "p0000-r000001.npz").write_bytes(
        (tmp_path / "b" / "p0000-r000001.npz").read_bytes()
    )
    with pytest.raises(CheckpointError, match=r"p0000-r000001\.npz was written by another"):
        ensemble(model, 3, seed=14, backend="serial", save_to=tmp_path / "a")


SUBPROCESS = """import sys
import granular
from helpers import ensemble_tasks

if __name__ == "__main__":
    granular.ensemble(ensemble_tasks.slow_draws, int(sys.argv[2]), seed=int(sys.argv[3]),
                      backend=sys.argv[4], workers=2, progress=False, save_to=sys.argv[1])
"""


def _killed_mid_run(tmp_path, folder, runs, seed, backend, delay):
    """Start an ensemble with save_to=folder in another process and SIGKILL it ``delay``
    seconds after its first run file appears (or when it ends)."""
    script = tmp_path / "ensemble_script.py"
    script.write_text(SUBPROCESS)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(HELPERS_ROOT), *sys.path]))
    proc = subprocess.Popen(
        [sys.executable, str(script), str(folder), str(runs), str(seed), backend], env=env
    )
    try:
        deadline = time.monotonic() + 60
        while not list(folder.glob("p*-r*.npz")) and proc.poll() is None:
            assert time.monotonic() < deadline, "no run finished in 60 s"
            time.sleep(0.005)
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait(30)


def _check_resume(tmp_path, folder, runs, seed):
    whole = ensemble(ensemble_tasks.slow_draws, runs, seed=seed, backend="serial")
    resumed = ensemble(ensemble_tasks.slow_draws, runs, seed=seed, backend="serial", save_to=folder)
    _same(whole, resumed)
    assert not list(folder.glob(".tmp-*")), "the killed writer's temporary files are gone"
    return len(list(folder.glob("p*-r*.npz")))


def test_an_ensemble_killed_mid_run_resumes_bit_for_bit(tmp_path):
    """SIGKILL (no cleanup runs, the directory's lock dies with the process) while runs are
    being written; the next call is not refused, computes the rest, and equals an
    uninterrupted ensemble exactly."""
    folder = tmp_path / "runs"
    _killed_mid_run(tmp_path, folder, 40, 15, "serial", delay=0.1)
    assert _check_resume(tmp_path, folder, 40, 15) == 40


@pytest.mark.slow
def test_fuzz_ensembles_killed_at_random_moments_resume_bit_for_bit(tmp_path):
    """Eight kills at random moments (seeded), with the serial and the process backend,
    each resumed and compared with the uninterrupted ensemble."""
    rng = np.random.default_rng(2026)
    for trial in range(8):
        folder = tmp_path / f"trial{trial}"
        backend = ("serial", "processes")[trial % 2]
        _killed_mid_run(tmp_path, folder, 30, 100 + trial, backend, delay=rng.uniform(0, 0.3))
        assert _check_resume(tmp_path, folder, 30, 100 + trial) == 30


# Damaged and crafted run files: one error (CheckpointError, naming the file), and never
# more read or decompressed than the file's own size.


def _run_file(tmp_path):
    ensemble(model, 2, seed=16, backend="serial", save_to=tmp_path)
    return tmp_path / "p0000-r000001.npz"


def _npz(members, deflated=()):
    """The bytes of a zip of ``members`` (name -> bytes), stored uncompressed except
    those named in ``deflated``."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for name, data in members.items():
            kind = zipfile.ZIP_DEFLATED if name in deflated else zipfile.ZIP_STORED
            zf.writestr(name, data, compress_type=kind)
    return buf.getvalue()


def _npy_header(descr, shape):
    header = {"descr": descr, "fortran_order": False, "shape": shape}
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue()


def _resume(tmp_path):
    return ensemble(model, 2, seed=16, backend="serial", save_to=tmp_path)


def _members(path):
    with zipfile.ZipFile(path) as zf:
        return {name: zf.read(name) for name in zf.namelist()}


def test_crafted_run_files_raise_checkpoint_error(tmp_path):
    victim = _run_file(tmp_path)
    good = _members(victim)
    meta = good["__run__.npy"]
    cases = {
        "huge header": {**good, "msd.npy": _npy_header("<f8", (1 << 40,)) + b"\0" * 64},
        "short data": {**good, "msd.npy": _npy_header("<f8", (5,)) + b"\0" * 32},
        "object array": {**good, "msd.npy": _npy_header("|O", (1,)) + b"\0" * 8},
        "structured": {**good, "msd.npy": _npy_header([("a", "<f8")], (1,)) + b"\0" * 8},
        "not npy": {**good, "msd.npy": b"hello"},
        "no description": {k: v for k, v in good.items() if k != "__run__.npy"},
        "a member missing": {k: v for k, v in good.items() if k != "msd.npy"},
        "deflated": good,
        "other member": {**good, "msd.txt": b"1"},
        "nested JSON": {
            **good,
            "__run__.npy": _npy_header("<U200000", ()) + ("[" * 200_000).encode("utf-32-le"),
        },
        "description of wrong types": {
            **good,
            "__run__.npy": meta.replace(b'"\x00\x00\x00o\x00\x00\x00k\x00\x00\x00"', b"1" * 16),
        },
    }
    for what, members in cases.items():
        victim.write_bytes(_npz(members, deflated=("msd.npy",) if what == "deflated" else ()))
        with pytest.raises(CheckpointError, match=r"p0000-r000001\.npz is unreadable") as info:
            _resume(tmp_path)
        assert "delete it" in str(info.value), what
    victim.unlink()
    victim.symlink_to("/dev/zero")
    with pytest.raises(CheckpointError, match="not a regular file"):
        _resume(tmp_path)
    victim.unlink()
    os.mkfifo(victim)  # opening a FIFO would wait for a writer forever
    with pytest.raises(CheckpointError, match="not a regular file"):
        _resume(tmp_path)


def test_a_deflated_member_is_refused_before_it_is_decompressed(tmp_path):
    """A run file of 256 kB with a member that inflates to 128 MiB: refused by its
    compression, with at most 16 MB allocated on the way (the file, twice, and change)."""
    victim = _run_file(tmp_path)
    good = _members(victim)
    with zipfile.ZipFile(victim, "w") as zf:
        for name, data in good.items():
            zf.writestr(name, data)
        big = zipfile.ZipInfo("big.npy")
        big.compress_type = zipfile.ZIP_DEFLATED
        with zf.open(big, "w", force_zip64=True) as f:
            f.write(_npy_header("<f8", (1 << 24,)))
            zeros = bytes(1 << 20)
            for _ in range(128):
                f.write(zeros)
    assert victim.stat().st_size < 1 << 20
    tracemalloc.start()
    try:
        with pytest.raises(CheckpointError, match="unreadable"):
            _resume(tmp_path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 16 << 20, f"{peak / 2**20:.0f} MiB allocated"


def test_fuzz_truncated_and_bit_flipped_run_files(tmp_path):
    """Every truncation and 300 random bit flips (seeded) of a run file: each either reads
    back as the very run it was (a flip in a field nothing reads) or raises CheckpointError;
    never another exception, never other numbers (the zip's CRC covers every array)."""
    victim = _run_file(tmp_path)
    original = victim.read_bytes()
    reference = _resume(tmp_path)
    rng = np.random.default_rng(7)
    damaged = [original[:n] for n in range(0, len(original), 11)]
    for _ in range(300):
        data = bytearray(original)
        bit = int(rng.integers(8 * len(data)))
        data[bit // 8] ^= 1 << (bit % 8)
        damaged.append(bytes(data))
    refused = 0
    for data in damaged:
        victim.write_bytes(data)
        try:
            _same(reference, _resume(tmp_path))
        except CheckpointError:
            refused += 1
    assert refused > len(damaged) // 2


def test_an_unreadable_fingerprint_is_one_error(tmp_path):
    ensemble(model, 1, seed=17, backend="serial", save_to=tmp_path)
    own = tmp_path / "ensemble.json"
    for text in ("[" * 100_000, "{" * 10, '"a string"', "x" * (2 << 20)):
        own.write_text(text)
        with pytest.raises(CheckpointError, match=r"ensemble\.json is unreadable"):
            ensemble(model, 1, seed=17, backend="serial", save_to=tmp_path)
    own.unlink()
    own.symlink_to("/dev/zero")
    with pytest.raises(CheckpointError, match="not a regular file"):
        ensemble(model, 1, seed=17, backend="serial", save_to=tmp_path)


RACE = """import sys, time
import granular
from granular import CheckpointError
from helpers import ensemble_tasks

if __name__ == "__main__":
    time.sleep(max(0.0, float(sys.argv[3]) - time.time()))  # both start together
    try:
        granular.ensemble(ensemble_tasks.slow_draws, 10, seed=int(sys.argv[2]),
                          backend="serial", progress=False, save_to=sys.argv[1])
    except CheckpointError as exc:
        print(exc)
        sys.exit(3)
"""


@pytest.mark.slow
def test_two_ensembles_started_together_on_one_directory_do_not_mix(tmp_path):
    """Two processes with different seeds start on one directory at the same instant
    (four trials): one finishes, the other is refused, and the directory resumes to
    exactly the winner's ensemble (without the lock, both passed the fingerprint check
    and wrote runs of two ensembles into one directory)."""
    script = tmp_path / "race.py"
    script.write_text(RACE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(HELPERS_ROOT), *sys.path]))
    for trial in range(4):
        folder = tmp_path / f"trial{trial}"
        start = time.time() + 2.0
        procs = {
            seed: subprocess.Popen(
                [sys.executable, str(script), str(folder), str(seed), str(start)],
                env=env,
                stdout=subprocess.PIPE,
                text=True,
            )
            for seed in (20 + 2 * trial, 21 + 2 * trial)
        }
        codes = {seed: p.wait(60) for seed, p in procs.items()}
        outs = {seed: p.stdout.read() for seed, p in procs.items()}
        assert sorted(codes.values()) == [0, 3], outs
        winner = next(seed for seed, code in codes.items() if code == 0)
        loser = next(seed for seed, code in codes.items() if code == 3)
        assert "another ensemble" in outs[loser]
        _same(
            ensemble(ensemble_tasks.slow_draws, 10, seed=winner, backend="serial"),
            ensemble(ensemble_tasks.slow_draws, 10, seed=winner, backend="serial", save_to=folder),
        )
