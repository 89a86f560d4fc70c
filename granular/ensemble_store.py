"""An ensemble's finished runs in a directory, so that an interrupted ensemble resumes.

``ensemble(..., save_to=directory)`` writes each run's result there as it finishes (one
``.npz`` per run, read back with ``allow_pickle=False``) and, called again, takes the runs
already there instead of repeating them.  Files are written to a temporary name and
renamed, so a run killed mid-write leaves no file that passes for finished.  The
directory's ``ensemble.json`` holds a fingerprint of what made it (models, run options,
quantities, seed, granular version); a call that differs in any of them is refused.  A
model function is recognised by its pickle (its qualified name and any partial arguments),
not by its code: edit a function's body and keep its name, and the directory will not
notice -- start a new directory when the model changes.  Runs are identified by (point,
run index) and their seeds, so the runs count may grow between calls: ``runs=k`` then
``runs=n`` computes only the n - k new ones.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
from pathlib import Path
from typing import Any

import numpy as np

from ._files import write_atomic
from .errors import CheckpointError

FINGERPRINT = "ensemble.json"
_META = "__run__"  # the entry of a run's file that describes it; results use other names


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
    entropy = [str(e) for e in entropy] if isinstance(entropy, (list, tuple)) else str(entropy)
    return {"entropy": entropy, "spawn_key": [int(k) for k in seed.spawn_key]}


def fingerprint(models, sweep, root, run_kwargs, quantities) -> dict[str, Any]:
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


class RunStore:
    """The directory of an ensemble's runs, checked against (or given) a fingerprint."""

    def __init__(self, path: str | os.PathLike, print_: dict[str, Any]) -> None:
        self.path = Path(path)
        self.path.mkdir(parents=True, exist_ok=True)
        own = self.path / FINGERPRINT
        if own.exists():
            try:
                theirs = json.loads(own.read_text())
            except (OSError, ValueError) as exc:
                raise CheckpointError(f"{own} is unreadable: {exc}") from exc
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
            self._write_atomic(own, json.dumps(print_, indent=1).encode())

    def _file(self, point: int, run: int) -> Path:
        return self.path / f"p{point:04d}-r{run:06d}.npz"

    def has(self, point: int, run: int) -> bool:
        return self._file(point, run).exists()

    def _write_atomic(self, target: Path, data: bytes) -> None:
        write_atomic(target, data)

    def write(self, point, run, seed, status, payload) -> None:
        """Store one finished run: its arrays (status "ok") or its failure."""
        meta = {"status": status, "seed": _seed_dict(seed)}
        arrays = {}
        if status == "ok":
            arrays = {k: np.asarray(v) for k, v in payload.items()}
            if _META in arrays:
                raise ValueError(f"a run's result may not be named {_META!r}")
            meta["scalars"] = sorted(k for k, v in payload.items() if np.ndim(v) == 0)
        else:
            meta["error"] = list(payload)
        import io

        buf = io.BytesIO()
        try:
            np.savez(buf, **{_META: np.array(json.dumps(meta))}, **arrays)
        except ValueError as exc:  # object arrays would need pickle to load
            raise ValueError(
                f"run {run} of point {point}: its result cannot be saved without pickle "
                f"({exc}); save_to stores NumPy arrays of numbers only"
            ) from exc
        self._write_atomic(self._file(point, run), buf.getvalue())

    def load(self, point, run, seed) -> tuple[str, Any]:
        """(status, payload) of a stored run, as ``_call_task`` returned it."""
        path = self._file(point, run)
        try:
            with np.load(path, allow_pickle=False) as npz:
                arrays = {k: npz[k] for k in npz.files}
            meta = json.loads(str(arrays.pop(_META)[()]))
        # any unreadable file (bad zip, missing entry, bad JSON) gets the same advice
        except Exception as exc:
            raise CheckpointError(
                f"{path} is unreadable ({exc.__class__.__name__}: {exc}); delete it and "
                "call again to redo that run"
            ) from exc
        if meta.get("seed") != _seed_dict(seed):
            raise CheckpointError(
                f"{path} was made with seed {meta.get('seed')}, but this call gives that run "
                f"{_seed_dict(seed)} (a SeedSequence that has spawned before gives new seeds: "
                "pass an int or a fresh SeedSequence)"
            )
        if meta["status"] != "ok":
            return meta["status"], tuple(meta["error"])
        scalars = set(meta.get("scalars", ()))
        return "ok", {k: (v[()] if k in scalars else v) for k, v in arrays.items()}
