"""Trajectories to and from GSD files (HOOMD-blue's format, read by OVITO, freud, HOOMD and
MDAnalysis): ``Trajectory.write("run.gsd")``, ``granular.read("run.gsd")`` and
``Scene.from_gsd("run.gsd", frame=-1)``.  Needs the ``gsd`` package
(``pip install 'granular[gsd]'``).

Files are written whole or not at all (beside the path, then renamed onto it), with the
permissions a plain ``open()`` gives (0o666 less the umask).  Reading checks every frame
as a Scene is checked and refuses a damaged or impossible file with ``GSDFileError``.

What each frame holds.  The HOOMD schema fixes the standard fields to float32, so these are
for viewers and analysis tools (OVITO, freud, MDAnalysis), good to about 7 digits:

- ``particles/position``: positions wrapped into the box, which GSD centres at the origin
  (position - box centre, in [-L/2, L/2]); disks lie in the plane z = 0
- ``particles/image`` (int32): periodic image flags, unwrapped = position + image * L
  (always 0 in a walled box)
- ``particles/velocity``, ``particles/diameter``, ``particles/mass``
- ``configuration/box`` and ``configuration/dimensions``; ``configuration/step`` = the
  sample's index
- a sheared box (``shear_rate`` != 0, docs/shear.md): the box's tilt ``xy = delta / L_y``
  at the sample's time (HOOMD's lattice vector a2 = (xy L_y, L_y, 0), delta the x offset
  of the image across the upper y face, in [-L_x/2, L_x/2)), positions inside that
  triclinic box and images through its lattice vectors; reading back, the exact unwrapped
  positions come into the box through the sliding images and the Scene of a frame gets
  the offset at its time
- 2D: ``configuration/dimensions`` = 2 and a box ``[Lx, Ly, max(Lx, Ly), 0, 0, 0]``.
  HOOMD itself writes Lz = 0 in 2D, but its readers take ``dimensions`` = 2 first and set
  Lz to 0 themselves (as for HOOMD 2's files, which kept an Lz), and gsd.hoomd does too;
  MDAnalysis reads the box as it stands, and an Lz of 0 is a volume of 0, which its
  analyses divide by.  So MDAnalysis gets the box ``Trajectory.to_universe`` gives (see
  ``granular.interop``).  freud: ``freud.box.Box.from_box(box, dimensions=2)`` (it warns
  that the Lz has no effect).

The exact float64 (and int64) values granular reads back live in the log section:

- every frame: ``log/granular/time`` (the real sample time), ``log/granular/unwrapped_positions``
  and ``log/granular/velocities`` (float64, (N, d)), and the counters ``kinetic_energy``,
  ``momentum``, ``pair_collisions``, ``wall_collisions``, ``virial``, ``wall_impulse``;
  from a ``Simulation(stress=True)`` run also the stress tensor's parts
  ``stress_collisional``, ``kinetic_time_tensor``, ``kinetic_tensor`` (float64, (d, d)), and
  HOOMD's ``md/compute/ThermodynamicQuantities/pressure_tensor`` (xx, xy, xz, yy, yz, zz,
  float64, zeros for z in 2D): the pressure tensor averaged over the window since the
  previous frame (EDMD's collisional stress is impulses: an instant between collisions has
  only the kinetic part, which is what frame 0, with no window, carries); with a vibrating
  wall also its books ``wall_work`` and ``collision_loss`` (float64, cumulative, as the
  Trajectory's)
- frame 0: ``stop_reason`` (UTF-8 bytes), ``format`` (this layout's version), and every
  parameter of the run's scene but the positions and velocities (``_scene_params``'s
  ``RUN_PARAMETERS``), each attribute the Scene keeps it in under its own name: ``lower``,
  ``upper``, ``radii``, ``masses``, ``boundary``, ``wall_restitution``, ``restitution``,
  ``contact_duration``, ... .  Arrays and numbers are float64 (a number of shape (1,)), a
  string UTF-8 bytes, a restitution law or a vibrating wall the UTF-8 bytes of its JSON
  description (``walls.describe``, as checkpoints store it; no vibrating wall: no field).
  They are written and read by iterating the declaration, each read back through its
  declared check: a parameter declared later needs no change here, and a file without it
  (written before) reads with its default.  Layout 1 from the start: the parameters after
  ``boundary`` were added beside the fields earlier readers read, and they read these files
  still.

Rough particles (a trajectory that stored ``angular_velocities``): ``particles/angmom`` and
``particles/moment_inertia`` in HOOMD's convention, without orientations (every
``particles/orientation`` stays the identity quaternion (1, 0, 0, 0), so the body frame is
the box's): HOOMD stores angular momentum as the quaternion P = 2 q x (0, S) conjugate to
the orientation q (Kamberaj 2005; HOOMD's "Anisotropic particles" page), S the angular
momentum in the body frame, so here P = (0, 2 I w).  ``moment_inertia`` holds the principal
moments (I, I, I) of a sphere and (0, 0, I) of a disk, which rotates about z only (HOOMD
integrates no axis of moment 0); I = q m r^2.  The exact spins are in the log,
``log/granular/angular_velocities`` (float64, (N,) in 2D, (N, 3) in 3D), with
``log/granular/rotational_energy`` every frame.  ``Scene.from_gsd`` of a HOOMD file takes its
spins from ``angmom``, ``orientation`` and ``moment_inertia`` (the box frame's angular
velocity, by the same convention) and its inertia factor when all particles share one.

(gsd >= 4 can write the HOOMD fields in float64, but OVITO and older gsd and HOOMD read
float32 ones: the standard fields stay float32 and the exact values go in the log.)

So ``granular.read`` gives back a Trajectory equal, array for array, to the one written.  For
other formats (extended XYZ, TRR, DCD, ...) go through MDAnalysis: ``Trajectory.to_universe()``
and its writers.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from . import _shear
from ._files import atomic_target, check_kind
from ._scene_params import REQUIRED, RUN_PARAMETERS, shape_of, spin_shape, split
from .driving import PairThermostat, WhiteNoise
from .errors import GSDFileError
from .interop import box_lengths_3d
from .walls import describe, from_description, is_described

FORMAT = 1  # the version of the log layout above
_COUNTERS = (
    "kinetic_energy",
    "momentum",
    "pair_collisions",
    "wall_collisions",
    "virial",
    "wall_impulse",
)
_INT_COUNTERS = ("pair_collisions", "wall_collisions")
# the log's own names beside the scene parameters' (which may not take one of them:
# tests/test_scene_params.py checks)
# the stress tensor's parts ((d, d) each), present from a Simulation(stress=True) run only
_TENSORS = ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor")
_HOOMD_PRESSURE_TENSOR = "md/compute/ThermodynamicQuantities/pressure_tensor"
# a vibrating wall's books (one number each), present from a run with such a wall only
_WALL_BOOKS = ("wall_work", "collision_loss")
LOG_NAMES = (
    "format", "stop_reason", "time", "unwrapped_positions", "velocities",
    "angular_velocities", "rotational_energy", *_COUNTERS, *_TENSORS, *_WALL_BOOKS
)  # fmt: skip


def _gsd():
    """The gsd package, with its modules gsd.hoomd (frames, for writing) and gsd.fl (chunks,
    for reading)."""
    try:
        import gsd.fl
        import gsd.hoomd
    except ImportError as exc:
        raise ImportError(
            "GSD files need the gsd package: pip install gsd (or pip install 'granular[gsd]')"
        ) from exc
    return gsd


def _check_suffix(path: str | os.PathLike) -> Path:
    path = Path(path)
    if path.suffix.lower() != ".gsd":
        raise ValueError(
            f"{str(path)!r}: granular writes and reads GSD files only (suffix .gsd); for XYZ, "
            "TRR, DCD and the other formats use MDAnalysis' writers on "
            "Trajectory.to_universe()"
        )
    return path


def _text(value: str) -> np.ndarray:
    return np.frombuffer(value.encode("utf-8"), dtype=np.uint8).copy()


def _encode(value: Any) -> np.ndarray:
    """A scene parameter's value as a log chunk: an array or a number as float64 (a number
    of shape (1,)), a string as its UTF-8 bytes, a restitution law as the UTF-8 bytes of
    its JSON description (``restitution.describe``, as checkpoints store it)."""
    if isinstance(value, str):
        return _text(value)
    # a restitution law, a vibrating wall or a random driving
    if is_described(value) or isinstance(value, WhiteNoise | PairThermostat):
        return _text(json.dumps(describe(value)))
    return np.atleast_1d(np.asarray(value, dtype=np.float64))


def _wrap(
    positions: np.ndarray, lower: np.ndarray, upper: np.ndarray, periodic: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Positions wrapped into [lower, upper) and their integer images, float64:
    positions == wrapped + images * (upper - lower) up to rounding."""
    x = np.asarray(positions, dtype=np.float64)
    lengths = upper - lower
    if not periodic:
        return x.copy(), np.zeros(x.shape, dtype=np.int64)
    images = np.floor((x - lower) / lengths).astype(np.int64)
    wrapped = x - images * lengths
    # rounding can leave a centre one ulp outside [lower, upper)
    high = wrapped >= upper
    low = wrapped < lower
    wrapped = np.where(high, wrapped - lengths, np.where(low, wrapped + lengths, wrapped))
    images = images + high - low
    return wrapped, images


