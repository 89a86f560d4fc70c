"""An ensemble's finished runs in a directory, so that an interrupted ensemble resumes.

``ensemble(..., save_to=directory)`` writes each run's result there as it finishes (one
``.npz`` per run) and, called again, takes the runs already there instead of repeating
them.  Files are written to a temporary name and renamed, so a run killed mid-write leaves
no file that passes for finished.

One ensemble at a time: a call holds an exclusive lock on the directory's ``.lock`` file
(``flock``; ``msvcrt.locking`` on Windows) from before it reads anything until it
returns, and a second call on the directory meanwhile is refused.  The operating system
drops the lock when its process dies, so a killed ensemble leaves nothing stuck.

The directory's ``ensemble.json`` holds a fingerprint of what made it (models, run
options, quantities, seed, granular version), and every run file carries that
fingerprint's digest: a call that differs in any of them is refused, and so is a run file
that another ensemble wrote.  A model function is recognised by its pickle (its qualified
name and any partial arguments), not by its code: edit a function's body and keep its
name, and the directory will not notice -- start a new directory when the model changes.
Runs are identified by (point, run index) and their seeds, so the runs count may grow
between calls: ``runs=k`` then ``runs=n`` computes only the n - k new ones.

Reading a run file trusts nothing in it, by the rules a checkpoint is read by
(granular/_npz.py): the file must be a regular file, its zip members stored uncompressed
and unencrypted (as ``np.savez`` writes them), inside the file and together no larger than
it, each a ``.npy`` array of plain numbers or text whose header's size matches its member,
with the zip's CRC checked; anything else is a ``CheckpointError`` naming the file.  So a
damaged or crafted file costs at most its own size in memory, and runs no code.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import pickle
import sys
import zipfile
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ._files import write_atomic
from ._npz import check_members, read_member, read_regular
from .errors import CheckpointError

FINGERPRINT = "ensemble.json"
_META = "__run__"  # the entry of a run's file that describes it; results use other names
LOCK = ".lock"
# ensemble.json is a few hundred bytes; anything far larger is not one
_MAX_FINGERPRINT_BYTES = 1 << 20
# dtype kinds a run file may hold: numbers, booleans and text (never objects)
_KINDS = "biufcUS"


def _digest(obj: Any, what: str) -> str:
    """SHA-256 of obj's pickle: a Scene by its arrays and parameters, a function by its
    module-level name and (for functools.partial) its arguments -- not by its code."""
    try:
        return hashlib.sha256(pickle.dumps(obj, protocol=4)).hexdigest()
    except (pickle.PicklingError, AttributeError, TypeError) as exc:
        raise ValueError(
            f"save_to needs {what} that can be pickled, to recognise it when resuming "
            "(a Scene, a module-level function, or a functools.partial of one), "
            f"got {obj!r}: {exc}"
        ) from exc


def _seed_dict(seed: np.random.SeedSequence) -> dict[str, Any]:
    entropy = seed.entropy
    text = [str(e) for e in entropy] if isinstance(entropy, (list, tuple)) else str(entropy)
    return {"entropy": text, "spawn_key": [int(k) for k in seed.spawn_key]}


def fingerprint(
    models: Sequence[Any],
    sweep: bool,
    root: np.random.SeedSequence,
    run_kwargs: dict[str, Any],
    quantities: Iterable[str],
) -> dict[str, Any]:
    """What an ensemble directory was made for (JSON-able)."""
    from . import __version__

    return {
        "granular_version": __version__,
        "sweep": bool(sweep),
        "models": [_digest(m, "every model") for m in models],
        "run_options": _digest(sorted(run_kwargs.items()), "run options"),
        "quantities": list(quantities),
        "seed": _seed_dict(root),
    }


def digest(print_: dict[str, Any]) -> str:
    """SHA-256 of a fingerprint's canonical JSON: what every run file of it carries."""
    return hashlib.sha256(json.dumps(print_, sort_keys=True).encode()).hexdigest()


