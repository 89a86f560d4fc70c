"""Checkpoints: a Simulation's whole state in a file, continued bit for bit after loading.

A checkpoint is a NumPy ``.npz`` file (read without pickle: only arrays of numbers and one
string are accepted, so loading one runs no code) holding

- ``meta``: JSON with the format name and version, the granular version, the engine's
  state layout (``_core.CHECKPOINT_LAYOUT``), the engine knobs (``cell_factor``,
  ``big_ratio``, ``shell``), the scene's parameters and a SHA-256 of the engine state;
- ``scene_<name>``: the arrays of the scene the Simulation was built from (positions,
  velocities, radii, masses, box corners);
- ``engine_state``: the C engine's state as bytes (``csrc/checkpoint.h``): particle
  records at their own clocks, image and collision counters, predictions, the event
  queue as it stands, cell and neighbour lists, the renumbering, the time and every
  counter.

Reading takes only what the state needs: exactly these members, stored (np.savez does not
compress), each of the shape and size the scene's N and d give it, so that nothing is
inflated or allocated beyond the file's own size.  Loading builds an engine from the stored
scene and knobs (which rebuilds what follows from them: cell sizes, neighbour tables) and
restores the saved state into it; the C core checks every size, index, link and counter it
reads.  The state must then be one the run can be in (``_fault``): a valid Scene as it is
now, and its energy and momentum those its initial scene allows.  A file from another format
version, granular version or engine layout is refused, as is a truncated, corrupt or
crafted one, with a ``CheckpointError`` saying which.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import struct
import zipfile
from collections.abc import Callable
from typing import IO, Any, Protocol, TypeVar

import numpy as np

from . import _core
from ._files import check_kind, write_atomic
from ._npz import check_members, open_regular, read_header, read_member
from ._rough import rough_keeps_energy
from ._scene_params import PARAMETERS, shape_of
from .errors import CheckpointError, GranularError
from .restitution import TABLE_MAX, heats, loses_energy
from .scene import Scene
from .walls import describe, from_description


class _Run(Protocol):
    """What a checkpoint takes from a granular.Simulation and gives back (named here by
    what it offers: simulation imports this module, so this one does not import it)."""

    _initial: Scene
    _knobs: dict[str, Any]
    _engine: Any  # _core.EDMD

    @property
    def scene(self) -> Scene: ...

    @property
    def time(self) -> float: ...


_S = TypeVar("_S", bound=_Run)


FORMAT = "granular-checkpoint"
FORMAT_VERSION = 1

# The Scene as stored, as its declaration (granular/_scene_params.py) says: an array
# parameter as a member scene_<attribute> each (the box as its corners lower and upper),
# the others in the meta JSON (restitution.describe: numbers, strings and laws).
_SCENE_ARRAYS = tuple(a for p in PARAMETERS if p.is_array for a in p.fields)
_SCENE_PARAMS = tuple(p.name for p in PARAMETERS if not p.is_array)


# Collisions without heated walls never add kinetic energy, elastic ones keep it, and
# pair collisions keep the momentum -- up to rounding: about 1e-16 of the energy
# (momentum) per collision, of either sign, which drifted them by 2e-15 (1e-16 of the
# largest momentum) in 5e5 collisions of 500 particles.  At that rate 1e-6 is out of
# reach (even 1e10 collisions all rounding one way would only just reach it).  A state
# off by more than this relative tolerance is not one its initial scene could reach.
_CONSERVED_RTOL = 1e-6


def potential_energy(scene: Any) -> float:
    """The potential energy of ``scene``'s particles in its gravity, measured from the
    box's corner that g points to (so it is >= 0): sum of m g . (corner - x)."""
    g = scene.gravity
    if g is None:
        return 0.0
    corner = np.where(g > 0, scene.upper, scene.lower)
    return float(np.sum(scene.masses * ((corner - scene.positions) @ g)))


def _version() -> str:
    from . import __version__

    return __version__