def _pad3(a, dtype=np.float32):
    a = np.asarray(a)
    if a.shape[-1] == 2:
        a = np.concatenate([a, np.zeros((*a.shape[:-1], 1), dtype=a.dtype)], axis=-1)
    return np.ascontiguousarray(a, dtype=dtype)


def _frame(hoomd, traj, k, lower, upper):
    """Sample ``k`` of ``traj`` as a HOOMD frame (see the module docstring for the fields)."""
    centre = 0.5 * (lower + upper)
    periodic = traj.boundary == "periodic"
    half = (0.5 * (upper - lower)).astype(np.float32)
    n = traj.n
    frame = hoomd.Frame()
    frame.configuration.step = k
    frame.configuration.box = [*box_lengths_3d(upper - lower), 0.0, 0.0, 0.0]
    frame.configuration.dimensions = traj.dim
    frame.particles.N = n
    frame.particles.types = ["A"]
    frame.particles.typeid = np.zeros(n, dtype=np.uint32)
    x = traj.positions[k]
    wrapped, images = _wrap(x, lower, upper, periodic)
    position = (wrapped - centre).astype(np.float32)
    rate = traj.scene_parameters.get("shear_rate", 0.0)
    if rate != 0.0:
        tilt, position, images = _sheared_frame(traj, k, lower, upper)
        frame.configuration.box = [*box_lengths_3d(upper - lower), tilt, 0.0, 0.0]
    elif periodic:
        # a centre just under the upper face can round to +L/2 in float32, outside
        # HOOMD's [-L/2, L/2): move it to -L/2 and count the image
        high = position >= half
        position = np.where(high, -half, position)
        images = images + high
    frame.particles.position = _pad3(position)
    frame.particles.image = _pad3(images, np.int32)
    frame.particles.diameter = np.asarray(2.0 * traj.radii, dtype=np.float32)
    frame.particles.mass = np.asarray(traj.masses, dtype=np.float32)
    log = {
        "granular/time": np.array([traj.times[k]], dtype=np.float64),
        "granular/unwrapped_positions": np.ascontiguousarray(x, dtype=np.float64),
    }
    if traj.velocities is not None:
        frame.particles.velocity = _pad3(traj.velocities[k])
        log["granular/velocities"] = np.ascontiguousarray(traj.velocities[k], dtype=np.float64)
    if traj.angular_velocities is not None:
        _spin_fields(frame, log, traj, k)
    if traj.rotational_energy is not None:
        log["granular/rotational_energy"] = np.array([traj.rotational_energy[k]], np.float64)
    for name in _COUNTERS:
        dtype = np.int64 if name in _INT_COUNTERS else np.float64
        log[f"granular/{name}"] = np.atleast_1d(np.asarray(getattr(traj, name)[k], dtype))
    if traj.stress_collisional is not None:
        for name in _TENSORS:
            log[f"granular/{name}"] = np.ascontiguousarray(getattr(traj, name)[k], np.float64)
        log[_HOOMD_PRESSURE_TENSOR] = _hoomd_pressure_tensor(traj, k)
    for name in _WALL_BOOKS:
        books = getattr(traj, name, None)
        if books is not None:
            log[f"granular/{name}"] = np.array([books[k]], dtype=np.float64)
    if k == 0:
        log["granular/format"] = np.array([FORMAT], dtype=np.int64)
        log["granular/stop_reason"] = _text(traj.stop_reason)
        params = traj.scene_parameters
        for p in RUN_PARAMETERS:
            for field, value in split(p, params[p.name]).items():
                if value is None:  # an absent option (no driving, no vibrating wall)
                    continue
                log[f"granular/{field}"] = _encode(value)
    frame.log = log
    return frame


