"""The mean flow of a sheared box (Lees-Edwards boundaries, csrc/boundary.h): the
velocities relative to it (peculiar velocities) and the temperature they define.

The images across the upper (lower) y face move along x with +(-) shear_rate * L_y, so
the steady mean flow is u_x(y) = shear_rate * (y - y_c), with y the position in the box
(the one the engine's velocities belong to: a particle's velocity jumps by the images'
speed when it crosses a y face) and y_c the box's centre, which the images' symmetry
leaves at rest (docs/shear.md).
"""

from __future__ import annotations

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