def _fault(sim: _Run) -> str | None:
    """What makes ``sim``'s current state one its run cannot have reached or cannot go on
    from, or None: its positions and velocities must make a valid Scene (the scale limits,
    inside the walls, no overlaps: the checks of a new scene, scene.py and
    csrc/validate.c), and its energy and momentum must be those its initial scene allows."""
    try:
        now = sim.scene
    except (GranularError, ValueError) as exc:
        return f"its particles now are not a valid scene ({exc})"
    start = sim._initial
    # rough particles trade energy between translation and rotation: the total counts
    e0 = start.kinetic_energy + start.rotational_energy
    e = now.kinetic_energy + now.rotational_energy
    periodic = start.boundary == "periodic"
    if start.gravity is not None:
        # gravity: between walls the energy kept is kinetic + potential; in a freely
        # falling periodic box the motion relative to the fall (v - g t) is that of a gas
        # without gravity, so the same checks apply to it
        if periodic:
            fall = start.gravity * sim.time
            now = now.replace(velocities=now.velocities - fall, gravity=None, free_fall=False)
            e = now.kinetic_energy
        else:
            e0, e = (
                x.kinetic_energy + x.rotational_energy + potential_energy(x) for x in (start, now)
            )
    if start.shear_rate != 0.0:
        return _sheared_fault(sim, start, now)
    if start.vibrating_wall is not None:  # it heats: the energy must be its bookkeeping's
        c = sim._engine.counters()
        # (a random driving's kicks add their energy to the wall's work)
        work, loss = c["wall_work"] + c["drive_energy"], c["collision_loss"]
        scale = max(e0, e, abs(work), abs(loss))
        if not abs(e - e0 - (work - loss)) <= _CONSERVED_RTOL * scale:
            return (
                f"its kinetic energy {e:.6g} is not the initial {e0:.6g} plus the vibrating "
                f"wall's work {work:.6g} (with any kicks') less the collisions' loss {loss:.6g}"
            )
    # (a random driving force adds energy: no bound then)
    elif (periodic or not heats(start.wall_restitution)) and start.driving is None:
        if e > e0 * (1.0 + _CONSERVED_RTOL):
            return (
                f"its kinetic energy {e:.6g} exceeds the initial scene's {e0:.6g}, which "
                "collisions without heated walls cannot do"
            )
        elastic = (
            not loses_energy(start.restitution)
            and (periodic or not loses_energy(start.wall_restitution))
            and rough_keeps_energy(start)
        )
        if elastic and e < e0 * (1.0 - _CONSERVED_RTOL):
            return (
                f"its kinetic energy {e:.6g} is below the initial scene's {e0:.6g}, which "
                "elastic collisions keep"
            )
    if periodic:
        p0, p = (np.sum(x.masses[:, None] * x.velocities, axis=0) for x in (start, now))
        top = e0 if start.driving is None else max(e0, e)  # (driving: now's energy)
        scale = math.sqrt(2.0 * top * float(np.sum(start.masses)))  # |P| <= this
        drift = float(np.max(np.abs(p - p0)))
        if not drift <= _CONSERVED_RTOL * scale:
            return (
                f"its momentum differs from the initial scene's by {drift:.6g} (of a largest "
                f"possible {scale:.6g}), which collisions in a periodic box keep"
            )
    return None


def _sheared_fault(sim: _Run, start: Any, now: Any) -> str | None:
    """_fault's energy and momentum for a sheared box (csrc/boundary.h), whose images do
    work on the gas: the energy is the initial one plus that work (shear_work) less what
    the collisions dissipated, and x momentum changes by -u m at each crossing of the
    upper face (u = shear_rate L_y), so by -u sum(m img_y) in all."""
    counters = sim._engine.counters()
    # the engine's own energy: the state read out re-enters a particle due to cross a y
    # face now, with its velocity jump, before the crossing's work is counted
    # (a random driving's kicks add their energy to the boundary's work)
    work = float(counters["shear_work"]) + float(counters["drive_energy"])
    # (rough particles: rotation counts, and the images slide without turning)
    e = float(counters["kinetic_energy"]) + now.rotational_energy
    e0 = start.kinetic_energy + start.rotational_energy
    scale_e = max(e0, e, abs(work))
    if e > e0 + work + _CONSERVED_RTOL * scale_e:
        return (
            f"its kinetic energy {e:.6g} exceeds the initial scene's {e0:.6g} plus the work "
            f"of the sheared boundary {work:.6g}"
        )
    elastic = not loses_energy(start.restitution) and rough_keeps_energy(start)
    if elastic and e < e0 + work - _CONSERVED_RTOL * scale_e:
        return (
            f"its kinetic energy {e:.6g} is below the initial scene's {e0:.6g} plus the work "
            f"of the sheared boundary {work:.6g}, which elastic collisions keep"
        )
    img = sim._engine.state()[2]
    u = start.shear_rate * float(start.upper[1] - start.lower[1])
    p0, p = (np.sum(x.masses[:, None] * x.velocities, axis=0) for x in (start, now))
    p0[0] -= u * float(np.sum(start.masses * img[:, 1]))
    scale = math.sqrt(2.0 * max(e0, e) * float(np.sum(start.masses)))
    drift = float(np.max(np.abs(p - p0)))
    if not drift <= _CONSERVED_RTOL * scale:
        return (
            f"its momentum differs from the initial scene's less the sheared boundary's "
            f"jumps by {drift:.6g} (of a largest possible {scale:.6g})"
        )
    return None