def _sheared_frame(traj, k, lower, upper):
    """A sheared box (csrc/boundary.h) at sample k as HOOMD draws it: the tilt xy =
    delta / L_y of the lattice vector a2 = (xy L_y, L_y, 0) (the image across the upper y
    face displaced by delta, taken in [-L_x/2, L_x/2)), the positions (float32) inside that
    triclinic box centred at the origin, and the images that unwrap them there
    (unwrapped = position + i_x a1 + i_y a2 + i_z a3)."""
    p = traj.scene_parameters
    lengths = upper - lower
    lx, ly = float(lengths[0]), float(lengths[1])
    delta = _shear.offset(p["shear_rate"], p["shear_offset"], lx, ly, float(traj.times[k]))
    delta = delta - lx if delta >= 0.5 * lx else delta
    x, img = _shear.wrap(
        traj.positions[k], lower, upper, p["shear_rate"], p["shear_offset"], float(traj.times[k])
    )
    c = x - 0.5 * (lower + upper)
    # unwrapped x = x + img_x L_x + img_y D, D = delta + m L_x: HOOMD's i_x takes m img_y,
    # and the shift that brings x - xy y into [-L_x/2, L_x/2)
    D = _shear.total_offset(p["shear_rate"], p["shear_offset"], ly, float(traj.times[k]))
    m = np.round((D - delta) / lx)
    shift = np.floor((c[:, 0] - delta / ly * c[:, 1]) / lx + 0.5)
    c[:, 0] -= shift * lx
    img[:, 0] = img[:, 0] + (m * img[:, 1]).astype(np.int64) + shift.astype(np.int64)
    return delta / ly, c.astype(np.float32), img


