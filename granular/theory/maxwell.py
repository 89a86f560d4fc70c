"""The Maxwell-Boltzmann speed distribution and its moments (thesis Table 2.2)."""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim


@keyword_only("speed", "temperature", "mass", "dim")
def maxwell_boltzmann_pdf(
    speed: FloatOrArray, *, temperature: float, mass: float = 1.0, dim: int = 3
) -> FloatOrArray:
    """Speed density of a gas in equilibrium (2.30 in 2D, 2.32 in 3D):
    2D ``(m v / T) exp(-m v^2 / 2T)``; 3D ``4 pi v^2 (m / 2 pi T)^(3/2) exp(-m v^2 / 2T)``."""
    _check_dim(dim)
    v = np.asarray(speed, dtype=np.float64)
    b = mass / temperature
    if dim == 2:
        return b * v * np.exp(-0.5 * b * v * v)
    return 4 * math.pi * v * v * (b / (2 * math.pi)) ** 1.5 * np.exp(-0.5 * b * v * v)


@keyword_only("temperature", "mass", "dim")
def maxwell_boltzmann_moments(
    *, temperature: float, mass: float = 1.0, dim: int = 3
) -> dict[str, float]:
    """Expectation values of Table 2.2: mean speed, mean squared speed, standard deviation
    of the speed and most probable speed."""
    _check_dim(dim)
    s = temperature / mass
    mean = math.sqrt(math.pi * s / 2) if dim == 2 else math.sqrt(8 * s / math.pi)
    mean_sq = dim * s
    return {
        "mean": mean,
        "mean_sq": mean_sq,
        "std": math.sqrt(mean_sq - mean**2),
        "most_probable": math.sqrt(s) if dim == 2 else math.sqrt(2 * s),
    }