def dumps(sim: _Run) -> bytes:
    """The checkpoint of ``sim`` as the bytes of an ``.npz`` file (see ``Simulation.save``)."""
    fault = _fault(sim)
    if fault:
        raise CheckpointError(
            f"this Simulation's state cannot continue, so it is not saved: {fault} (as a "
            "NonFiniteError or HeatedWallsError leaves it)"
        )
    state = np.frombuffer(sim._engine.save_state(), dtype=np.uint8)
    scene = sim._initial
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "granular_version": _version(),
        "layout": str(_core.CHECKPOINT_LAYOUT),
        "knobs": {k: v if isinstance(v, (str, bool)) else float(v) for k, v in sim._knobs.items()},
        "scene": {name: describe(getattr(scene, name)) for name in _SCENE_PARAMS},
        "engine_state_sha256": hashlib.sha256(state.data).hexdigest(),
    }
    # an unset array (gravity None) is stored as zeros, which its check reads as unset
    stored = {name: getattr(scene, name) for name in _SCENE_ARRAYS}
    arrays: dict[str, Any] = {
        f"scene_{name}": np.zeros(scene.dim) if a is None else a for name, a in stored.items()
    }
    buf = io.BytesIO()
    np.savez(buf, meta=np.array(json.dumps(meta)), engine_state=state, **arrays)
    return buf.getvalue()


def save(sim: _Run, path: str | os.PathLike) -> None:
    """Write ``sim``'s checkpoint to ``path`` atomically (``_files.write_atomic``): an older
    checkpoint at ``path`` survives until the new one is complete."""
    write_atomic(path, dumps(sim), suffix=".npz")


def load(path: str | os.PathLike, make: Callable[..., _S]) -> _S:
    """The Simulation saved in ``path`` (see ``Simulation.load``), built by
    ``make(scene, **knobs)`` (the Simulation class) and given the saved state."""
    where = repr(os.fspath(path))
    try:
        f = open_regular(path)
    except (FileNotFoundError, PermissionError):
        raise  # as open() and granular.read say it: not a fault of the file's content
    except OSError as exc:
        raise CheckpointError(f"cannot read the checkpoint {where}: {exc}") from exc
    except ValueError as exc:  # a device (/dev/zero), a pipe: no size to check, no end
        raise CheckpointError(
            f"{where} is {exc}: a checkpoint is a file written by Simulation.save"
        ) from exc
    with f:
        meta, arrays = _read_npz(f, where)
    return _build(meta, arrays, where, make)


# The members of a checkpoint's zip archive, each an .npy array.
_MEMBERS = ("meta", "engine_state", *(f"scene_{name}" for name in _SCENE_ARRAYS))
# The meta JSON, stored as a NumPy unicode string (4 bytes a character): at most two
# restitution tables of TABLE_MAX points, each number at most 24 characters and a
# separator, and a few kB besides.
_META_MAX_BYTES = 4 * (2 * 2 * TABLE_MAX * 26 + (1 << 16))
# What a damaged or crafted archive makes NumPy's and zipfile's readers raise.
_READ_ERRORS = (
    OSError,
    ValueError,
    EOFError,
    KeyError,
    TypeError,
    IndexError,
    OverflowError,
    NotImplementedError,  # an unknown compression method
    RuntimeError,  # an encrypted member; RecursionError (deeply nested JSON) is one too
    struct.error,
    zipfile.BadZipFile,
)