def _hoomd_pressure_tensor(traj, k):
    """HOOMD's six components (xx, xy, xz, yy, yz, zz) of the pressure tensor at frame k:
    averaged over the window since frame k - 1; frame 0 the kinetic part alone."""
    p = np.zeros((3, 3))
    d = traj.dim
    if k == 0:
        p[:d, :d] = traj.kinetic_pressure_tensor()[0]
    else:
        p[:d, :d] = traj.pressure_tensor(per_window=True)[k - 1]
    return np.array([p[0, 0], p[0, 1], p[0, 2], p[1, 1], p[1, 2], p[2, 2]])


def _spin_fields(frame, log, traj, k):
    """Rough particles' spins of sample ``k``: HOOMD's angmom and moment_inertia (module
    docstring), the exact values in the log."""
    w = np.asarray(traj.angular_velocities[k], dtype=np.float64)
    q = float(traj.scene_parameters["inertia_factor"])
    inertia = q * np.asarray(traj.masses) * np.asarray(traj.radii) ** 2
    w3 = np.zeros((traj.n, 3))
    if traj.dim == 2:
        w3[:, 2] = w
        moments = np.zeros((traj.n, 3))
        moments[:, 2] = inertia
    else:
        w3[:] = w
        moments = np.repeat(inertia[:, None], 3, axis=1)
    angmom = np.zeros((traj.n, 4))
    angmom[:, 1:] = 2.0 * inertia[:, None] * w3  # P = 2 q x (0, I w), q = 1
    frame.particles.angmom = angmom.astype(np.float32)
    frame.particles.moment_inertia = moments.astype(np.float32)
    log["granular/angular_velocities"] = np.ascontiguousarray(w)


def write(traj: Any, path: str | os.PathLike) -> None:
    """Write a Trajectory to a GSD file (see the module docstring for the fields).

    The file is written beside ``path`` and renamed onto it when complete, so an error or an
    interruption never leaves a half-written file (an older file at ``path`` survives); it
    gets the permissions a plain ``open()`` would give it (0o666 less the umask, or those of
    the file it replaces).

    Parameters
    ----------
    traj : Trajectory
        With stored positions (velocities are written when stored).
    path : str or os.PathLike
        Ending in ``.gsd``.
    """
    path = _check_suffix(path)
    if traj.positions is None:
        raise ValueError(
            "this trajectory did not store positions, which a GSD file needs; run with "
            "store including 'positions' (and 'velocities')"
        )
    hoomd = _gsd().hoomd
    lower = np.asarray(traj.lower, dtype=np.float64)
    upper = np.asarray(traj.upper, dtype=np.float64)
    # gsd creates its files 0o660 less the umask, but keeps the mode of one it truncates
    with atomic_target(path, ".gsd") as tmp, hoomd.open(name=tmp, mode="w") as f:
        for k in range(len(traj.times)):
            f.append(_frame(hoomd, traj, k, lower, upper))


