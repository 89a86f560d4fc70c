"""The mean flow of a sheared box (Lees-Edwards boundaries, csrc/boundary.h): the
velocities relative to it (peculiar velocities) and the temperature they define.

The images across the upper (lower) y face move along x with +(-) shear_rate * L_y, so
the steady mean flow is u_x(y) = shear_rate * (y - y_c), with y the position in the box
(the one the engine's velocities belong to: a particle's velocity jumps by the images'
speed when it crosses a y face) and y_c the box's centre, which the images' symmetry
leaves at rest (docs/shear.md).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray


def box_y(y: NDArray[np.float64], lower: float, upper: float) -> NDArray[np.float64]:
    """y coordinates (unwrapped or not) brought into the box [lower, upper) [L]."""
    return lower + np.mod(np.asarray(y) - lower, upper - lower)


def peculiar_velocities(
    positions: NDArray[np.float64],
    velocities: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    shear_rate: float,
) -> NDArray[np.float64]:
    """(..., N, d) velocities less the mean flow shear_rate * (y - y_c) along x.

    Parameters
    ----------
    positions, velocities : (..., N, d) arrays
        Positions (unwrapped or in the box) [L] and the engine's velocities [sqrt(eps/m)].
    lower, upper : (d,) arrays
        The box's corners [L].
    shear_rate : float
        [sqrt(eps/m) / L].
    """
    v = np.array(velocities, dtype=np.float64, copy=True)
    y = box_y(np.asarray(positions)[..., 1], float(lower[1]), float(upper[1]))
    v[..., 0] -= shear_rate * (y - 0.5 * (float(lower[1]) + float(upper[1])))
    return v


def flow_temperature(
    positions: NDArray[np.float64],
    velocities: NDArray[np.float64],
    masses: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    shear_rate: float,
) -> NDArray[np.float64]:
    """The temperature of the peculiar velocities, sum m |V|^2 / (d N) [eps], for each
    sample of (..., N, d) positions and velocities."""
    v = peculiar_velocities(positions, velocities, lower, upper, shear_rate)
    n, d = v.shape[-2], v.shape[-1]
    return np.einsum("...nd,n->...", v * v, np.asarray(masses)) / (d * n)


def total_offset(shear_rate: float, shear_offset: float, ly: float, t: float) -> float:
    """The accumulated image offset D(t) = shear_offset + shear_rate L_y t [L], computed as
    the engine does (csrc/boundary.h bd_le_total)."""
    return shear_offset + shear_rate * ly * t


def offset(shear_rate: float, shear_offset: float, lx: float, ly: float, t: float) -> float:
    """The image offset delta(t) = D(t) mod L_x in [0, L_x) [L] (bd_le_offset)."""
    d = math.fmod(total_offset(shear_rate, shear_offset, ly, t), lx)
    if d < 0.0:
        d += lx
    return d if d < lx else 0.0


def wrap(
    unwrapped: NDArray[np.float64],
    lower: NDArray[np.float64],
    upper: NDArray[np.float64],
    shear_rate: float,
    shear_offset: float,
    t: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """(N, d) unwrapped positions of a sheared box at time t brought into the box, with
    their image counters (the engine's: unwrapped x = x + img_x L_x + img_y D(t))."""
    lower = np.asarray(lower, dtype=np.float64)
    lengths = np.asarray(upper, dtype=np.float64) - lower
    x = np.array(unwrapped, dtype=np.float64, copy=True)
    img = np.zeros(x.shape, dtype=np.int64)
    img[:, 1:] = np.floor((x[:, 1:] - lower[1:]) / lengths[1:]).astype(np.int64)
    x[:, 1:] -= img[:, 1:] * lengths[1:]
    x[:, 0] -= img[:, 1] * total_offset(shear_rate, shear_offset, float(lengths[1]), t)
    img[:, 0] = np.floor((x[:, 0] - lower[0]) / lengths[0]).astype(np.int64)
    x[:, 0] -= img[:, 0] * lengths[0]
    # rounding can leave a centre one ulp outside [lower, upper)
    upper = lower + lengths
    x = np.where(x >= upper, x - lengths, np.where(x < lower, x + lengths, x))
    return x, img