class _DirectoryLock:
    """An exclusive lock on ``folder/.lock`` held through an open file: ``flock`` on POSIX
    (its owner is the open file, so two calls in one process exclude each other too),
    ``msvcrt.locking`` on Windows.  The kernel releases it when the process dies; the file
    itself stays (deleting it would let two processes lock two different files)."""

    def __init__(self, folder: Path) -> None:
        path = folder / LOCK
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            if not self._try_lock(fd):
                try:  # the holder's pid, for the message (Windows may refuse the read)
                    os.lseek(fd, 0, os.SEEK_SET)
                    holder = os.read(fd, 32).decode(errors="replace").strip()
                except OSError:
                    holder = ""
                who = f"process {holder}" if holder.isdigit() else "another process"
                raise CheckpointError(
                    f"{folder} is in use by another ensemble ({who} holds {path}): "
                    "two ensembles in one save_to directory would mix their runs.  Wait for "
                    "it to finish (then call again to resume from its runs), or give this "
                    "call another directory"
                )
            # the holder's pid, padded to a fixed width so no truncation is needed
            os.lseek(fd, 0, os.SEEK_SET)
            os.write(fd, f"{os.getpid():<20d}\n".encode())
        except BaseException:
            os.close(fd)
            raise
        self._fd: int | None = fd

    @staticmethod
    def _try_lock(fd: int) -> bool:
        if sys.platform == "win32":
            import msvcrt

            try:
                msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
            except OSError:
                return False
            return True
        import fcntl

        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        return True

    def release(self) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing the file drops the lock (flock and msvcrt alike)
            self._fd = None


def _read_run_file(path: Path) -> dict[str, np.ndarray]:
    """The arrays of a run file, read within the file's own size (see the module's
    docstring and granular/_npz.py); ValueError, OSError or zipfile's errors for anything
    else."""
    data = read_regular(path)
    arrays = {}
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        for filename, info in check_members(zf, len(data)).items():
            name = filename.removesuffix(".npy")
            if name == filename:
                raise ValueError(f"unexpected member {filename!r}")
            # np.savez writes an array that is Fortran- but not C-contiguous as Fortran
            arrays[name] = read_member(zf, info, _KINDS, fortran_ok=True).copy()
    return arrays


def _check_meta(meta: Any) -> dict[str, Any]:
    """A run file's description, checked for the fields and types ``load`` uses."""
    ok = (
        isinstance(meta, dict)
        and meta.get("status") in ("ok", "error")
        and isinstance(meta.get("seed"), dict)
        and isinstance(meta.get("ensemble"), str)
    )
    if ok and meta["status"] == "ok":
        names = [meta.get("scalars"), meta.get("arrays")]
        ok = all(isinstance(n, list) and all(isinstance(k, str) for k in n) for n in names)
    elif ok:
        error = meta.get("error")
        ok = isinstance(error, list) and len(error) == 3 and all(isinstance(e, str) for e in error)
    if not ok:
        raise ValueError("its description lacks fields or has wrong types")
    return meta