class _File:
    """A GSD file open for reading chunk by chunk (gsd.fl).  Only the chunks asked for are
    read (gsd.hoomd's frames would allocate every standard field for the N a frame claims,
    whatever the file holds), and all of them together no more than twice the file's size:
    each chunk lies inside the file (gsd checks) and a sound file stores each once, so more
    is a corrupt index whose chunks overlap."""

    def __init__(self, path: str | os.PathLike) -> None:
        check_kind(path, "gsd", GSDFileError)  # a checkpoint or another .npz: say what reads it
        self.path = _check_suffix(path)
        if not self.path.is_file():
            raise FileNotFoundError(f"no GSD file at {str(self.path)!r}")
        self.where = repr(str(self.path))
        # a sound file's chunks, each read once (frame 0's positions twice), fit in it twice
        self._budget = 2 * self.path.stat().st_size
        fl = _gsd().fl
        try:
            self._f = fl.open(name=str(self.path), mode="r")
        except (PermissionError, FileNotFoundError):
            raise
        except (OSError, RuntimeError, ValueError, MemoryError, UnicodeError) as exc:
            raise GSDFileError(f"{self.where} is not a readable GSD file: {exc}") from exc
        self.frames = int(self._f.nframes)

    def __enter__(self) -> _File:
        return self

    def __exit__(self, *exc: Any) -> None:
        self._f.close()

    def error(self, frame: int, name: str, what: str) -> GSDFileError:
        return GSDFileError(f"{self.where}, frame {frame}: {name} {what}")

    def has(self, frame: int, name: str) -> bool:
        return bool(self._f.chunk_exists(frame=frame, name=name))

    def raw(self, frame: int, name: str) -> np.ndarray:
        """Chunk ``name`` of ``frame`` as stored (GSDFileError if missing or unreadable)."""
        if not self.has(frame, name):
            raise self.error(frame, name, "is missing")
        try:
            a = self._f.read_chunk(frame=frame, name=name)
        except (OSError, RuntimeError, ValueError, KeyError, MemoryError) as exc:
            raise self.error(frame, name, f"cannot be read ({exc})") from exc
        self._budget -= a.nbytes
        if self._budget < 0:
            raise self.error(
                frame, name, "takes the data read past twice the file's size: its index is corrupt"
            )
        return a

    def array(self, frame: int, name: str, shape: tuple, integer: bool = False) -> np.ndarray:
        """Chunk ``name`` of ``frame`` as float64 (int64 if ``integer``) of ``shape``."""
        a = self.raw(frame, name)
        if a.dtype.kind not in ("iu" if integer else "fiu"):
            kind = "integers" if integer else "numbers"
            raise self.error(frame, name, f"holds {a.dtype} values, not {kind}")
        if a.shape != shape:
            raise self.error(frame, name, f"has shape {a.shape}, expected {shape}")
        return a.astype(np.int64 if integer else np.float64)

    def text(self, frame: int, name: str) -> str:
        a = self.raw(frame, name)
        if a.dtype.kind not in "iu" or a.dtype.itemsize != 1 or a.ndim != 1:
            raise self.error(frame, name, f"is not text (a {a.dtype} array of shape {a.shape})")
        try:
            return bytes(a.astype(np.uint8)).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise self.error(frame, name, f"is not UTF-8 text ({exc})") from exc


def _log(name: str) -> str:
    return f"log/granular/{name}"


def _params(f: _File) -> tuple[dict[str, Any], str]:
    """The run's scene parameters (``{name: value as the Scene keeps it}``) and the stop
    reason, from frame 0 of a file granular wrote; each parameter checked by its declared
    check (GSDFileError naming the field).  A parameter the file lacks, from a granular
    that did not declare it yet, has its default (what that granular's runs used)."""
    if not f.has(0, _log("format")):
        raise GSDFileError(
            f"{f.where} was not written by granular (no log/granular/format); read it "
            "with gsd.hoomd.open, or take one frame with Scene.from_gsd"
        )
    version = int(f.array(0, _log("format"), (1,), integer=True)[0])
    if not 1 <= version <= FORMAT:
        raise GSDFileError(
            f"{f.where} has granular GSD layout {version}, this version reads layouts 1 to "
            f"{FORMAT}" + (": it was written by a newer granular" if version > FORMAT else "")
        )
    # the particles and dimensions are those of frame 0's positions; every other array must
    # agree with them
    x0 = f.raw(0, _log("unwrapped_positions"))
    if x0.ndim != 2 or x0.shape[0] < 1 or x0.shape[1] not in (2, 3):
        raise f.error(
            0, _log("unwrapped_positions"), f"has shape {x0.shape}, expected (N, 2) or (N, 3)"
        )
    n, d = x0.shape
    params: dict[str, Any] = {}
    for p in RUN_PARAMETERS:
        names = [_log(field) for field in p.fields]
        if p.default is not REQUIRED and not any(f.has(0, name) for name in names):
            params[p.name] = p.check(p.default, n, d)
            continue
        if p.is_array:
            parts = tuple(f.array(0, name, shape_of(p, n, d)) for name in names)
            value = parts if p.attributes else parts[0]
        else:
            value = _decode(f, names[0], p.default)
        try:
            params[p.name] = p.check(value, n, d)
        except (ValueError, TypeError, OverflowError) as exc:
            raise f.error(0, " and ".join(names), f"is not a valid {p.name}: {exc}") from exc
    return params, f.text(0, _log("stop_reason"))


