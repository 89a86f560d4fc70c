"""Trajectories out to MDAnalysis (and through it to OVITO, VMD, GROMACS tools).

Units: MDAnalysis counts lengths in angstrom and time in picoseconds; granular's lengths
(box units) and times are handed over as those numbers unchanged.  MDAnalysis keeps
coordinates in float32 (about 7 significant digits) and gives frames evenly spaced times
(``dt``), so log-spaced samples lose their real times in a Universe -- the file written by
``write_trajectory`` keeps them.

Boxes.  MDAnalysis (like a GSD file's ``configuration/box``) knows only three-dimensional,
periodic boxes; granular gives it the box's edge lengths whatever its boundary, the same in
a Universe (``to_universe``), a TRR file (``write_trajectory``) and a GSD file read by
MDAnalysis.  In 2D the disks lie in the plane z = 0 of a box as deep as its longest edge,
``[Lx, Ly, max(Lx, Ly), 90, 90, 90]`` (``box_lengths_3d``): a depth of 0 would give a
volume of 0, which MDAnalysis' analyses divide by (``InterRDF``), and a depth under twice
a distance cutoff makes its periodic neighbour searches fail or count pairs that the
brute-force search does not.  So MDAnalysis' densities are per volume Lx Ly Lz:
``InterRDF`` of a 2D run counts pairs in spherical shells, about g(r) Lz / (2r); the 2D
g(r) is its ``rdf`` times V_shell / (Lz A_ring), with V_shell = 4 pi (r2^3 - r1^3) / 3 and
A_ring = pi (r2^2 - r1^2) for each bin [r1, r2] (docs/files.md).  In a walled box
MDAnalysis still wraps distances across the walls, which pairs near opposite walls feel.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from numpy.typing import ArrayLike


def _mda():
    try:
        import MDAnalysis
    except ImportError as exc:  # pragma: no cover - exercised only without MDAnalysis
        raise ImportError(
            "this needs MDAnalysis: pip install MDAnalysis (or pip install 'granular[interop]')"
        ) from exc
    return MDAnalysis


def _as_3d(positions):
    x = np.asarray(positions, dtype=np.float64)
    if x.ndim != 3 or x.shape[2] not in (2, 3):
        raise ValueError(f"positions must have shape (T, N, d) with d = 2 or 3, got {x.shape}")
    if x.shape[2] == 2:  # MDAnalysis is three-dimensional: disks lie in the plane z = 0
        x = np.concatenate([x, np.zeros((*x.shape[:2], 1))], axis=2)
    return x


def box_lengths_3d(lengths: ArrayLike) -> list[float]:
    """The three edge lengths of a box as tools that know only 3D boxes (MDAnalysis, a GSD
    file's ``configuration/box``) are given it: a 3D box's own, and for a 2D box
    ``[Lx, Ly, max(Lx, Ly)]`` (see the module docstring for why that depth).

    Parameters
    ----------
    lengths : array_like, shape (d,)
        The box's edge lengths (box units), d = 2 or 3.
    """
    L = [float(v) for v in np.asarray(lengths, dtype=np.float64)]
    return [*L, max(L)] if len(L) == 2 else L


def _dimensions(box, dim):
    if box is None:
        return None
    L = np.broadcast_to(np.asarray(box, dtype=np.float64), (dim,))
    return np.array([*box_lengths_3d(L), 90.0, 90.0, 90.0], dtype=np.float32)


def to_universe(
    times: ArrayLike,
    positions: ArrayLike,
    box: ArrayLike | None = None,
    radii: ArrayLike | None = None,
) -> Any:
    """An in-memory ``MDAnalysis.Universe`` with one atom per particle and one frame per
    sample (unwrapped positions; 2D ones in the plane z = 0).

    Parameters
    ----------
    times : array_like, shape (T,)
        Sample times.  Frame times are evenly spaced by their mean spacing (MDAnalysis'
        MemoryReader knows only a constant dt).
    positions : array_like, shape (T, N, d)
        Positions (box units), d = 2 or 3.
    box : array_like, shape (d,), optional
        The box's edge lengths: the frames' dimensions, ``box_lengths_3d(box)`` and right
        angles (in 2D ``[Lx, Ly, max(Lx, Ly), 90, 90, 90]``; see the module docstring).
        None: no dimensions, which MDAnalysis' distance-based analyses refuse.
    radii : array_like, shape (N,), optional
        Stored as the atoms' ``radii`` attribute.
    """
    mda = _mda()
    from MDAnalysis.coordinates.memory import MemoryReader

    t = np.asarray(times, dtype=np.float64)
    x = _as_3d(positions)
    n = x.shape[1]
    u = mda.Universe.empty(n, trajectory=False)
    if radii is not None:
        u.add_TopologyAttr("radii", np.broadcast_to(np.asarray(radii, dtype=np.float64), (n,)))
    dims = _dimensions(box, np.asarray(positions).shape[2])
    dt = float((t[-1] - t[0]) / (len(t) - 1)) if len(t) > 1 else 1.0
    u.load_new(x.astype(np.float32), format=MemoryReader, order="fac", dt=dt, dimensions=dims)
    return u


def write_trajectory(
    path: str | os.PathLike[str],
    times: ArrayLike,
    positions: ArrayLike,
    velocities: ArrayLike | None = None,
    box: ArrayLike | None = None,
) -> str:
    """Write a GROMACS TRR file (through MDAnalysis' TRRWriter): per frame its real time,
    unwrapped positions and optionally velocities, in float32.  MDAnalysis, OVITO, VMD and
    GROMACS read it; 2D scenes are written in the plane z = 0.

    TRR rather than XTC because XTC compresses coordinates to a fixed precision.  ``box``:
    the box's edge lengths, written as in ``to_universe``.
    """
    mda = _mda()
    from MDAnalysis.coordinates.TRR import TRRWriter

    t = np.asarray(times, dtype=np.float64)
    x = _as_3d(positions)
    v = None if velocities is None else _as_3d(velocities)
    if len(t) != len(x):
        raise ValueError("times and positions must have the same number of samples")
    n = x.shape[1]
    u = mda.Universe.empty(n, trajectory=True, velocities=v is not None)
    dims = _dimensions(box, np.asarray(positions).shape[2])
    with TRRWriter(str(path), n) as w:
        for k in range(len(t)):
            ts = u.trajectory.ts
            ts.positions = x[k]
            if v is not None:
                ts.velocities = v[k]
            ts.dimensions = dims
            ts.time = t[k]
            ts.frame = k
            w.write(u.atoms)
    return str(path)