class RunStore:
    """The directory of an ensemble's runs, locked for this call and checked against (or
    given) a fingerprint.  Use as a context manager, or call ``close()``, to release the
    lock."""

    def __init__(self, path: str | os.PathLike, print_: dict[str, Any]) -> None:
        self.path = Path(path)
        self.path.mkdir(parents=True, exist_ok=True)
        self._lock = _DirectoryLock(self.path)
        try:
            self._check_or_write(print_)
            # with the lock held no one else writes here: a temporary file is a dead
            # writer's (write_atomic's, killed before its rename)
            for stale in self.path.glob(".tmp-*"):
                stale.unlink(missing_ok=True)
        except BaseException:
            self._lock.release()
            raise
        self.digest = digest(print_)

    def _check_or_write(self, print_: dict[str, Any]) -> None:
        own = self.path / FINGERPRINT
        if own.exists():
            try:
                theirs = json.loads(read_regular(own, _MAX_FINGERPRINT_BYTES))
                if not isinstance(theirs, dict):
                    raise ValueError("not a JSON object")
            # any unreadable file (I/O, not JSON, nested too deep, too large) gets one error
            except Exception as exc:
                raise CheckpointError(
                    f"{own} is unreadable ({exc.__class__.__name__}: {exc}): not made by "
                    "ensemble(save_to=...), or damaged; use another directory"
                ) from exc
            differ = sorted(k for k in set(print_) | set(theirs) if print_.get(k) != theirs.get(k))
            if differ:
                raise CheckpointError(
                    f"{self.path} holds runs of another ensemble (its {', '.join(differ)} "
                    "differ from this call's; see its ensemble.json): use another directory, "
                    "or empty this one to start afresh"
                )
        else:
            if any(self.path.glob("p*-r*.npz")):
                raise CheckpointError(
                    f"{self.path} holds run files but no {FINGERPRINT}: not made by "
                    "ensemble(save_to=...), or damaged; use another directory"
                )
            write_atomic(own, json.dumps(print_, indent=1).encode())

    def close(self) -> None:
        """Release the directory's lock (the files stay)."""
        self._lock.release()

    def __enter__(self) -> RunStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _file(self, point: int, run: int) -> Path:
        return self.path / f"p{point:04d}-r{run:06d}.npz"

    def has(self, point: int, run: int) -> bool:
        return self._file(point, run).exists()

    def write(
        self, point: int, run: int, seed: np.random.SeedSequence, status: str, payload: Any
    ) -> None:
        """Store one finished run: its arrays (status "ok") or its failure (the first
        three entries of the payload: repr, type name, traceback)."""
        meta = {"status": status, "seed": _seed_dict(seed), "ensemble": self.digest}
        arrays: dict[str, np.ndarray] = {}
        if status == "ok":
            arrays = {k: np.asarray(v) for k, v in payload.items()}
            if _META in arrays:
                raise ValueError(f"a run's result may not be named {_META!r}")
            meta["scalars"] = sorted(k for k, v in payload.items() if np.ndim(v) == 0)
            # the names stored, so that a run missing one (a damaged zip directory can
            # hide a member) is refused, not read as a run without that quantity
            meta["arrays"] = sorted(arrays)
        else:
            meta["error"] = [str(e) for e in payload[:3]]
        bad = sorted(k for k, v in arrays.items() if v.dtype.kind not in _KINDS)
        if bad:
            raise ValueError(
                f"run {run} of point {point}: its result {bad} are not arrays of numbers "
                "or text; save_to stores NumPy arrays of numbers only"
            )
        buf = io.BytesIO()
        # Any: mypy would match the names against savez's own keywords (allow_pickle)
        entries: dict[str, Any] = {_META: np.array(json.dumps(meta)), **arrays}
        np.savez(buf, **entries)
        write_atomic(self._file(point, run), buf.getvalue())

    def load(self, point: int, run: int, seed: np.random.SeedSequence) -> tuple[str, Any]:
        """(status, payload) of a stored run, as ``_call_task`` returned it."""
        path = self._file(point, run)
        try:
            arrays = _read_run_file(path)
            meta = _check_meta(json.loads(str(arrays.pop(_META)[()])))
            if meta["status"] == "ok" and sorted(arrays) != meta["arrays"]:
                raise ValueError(f"it holds {sorted(arrays)}, not the {meta['arrays']} written")
        # any unreadable file (I/O, bad zip, crafted header, missing entry, bad or deeply
        # nested JSON) gets the same error and advice
        except Exception as exc:
            raise CheckpointError(
                f"{path} is unreadable ({exc.__class__.__name__}: {exc}); delete it and "
                "call again to redo that run"
            ) from exc
        if meta["ensemble"] != self.digest:
            raise CheckpointError(
                f"{path} was written by another ensemble than the one {self.path / FINGERPRINT}"
                " describes (another model, run options, quantities, seed or granular "
                "version): its runs cannot be mixed with this one's.  Delete that file to "
                "redo the run, or use another directory"
            )
        if meta["seed"] != _seed_dict(seed):
            raise CheckpointError(
                f"{path} was made with seed {meta['seed']}, but this call gives that run "
                f"{_seed_dict(seed)} (a SeedSequence that has spawned before gives new seeds: "
                "pass an int or a fresh SeedSequence)"
            )
        if meta["status"] != "ok":
            return meta["status"], tuple(meta["error"])
        scalars = set(meta["scalars"])
        return "ok", {k: (v[()] if k in scalars else v) for k, v in arrays.items()}