def _read_npz(
    f: IO[bytes] | bytes | bytearray | memoryview, where: str
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """(meta, arrays) from the checkpoint in the binary file ``f`` (or bytes); what is
    read is bounded by the file's size and the sizes the state's arrays must have."""
    if isinstance(f, (bytes, bytearray, memoryview)):
        f = io.BytesIO(f)
    if check_kind(f, "npz", CheckpointError, where) is None:
        raise CheckpointError(
            f"{where} is not a granular checkpoint: it is neither a zip archive nor a GSD "
            "file.  Simulation.load reads the checkpoints Simulation.save writes"
        )
    try:
        with zipfile.ZipFile(f) as zf:
            return _read_members(zf, f, where)
    except CheckpointError:
        raise
    except _READ_ERRORS as exc:
        raise CheckpointError(
            f"{where} is not a granular checkpoint, or it is truncated or corrupt "
            f"({exc.__class__.__name__}: {exc})"
        ) from exc


def _read_members(zf, f, where):
    size = f.seek(0, os.SEEK_END)
    names = check_members(zf, size)
    if "meta.npy" not in names:
        raise CheckpointError(f"{where} is not a granular checkpoint (no {FORMAT!r} header)")
    meta = json.loads(str(read_member(zf, names["meta.npy"], "U", (), _META_MAX_BYTES)[()]))
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise CheckpointError(f"{where} is not a granular checkpoint (no {FORMAT!r} header)")
    _check_version(meta, where)
    want = {f"{name}.npy" for name in _MEMBERS}
    if set(names) != want:
        raise ValueError(
            f"its members are {sorted(names)}; a checkpoint holds exactly {sorted(want)}"
        )
    # the sizes of the scene's arrays follow from its positions' (N, d); the engine
    # state's size from its own header, which must agree with them
    with zf.open(names["scene_positions.npy"]) as fp:
        n_d, _, _ = read_header(fp, "scene_positions.npy")
    if len(n_d) != 2 or n_d[1] not in (2, 3) or n_d[0] < 1:
        raise ValueError(f"its scene positions have shape {n_d}, not (N, 2) or (N, 3)")
    n, d = n_d
    f8 = np.dtype(np.float64)  # native, as np.savez wrote the Scene's arrays
    shapes = {a: shape_of(p, n, d) for p in PARAMETERS if p.is_array for a in p.fields}
    arrays = {
        f"scene_{name}": read_member(zf, names[f"scene_{name}.npy"], f8, shape)
        for name, shape in shapes.items()
    }

    def check_head(head, nbytes):
        # csrc/checkpoint.c's header: magic 8, version 4, byte order 4, layout 8, then
        # the total size (uint64), n (int64) and dim (int32)
        if len(head) < 44:
            raise ValueError("its engine state is truncated")
        total, n_state, d_state = struct.unpack_from("=Qqi", head, 24)
        if (total, n_state, d_state) != (nbytes, n, d):
            raise ValueError(
                f"its engine state's header says {total} bytes, N = {n_state}, d = "
                f"{d_state}; the state has {nbytes} bytes and the scene N = {n}, d = {d}"
            )

    state = names["engine_state.npy"]
    arrays["engine_state"] = read_member(zf, state, np.dtype("u1"), (None,), check_head=check_head)
    return meta, arrays


def _check_version(meta: dict, where: str) -> None:
    mine = (FORMAT_VERSION, _version(), str(_core.CHECKPOINT_LAYOUT))
    theirs = (meta.get("format_version"), meta.get("granular_version"), meta.get("layout"))
    if theirs != mine:
        raise CheckpointError(
            f"{where} was written by granular {theirs[1]} (checkpoint format {theirs[0]}, "
            f"engine layout {theirs[2]}); this is granular {mine[1]} (format {mine[0]}, "
            f"layout {mine[2]}).  A run continues bit for bit only in the version that saved "
            "it: load it there, or start afresh here from its scene (Simulation(old.scene))"
        )


def loads(data: bytes, make: Callable[..., _S], where: str = "the checkpoint") -> _S:
    """The Simulation in checkpoint bytes made by ``dumps`` (also what unpickling calls),
    built by ``make`` as in ``load``."""
    meta, arrays = _read_npz(bytes(data), where)
    return _build(meta, arrays, where, make)


def _build(
    meta: dict[str, Any],
    arrays: dict[str, np.ndarray],
    where: str,
    make: Callable[..., _S],
) -> _S:
    """The Simulation of a checkpoint's parts, read and checked for their sizes."""
    try:
        state = arrays["engine_state"]
        if hashlib.sha256(state.data).hexdigest() != meta["engine_state_sha256"]:
            raise ValueError("the engine state does not match its checksum")
        # the arrays; the boundary's string, numbers and laws: Any, to be checked by Scene
        params: dict[str, Any] = {
            p.name: tuple(arrays[f"scene_{a}"] for a in p.fields)
            if p.attributes
            else arrays[f"scene_{p.name}"]
            for p in PARAMETERS
            if p.is_array
        }
        params.update({name: from_description(meta["scene"][name]) for name in _SCENE_PARAMS})
        knobs = meta["knobs"]
        scene = Scene(**params)
        sim = make(scene, **knobs)
        sim._engine.restore_state(state)
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise CheckpointError(f"{where} is corrupt: {exc}") from exc
    fault = _fault(sim)
    if fault:
        raise CheckpointError(f"{where} is corrupt: {fault}")
    return sim
