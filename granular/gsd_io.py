"""Trajectories to and from GSD files (HOOMD-blue's format, read by OVITO, freud, HOOMD and
MDAnalysis): ``Trajectory.write("run.gsd")``, ``granular.read("run.gsd")`` and
``Scene.from_gsd("run.gsd", frame=-1)``.  Needs the ``gsd`` package
(``pip install 'granular[gsd]'``).

What each frame holds.  The HOOMD schema fixes the standard fields to float32, so these are
for viewers and analysis tools (OVITO, freud, MDAnalysis), good to about 7 digits:

- ``particles/position``: positions wrapped into the box, which GSD centres at the origin
  (position - box centre, in [-L/2, L/2]); disks lie in the plane z = 0
- ``particles/image`` (int32): periodic image flags, unwrapped = position + image * L
  (always 0 in a walled box)
- ``particles/velocity``, ``particles/diameter``, ``particles/mass``
- ``configuration/box`` (2D: Lz = 0, ``configuration/dimensions`` = 2) and
  ``configuration/step`` = the sample's index

The exact float64 (and int64) values granular reads back live in the log section:

- every frame: ``log/granular/time`` (the real sample time), ``log/granular/unwrapped_positions``
  and ``log/granular/velocities`` (float64, (N, d)), and the counters ``kinetic_energy``,
  ``momentum``, ``pair_collisions``, ``wall_collisions``, ``virial``, ``wall_impulse``
- frame 0: the scene's ``lower``, ``upper``, ``radii``, ``masses`` (float64), ``boundary`` and
  ``stop_reason`` (as UTF-8 bytes), and ``format`` (this layout's version)

(gsd >= 4 can write the HOOMD fields in float64, but OVITO and older gsd and HOOMD read
float32 ones: the standard fields stay float32 and the exact values go in the log.)

So ``granular.read`` gives back a Trajectory equal, array for array, to the one written.  For
other formats (extended XYZ, TRR, DCD, ...) go through MDAnalysis: ``Trajectory.to_universe()``
and its writers.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ._files import check_kind

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


def _gsd_hoomd():
    try:
        import gsd.hoomd
    except ImportError as exc:
        raise ImportError(
            "GSD files need the gsd package: pip install gsd (or pip install 'granular[gsd]')"
        ) from exc
    return gsd.hoomd


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


def _untext(value: Any) -> str:
    return bytes(np.asarray(value, dtype=np.uint8)).decode("utf-8")


def _wrap(positions: np.ndarray, lower: np.ndarray, upper: np.ndarray, periodic: bool):
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


def _box(lower, upper):
    lengths = np.asarray(upper, dtype=np.float64) - np.asarray(lower, dtype=np.float64)
    if len(lengths) == 2:
        return [float(lengths[0]), float(lengths[1]), 0.0, 0.0, 0.0, 0.0], 2
    return [float(v) for v in lengths] + [0.0, 0.0, 0.0], 3


def _pad3(a, dtype=np.float32):
    a = np.asarray(a)
    if a.shape[-1] == 2:
        a = np.concatenate([a, np.zeros((*a.shape[:-1], 1), dtype=a.dtype)], axis=-1)
    return np.ascontiguousarray(a, dtype=dtype)


def write(traj: Any, path: str | os.PathLike) -> None:
    """Write a Trajectory to a GSD file (see the module docstring for the fields); the
    trajectory must have stored positions (velocities are written when stored)."""
    path = _check_suffix(path)
    if traj.positions is None:
        raise ValueError(
            "this trajectory did not store positions, which a GSD file needs; run with "
            "store including 'positions' (and 'velocities')"
        )
    hoomd = _gsd_hoomd()
    lower = np.asarray(traj.lower, dtype=np.float64)
    upper = np.asarray(traj.upper, dtype=np.float64)
    centre = 0.5 * (lower + upper)
    box, dimensions = _box(lower, upper)
    periodic = traj.boundary == "periodic"
    half = (0.5 * (upper - lower)).astype(np.float32)
    n = traj.n
    with hoomd.open(name=str(path), mode="w") as f:
        for k in range(len(traj.times)):
            frame = hoomd.Frame()
            frame.configuration.step = k
            frame.configuration.box = box
            frame.configuration.dimensions = dimensions
            frame.particles.N = n
            frame.particles.types = ["A"]
            frame.particles.typeid = np.zeros(n, dtype=np.uint32)
            x = traj.positions[k]
            wrapped, images = _wrap(x, lower, upper, periodic)
            position = (wrapped - centre).astype(np.float32)
            if periodic:
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
                log["granular/velocities"] = np.ascontiguousarray(
                    traj.velocities[k], dtype=np.float64
                )
            for name in _COUNTERS:
                dtype = np.int64 if name in _INT_COUNTERS else np.float64
                log[f"granular/{name}"] = np.atleast_1d(np.asarray(getattr(traj, name)[k], dtype))
            if k == 0:
                log.update(
                    {
                        "granular/format": np.array([FORMAT], dtype=np.int64),
                        "granular/lower": lower,
                        "granular/upper": upper,
                        "granular/radii": np.asarray(traj.radii, dtype=np.float64),
                        "granular/masses": np.asarray(traj.masses, dtype=np.float64),
                        "granular/boundary": _text(traj.boundary),
                        "granular/stop_reason": _text(traj.stop_reason),
                    }
                )
            frame.log = log
            f.append(frame)


def _open(path):
    check_kind(path, "gsd")  # a checkpoint or another .npz: say what reads it
    path = _check_suffix(path)
    if not path.is_file():
        raise FileNotFoundError(f"no GSD file at {str(path)!r}")
    return _gsd_hoomd().open(name=str(path), mode="r")


def _params(first, path):
    log = first.log
    if "granular/format" not in log:
        raise ValueError(
            f"{str(path)!r} was not written by granular (no log/granular/format); read it "
            "with gsd.hoomd.open, or take one frame with Scene.from_gsd"
        )
    version = int(np.asarray(log["granular/format"]).ravel()[0])
    if version != FORMAT:
        raise ValueError(
            f"{str(path)!r} has granular GSD layout {version}, this version reads {FORMAT}"
        )
    return dict(
        lower=np.array(log["granular/lower"], dtype=np.float64),
        upper=np.array(log["granular/upper"], dtype=np.float64),
        radii=np.array(log["granular/radii"], dtype=np.float64),
        masses=np.array(log["granular/masses"], dtype=np.float64),
        boundary=_untext(log["granular/boundary"]),
        stop_reason=_untext(log["granular/stop_reason"]),
    )


def read(path: str | os.PathLike) -> Any:
    """Read a GSD file written by ``Trajectory.write`` back into a Trajectory, with the
    exact float64 values of the log section."""
    from .trajectory import Trajectory

    with _open(path) as f:
        if len(f) == 0:
            raise ValueError(f"{str(path)!r} holds no frames")
        params = _params(f[0], path)
        frames = [frame.log for frame in f]
    times = np.array([np.asarray(log["granular/time"]).ravel()[0] for log in frames])
    positions = np.array([log["granular/unwrapped_positions"] for log in frames], np.float64)
    has_v = all("granular/velocities" in log for log in frames)
    velocities = (
        np.array([log["granular/velocities"] for log in frames], np.float64) if has_v else None
    )
    counters = {}
    for name in _COUNTERS:
        dtype = np.int64 if name in _INT_COUNTERS else np.float64
        values = np.array([np.asarray(log[f"granular/{name}"], dtype) for log in frames])
        counters[name] = values if name == "momentum" else values.reshape(len(frames))
    return Trajectory(times, positions, velocities, **counters, **params)


def scene_from_gsd(path: str | os.PathLike, frame: int = -1, **params: Any) -> Any:
    """A Scene from one frame of a GSD file: exact when granular wrote it, else from the
    float32 HOOMD fields (a periodic box centred at the origin).  ``params`` are the Scene's
    other keywords (restitution, wall_restitution, contact_duration; boundary for a
    foreign file)."""
    from .scene import Scene

    with _open(path) as f:
        count = len(f)
        if not -count <= frame < count:
            raise IndexError(f"frame {frame} out of range: {str(path)!r} holds {count} frames")
        first = f[0]
        snap = f[frame % count]
        own = "granular/format" in first.log
        if own:
            p = _params(first, path)
            lower, upper = p["lower"], p["upper"]
            periodic = p["boundary"] == "periodic"
            x, _ = _wrap(snap.log["granular/unwrapped_positions"], lower, upper, periodic)
            v = snap.log.get("granular/velocities")
            if v is None:
                v = np.zeros_like(x)
            params.setdefault("boundary", p["boundary"])
            return Scene(
                x,
                np.array(v, dtype=np.float64),
                p["radii"],
                p["masses"],
                box=(lower, upper),
                **params,
            )
        dim = int(snap.configuration.dimensions)
        lengths = np.asarray(snap.configuration.box[:dim], dtype=np.float64)
        x = np.asarray(snap.particles.position[:, :dim], dtype=np.float64)
        v = np.asarray(snap.particles.velocity[:, :dim], dtype=np.float64)
        lower, upper = -0.5 * lengths, 0.5 * lengths
        x = np.where(x >= upper, x - lengths, x)
        return Scene(
            x,
            v,
            0.5 * np.asarray(snap.particles.diameter, dtype=np.float64),
            np.asarray(snap.particles.mass, dtype=np.float64),
            box=(lower, upper),
            **params,
        )