def _decode(f: _File, name: str, default: Any) -> Any:
    """A parameter that is not an array, as ``_encode`` wrote it in frame 0: a number
    (float64 of shape (1,)), a string or a restitution law's JSON description (text)."""
    a = f.raw(0, name)
    if not isinstance(default, str) and not (a.dtype.kind in "iu" and a.dtype.itemsize == 1):
        return f.array(0, name, (1,))[0]  # not text: a number
    text = f.text(0, name)
    if not text.startswith("{"):
        if not isinstance(default, str):
            raise f.error(0, name, f"is the text {text[:40]!r}, not a number or a law")
        return text
    try:
        return from_description(json.loads(text))
    except (ValueError, TypeError, RecursionError) as exc:
        kind = "vibrating wall's" if name.endswith("vibrating_wall") else "restitution law's"
        raise f.error(0, name, f"is not a {kind} description ({exc})") from exc


def _wrap_checked(f: _File, k: int, x: np.ndarray, p: dict[str, Any]) -> np.ndarray:
    """Unwrapped positions of frame ``k`` wrapped into a periodic box (as they are in a
    walled one).  Positions that are not finite are left for Scene to refuse (it names
    what is wrong); positions so far out that float64 cannot wrap them are refused."""
    lower, upper = p["box"]
    with np.errstate(all="ignore"):
        if p["boundary"] != "periodic" or not np.all(np.isfinite(x)):
            return x  # Scene refuses what is not sound, and says why
        boxes = np.max(np.abs((x - lower) / (upper - lower)))
    if not boxes < 2.0**53:
        raise f.error(
            k,
            _log("unwrapped_positions"),
            f"reaches {boxes:.3g} box lengths from the box: float64 cannot wrap it back",
        )
    return _wrap(x, lower, upper, True)[0]


def _scene(
    f: _File,
    k: int,
    x: np.ndarray,
    v: np.ndarray,
    p: dict[str, Any],
    make_scene: Any,
    t: float = 0.0,
    w: np.ndarray | None = None,
) -> Any:
    """Frame ``k``'s state (at time ``t``) as a Scene (``make_scene``: the Scene class) with
    the run's parameters ``p`` (and spins ``w``, if the file has them), which checks it as
    every scene is checked (finite, the scales, inside the box, no overlaps).  A sheared
    box's (csrc/boundary.h) positions are brought into the box through its images at t, and
    the Scene gets the offset then.  A vibrating wall's phase is moved on to the frame's
    time (``VibratingWall.at_time``: where the wall was then)."""
    if p.get("shear_rate", 0.0) != 0.0 and np.all(np.isfinite(x)):
        lower, upper = p["box"]
        rate, d0 = p["shear_rate"], p["shear_offset"]
        lx, ly = float(upper[0] - lower[0]), float(upper[1] - lower[1])
        x = _shear.wrap(
            _wrap_checked(f, k, x, {**p, "boundary": "walls"}), lower, upper, rate, d0, t
        )[0]
        p = {**p, "shear_offset": _shear.offset(rate, d0, lx, ly, t)}
    x = _wrap_checked(f, k, x, p)
    if p.get("vibrating_wall") is not None:
        p = {**p, "vibrating_wall": p["vibrating_wall"].at_time(f.array(k, _log("time"), (1,))[0])}
    try:
        if w is not None:
            return make_scene(x, v, angular_velocities=w, **p)
        return make_scene(x, v, **p)
    except (ValueError, TypeError) as exc:
        raise GSDFileError(f"{f.where}, frame {k}: not a valid state: {exc}") from exc


