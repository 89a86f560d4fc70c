"""Checkpoints: a Simulation's whole state in a file, continued bit for bit after loading.

A checkpoint is a NumPy ``.npz`` file (read with ``allow_pickle=False``: loading one runs
no code) holding

- ``meta``: JSON with the format name and version, the granular version, the engine's
  state layout (``_core.CHECKPOINT_LAYOUT``), the engine knobs (``cell_factor``,
  ``big_ratio``, ``shell``), the scene's parameters and a SHA-256 of the engine state;
- ``scene_<name>``: the arrays of the scene the Simulation was built from (positions,
  velocities, radii, masses, box corners);
- ``engine_state``: the C engine's state as bytes (``csrc/checkpoint.h``): particle
  records at their own clocks, image and collision counters, predictions, the event
  queue as it stands, cell and neighbour lists, the renumbering, the time and every
  counter.

Loading builds an engine from the stored scene and knobs (which rebuilds what follows
from them: cell sizes, neighbour tables) and restores the saved state into it; the
C core checks every size, index and link it reads.  A file from another format version,
granular version or engine layout is refused, as is a truncated or corrupt one, with a
``CheckpointError`` saying which.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import tempfile
import zipfile
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core
from .errors import CheckpointError
from .restitution import describe, from_description
from .scene import Scene

if TYPE_CHECKING:
    from .simulation import Simulation

FORMAT = "granular-checkpoint"
FORMAT_VERSION = 1

# The Scene as stored: its arrays, and its other constructor keywords as JSON.  A new
# Scene parameter (e.g. a restitution law) is one more name in _SCENE_PARAMS, with a
# JSON-able value.
_SCENE_ARRAYS = ("positions", "velocities", "radii", "masses", "lower", "upper")
_SCENE_PARAMS = ("boundary", "wall_restitution", "restitution", "contact_duration")


# The largest speed the C restore accepts (csrc/checkpoint.c; granular/scene.py's limit).
_MAX_SPEED = 1e140


def _version() -> str:
    from . import __version__

    return __version__


def dumps(sim: Simulation) -> bytes:
    """The checkpoint of ``sim`` as the bytes of an ``.npz`` file (see ``Simulation.save``)."""
    _, vel, _ = sim._engine.state()
    if not np.all(np.abs(vel) <= _MAX_SPEED):
        raise CheckpointError(
            "this Simulation's velocities are not finite or beyond 1e140 (as a NonFiniteError "
            "or HeatedWallsError leaves them): the state cannot continue, so it is not saved"
        )
    state = np.frombuffer(sim._engine.save_state(), dtype=np.uint8)
    scene = sim._initial
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "granular_version": _version(),
        "layout": str(_core.CHECKPOINT_LAYOUT),
        "knobs": {k: v if isinstance(v, str) else float(v) for k, v in sim._knobs.items()},
        "scene": {name: describe(getattr(scene, name)) for name in _SCENE_PARAMS},
        "engine_state_sha256": hashlib.sha256(state).hexdigest(),
    }
    arrays = {f"scene_{name}": getattr(scene, name) for name in _SCENE_ARRAYS}
    buf = io.BytesIO()
    np.savez(buf, meta=np.array(json.dumps(meta)), engine_state=state, **arrays)
    return buf.getvalue()


def save(sim: Simulation, path: str | os.PathLike) -> None:
    """Write ``sim``'s checkpoint to ``path`` atomically (``write_atomic``): an older
    checkpoint at ``path`` survives until the new one is complete."""
    write_atomic(path, dumps(sim), suffix=".npz")


def write_atomic(path: str | os.PathLike, data: bytes, suffix: str = ".part") -> None:
    """Write ``data`` to ``path`` so that a crash mid-way never leaves a half file: into a
    temporary file (``.tmp-*``) in the same directory, flushed to disk, then renamed over
    ``path`` (a rename within a file system is atomic)."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=suffix, dir=folder)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load(path: str | os.PathLike) -> Simulation:
    """The Simulation saved in ``path`` (see ``Simulation.load``)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as exc:
        raise CheckpointError(f"cannot read the checkpoint {os.fspath(path)!r}: {exc}") from exc
    return loads(data, where=repr(os.fspath(path)))


def _read_npz(data: bytes, where: str) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}
        meta = json.loads(str(arrays.pop("meta")[()]))
    except (
        OSError,
        ValueError,
        EOFError,
        KeyError,
        TypeError,
        IndexError,
        zipfile.BadZipFile,
        json.JSONDecodeError,
    ) as exc:
        raise CheckpointError(
            f"{where} is not a granular checkpoint, or it is truncated or corrupt "
            f"({exc.__class__.__name__}: {exc})"
        ) from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise CheckpointError(f"{where} is not a granular checkpoint (no {FORMAT!r} header)")
    return meta, arrays


def loads(data: bytes, where: str = "the checkpoint") -> Simulation:
    """The Simulation in checkpoint bytes made by ``dumps`` (also what unpickling calls)."""
    from .simulation import Simulation

    meta, arrays = _read_npz(bytes(data), where)
    mine = (FORMAT_VERSION, _version(), str(_core.CHECKPOINT_LAYOUT))
    theirs = (meta.get("format_version"), meta.get("granular_version"), meta.get("layout"))
    if theirs != mine:
        raise CheckpointError(
            f"{where} was written by granular {theirs[1]} (checkpoint format {theirs[0]}, "
            f"engine layout {theirs[2]}); this is granular {mine[1]} (format {mine[0]}, "
            f"layout {mine[2]}).  A run continues bit for bit only in the version that saved "
            "it: load it there, or start afresh here from its scene (Simulation(old.scene))"
        )
    try:
        state = arrays["engine_state"]
        if state.dtype != np.uint8 or state.ndim != 1:
            raise ValueError("engine_state is not a byte array")
        if hashlib.sha256(state).hexdigest() != meta["engine_state_sha256"]:
            raise ValueError("the engine state does not match its checksum")
        fields = {name: arrays[f"scene_{name}"] for name in _SCENE_ARRAYS}
        params = {name: from_description(meta["scene"][name]) for name in _SCENE_PARAMS}
        knobs = meta["knobs"]
        scene = Scene(
            fields["positions"],
            fields["velocities"],
            fields["radii"],
            fields["masses"],
            box=(fields["lower"], fields["upper"]),
            **params,
        )
        sim = Simulation(scene, **knobs)
        sim._engine.restore_state(state)
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(f"{where} is corrupt: {exc}") from exc
    return sim