def read(path: str | os.PathLike, make_scene: Any, make_trajectory: Any) -> Any:
    """The Trajectory (``make_trajectory``: the Trajectory class) in a GSD file written by
    ``Trajectory.write``, each frame checked as a Scene (``make_scene``); see
    ``granular.read``, which calls this.  Passed the classes, this module imports neither
    scene nor trajectory (which import it)."""
    with _File(path) as f:
        if f.frames == 0:
            raise GSDFileError(f"{f.where} holds no frames")
        p, stop_reason = _params(f)
        n, d = len(p["radii"]), len(p["box"][0])
        has_v = f.has(0, _log("velocities"))
        has_w = f.has(0, _log("angular_velocities"))  # rough particles' spins
        has_rot = f.has(0, _log("rotational_energy"))
        spins: list[np.ndarray] = []
        rotational: list[float] = []
        still = np.zeros((n, d))
        times: list[float] = []
        positions: list[np.ndarray] = []
        velocities: list[np.ndarray] = []
        counters: dict[str, list] = {name: [] for name in _COUNTERS}
        stress = f.has(0, _log("stress_collisional"))
        tensors: dict[str, list] = {name: [] for name in _TENSORS} if stress else {}
        books: dict[str, list] = {name: [] for name in _WALL_BOOKS if f.has(0, _log(name))}
        for k in range(f.frames):
            t = f.array(k, _log("time"), (1,))[0]
            if not np.isfinite(t):
                raise f.error(k, _log("time"), f"is {t}, not a finite time")
            if times and not t > times[-1]:
                raise f.error(
                    k,
                    _log("time"),
                    f"is {t}, not after frame {k - 1}'s {times[-1]}: sample times must increase",
                )
            times.append(t)
            x = f.array(k, _log("unwrapped_positions"), (n, d))
            v = still
            if has_v:
                v = f.array(k, _log("velocities"), (n, d))
                velocities.append(v)
            elif f.has(k, _log("velocities")):
                raise f.error(k, _log("velocities"), "is there but frame 0 has none")
            w = f.array(k, _log("angular_velocities"), spin_shape(n, d)) if has_w else None
            if w is not None:
                spins.append(w)
            if has_rot:
                e = f.array(k, _log("rotational_energy"), (1,))[0]
                if not (np.isfinite(e) and e >= 0):
                    raise f.error(k, _log("rotational_energy"), f"is {e}, not finite and >= 0")
                rotational.append(float(e))
            _scene(f, k, x, v, p, make_scene, t, w)
            positions.append(x)
            for name in _COUNTERS:
                value = _counter(f, k, name, d, counters[name])
                counters[name].append(value)
            for name in tensors:
                tensor = f.array(k, _log(name), (d, d))
                if not np.all(np.isfinite(tensor)):
                    raise f.error(k, _log(name), "contains NaN or infinity")
                tensors[name].append(tensor)
            for name in books:
                value = f.array(k, _log(name), (1,))[0]
                if not np.isfinite(value):
                    raise f.error(k, _log(name), f"is {value}, not finite")
                books[name].append(value)
    # the counters' keywords: arrays of floats or of counts (Any: mypy would match them
    # against every keyword of Trajectory, its strings too)
    arrays: dict[str, Any] = {name: np.array(values) for name, values in counters.items()}
    arrays.update({name: np.array(values).reshape(-1, d, d) for name, values in tensors.items()})
    arrays.update({name: np.array(values, dtype=np.float64) for name, values in books.items()})
    return make_trajectory(
        np.array(times),
        np.array(positions).reshape(len(times), n, d),
        np.array(velocities).reshape(len(times), n, d) if has_v else None,
        **arrays,
        # the scene's fields the Trajectory keeps as its own (radii, masses, the box's
        # corners, the boundary: the same rule as Trajectory's), and all of its parameters
        **{
            field: value
            for q in RUN_PARAMETERS
            for field, value in split(q, p[q.name]).items()
            if field in make_trajectory.__annotations__
        },
        stop_reason=stop_reason,
        parameters=p,
        angular_velocities=np.array(spins).reshape(len(times), *spin_shape(n, d))
        if has_w
        else None,
        rotational_energy=np.array(rotational) if has_rot else None,
    )


def _counter(f: _File, k: int, name: str, d: int, before: list) -> Any:
    """Frame ``k``'s value of a counter: finite; the collision counts whole, >= 0 and never
    below the previous frame's (they count since the simulation began)."""
    if name in _INT_COUNTERS:
        value = int(f.array(k, _log(name), (1,), integer=True)[0])
        if value < 0 or (before and value < before[-1]):
            least = before[-1] if before else 0
            raise f.error(k, _log(name), f"is {value}, below {least}: a count never decreases")
        return value
    array = f.array(k, _log(name), (d,) if name == "momentum" else (1,))
    if not np.all(np.isfinite(array)):
        raise f.error(k, _log(name), "contains NaN or infinity")
    return array if name == "momentum" else float(array[0])


def scene_from_gsd(path: str | os.PathLike, frame: int, make_scene: Any, **params: Any) -> Any:
    """A Scene from one frame of a GSD file: exact when granular wrote it, else from the
    float32 HOOMD fields (a periodic box centred at the origin).

    Parameters
    ----------
    path : str or os.PathLike
        A ``.gsd`` file.
    frame : int
        The frame's index (negative: from the end).
    make_scene : type
        The Scene class (``Scene.from_gsd`` passes it).
    **params
        Scene parameters to set (``Scene.replace``): those a foreign file does not hold
        (its boundary, restitutions), or changes to the run's.

    Raises
    ------
    GSDFileError
        The file, or the frame's state in it, is unreadable or invalid (as for ``read``).
    IndexError
        No such frame.
    """
    with _File(path) as f:
        count = f.frames
        if not -count <= frame < count:
            raise IndexError(f"frame {frame} out of range: {f.where} holds {count} frames")
        k = frame % count
        if f.has(0, _log("format")):
            p, _ = _params(f)
            n, d = len(p["radii"]), len(p["box"][0])
            x = f.array(k, _log("unwrapped_positions"), (n, d))
            v = np.zeros((n, d))
            if f.has(k, _log("velocities")):
                v = f.array(k, _log("velocities"), (n, d))
            t = float(f.array(k, _log("time"), (1,))[0])
            w = None
            if f.has(k, _log("angular_velocities")):
                w = f.array(k, _log("angular_velocities"), spin_shape(n, d))
            own = _scene(f, k, x, v, p, make_scene, t, w)
        else:
            own = _foreign_scene(f, k, make_scene)
    return own.replace(**params)


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products of quaternions (..., 4) stored (real, x, y, z)."""
    w1, v1 = a[..., :1], a[..., 1:]
    w2, v2 = b[..., :1], b[..., 1:]
    w = w1 * w2 - np.sum(v1 * v2, axis=-1, keepdims=True)
    return np.concatenate([w, w1 * v2 + w2 * v1 + np.cross(v1, v2)], axis=-1)


def _foreign_spins(f, k, get, n, dim, radii, masses):
    """A HOOMD frame's spins as Scene keywords (see the module docstring): the body-frame
    angular momentum S = im(q* P) / 2 turned into the box frame by the orientation q,
    divided by the moment of inertia about each axis (0 where it is 0: no rotation there);
    the scene's inertia_factor I / (m r^2) when every particle has the same one (within
    float32's rounding) in (0, 1]."""
    P = get("particles/angmom", (n, 4), 0.0)
    q = get("particles/orientation", (n, 4), [1.0, 0.0, 0.0, 0.0])
    moments = get("particles/moment_inertia", (n, 3), 0.0)
    conj = q * np.array([1.0, -1.0, -1.0, -1.0])
    body = 0.5 * _quat_mul(conj, P)
    body[:, 0] = 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        w_body = np.where(moments > 0, body[:, 1:] / moments, 0.0)
    w = _quat_mul(_quat_mul(q, np.concatenate([np.zeros((n, 1)), w_body], axis=1)), conj)[:, 1:]
    out: dict[str, Any] = {"angular_velocities": w[:, 2] if dim == 2 else w}
    axis = moments[:, 2] if dim == 2 else moments[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = axis / (masses * radii**2)
    if np.all(np.isfinite(factor)) and np.ptp(factor) <= 1e-5 * np.max(np.abs(factor)):
        if 0.0 < float(factor[0]) <= 1.0 + 1e-6:
            out["inertia_factor"] = min(float(factor[0]), 1.0)
    return out


def _foreign_scene(f: _File, k: int, make_scene: Any) -> Any:
    """Frame ``k`` of a file granular did not write, from its float32 HOOMD fields, as a
    periodic box centred at the origin.  A field missing from frame ``k`` is frame 0's, else
    HOOMD's default (gsd.hoomd's rule)."""

    def get(name, shape, default=None):
        for at in (k, 0):
            if f.has(at, name):
                return f.array(at, name, shape)
        if default is None:
            raise f.error(k, name, "is missing (and frame 0 has none)")
        return np.broadcast_to(np.asarray(default, dtype=np.float64), shape)

    n = int(get("particles/N", (1,))[0])
    if n < 1:
        raise f.error(k, "particles/N", f"is {n}: the frame holds no particles")
    box = get("configuration/box", (6,), [1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    dim = int(get("configuration/dimensions", (1,), [2.0 if box[2] == 0 else 3.0])[0])
    if dim not in (2, 3):
        raise f.error(k, "configuration/dimensions", f"is {dim}, not 2 or 3")
    if np.any(box[3 : 3 + (1 if dim == 2 else 3)] != 0):
        raise f.error(
            k,
            "configuration/box",
            f"has tilts {box[3:].tolist()}: granular's boxes are rectangular (a sheared "
            "box's tilt is read only from the files granular writes, whose log holds the "
            "shear)",
        )
    x = get("particles/position", (n, 3))[:, :dim]
    v = get("particles/velocity", (n, 3), 0.0)[:, :dim]
    lengths = box[:dim]
    lower, upper = -0.5 * lengths, 0.5 * lengths
    x = np.where(x >= upper, x - lengths, x)
    radii = 0.5 * get("particles/diameter", (n,), 1.0)
    masses = get("particles/mass", (n,), 1.0)
    spin = {}
    if f.has(k, "particles/angmom") or f.has(0, "particles/angmom"):
        spin = _foreign_spins(f, k, get, n, dim, radii, masses)
    try:
        return make_scene(x, v, radii, masses, box=(lower, upper), **spin)
    except (ValueError, TypeError) as exc:
        raise GSDFileError(f"{f.where}, frame {k}: not a valid state: {exc}") from exc
