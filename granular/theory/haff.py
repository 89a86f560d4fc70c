"""Collisions, Haff's law and the transport coefficients of a gas with a constant
restitution xi (thesis ch. 2): collision frequency, Haff's tau0, D0, gamma0."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .. import restitution as _restitution
from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .equation_of_state import contact_value, packing_fraction


def _eta(density, radius, dim, eta):
    return packing_fraction(n=density, radius=radius, volume=1.0, dim=dim) if eta is None else eta


@keyword_only("density", "radius", "temperature", "mass", "dim", "eta")
def collision_frequency(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Enskog collision frequency per particle, the inverse mean collision time (2.42).

    3D: ``4 sqrt(pi) g2 sigma^2 n sqrt(T/m)``; 2D: ``2 sqrt(pi) g2 sigma n sqrt(T/m)``,
    with sigma = 2 r the diameter and n = N / V.  (2.70)-(2.71) print the collision time
    as proportional to sqrt(T); (2.42), used here, makes it 1/sqrt(T).
    """
    _check_dim(dim)
    g2 = contact_value(_eta(density, radius, dim, eta), dim=dim)
    sigma = 2.0 * radius
    geometry = 4.0 * sigma**2 if dim == 3 else 2.0 * sigma
    return geometry * math.sqrt(math.pi) * g2 * density * np.sqrt(np.asarray(temperature) / mass)


@keyword_only("density", "radius", "temperature", "mass", "dim", "eta")
def collision_time(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Mean time between collisions of one particle, ``1 / collision_frequency`` (2.42)."""
    return 1.0 / collision_frequency(
        density=density, radius=radius, temperature=temperature, mass=mass, dim=dim, eta=eta
    )


def _constant_xi(xi):
    """A formula for a constant restitution given a law: say what to use instead."""
    if isinstance(xi, _restitution.RestitutionLaw):
        raise TypeError(
            f"restitution must be a number (a constant xi), got a {type(xi).__name__}; for "
            "a viscoelastic gas use theory.viscoelastic_* with the law, or "
            "langevin.coefficients_from_scene(scene)"
        )
    return xi


@keyword_only(
    "density", "radius", "xi", "temperature0", "mass", "dim", "eta", renamed={"xi": "restitution"}
)
def haff_tau0(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    temperature0: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Haff's time scale tau0 (2.41, 2.45): ``1/tau0 = (1 - xi^2) omega(T0) / (2 d)``.

    In 3D this is (2.45), ``(2/3)(1 - xi^2) sqrt(pi) g2 n sigma^2 sqrt(T0/m)``.  The
    general d follows the same derivation: a collision of equal masses loses
    ``(1 - xi^2) m (v_n)^2 / 4``, which averages to ``(1 - xi^2) T`` over collisions of a
    Maxwellian gas, so ``dT/dt = -(1 - xi^2) omega T / d``.  Infinite for xi = 1.
    """
    xi = _constant_xi(restitution)
    if xi == 1.0:
        return math.inf
    omega = collision_frequency(
        density=density, radius=radius, temperature=temperature0, mass=mass, dim=dim, eta=eta
    )
    return 2 * dim / ((1.0 - xi**2) * omega)


@keyword_only("t", "temperature0", "tau0")
def haff_temperature(
    t: FloatOrArray, *, temperature0: FloatOrArray, tau0: FloatOrArray
) -> FloatOrArray:
    """Haff's law ``T(t) = T0 / (1 + t/tau0)^2`` (2.40), homogeneous cooling state."""
    t = np.asarray(t, dtype=np.float64)
    return temperature0 / (1.0 + t / tau0) ** 2


@keyword_only(
    "density", "radius", "xi", "temperature0", "mass", "dim", "eta", renamed={"xi": "restitution"}
)
def diffusion_d0(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    temperature0: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Self-diffusion coefficient at t = 0 (2.49-2.52): ``D0 = 4 D_E / (1 + xi)^2`` with
    Enskog's D_E = ``3 / (8 n g2 sigma^2) sqrt(T0 / (pi m))`` in 3D (2.50), and its 2D
    counterpart ``1 / (2 n g2 sigma) sqrt(T0 / (pi m))`` (velocity relaxation rate
    gamma_E = (2/d) omega, the same Enskog derivation).  Per dimension:
    ``<dx^2> = 2 D t``."""
    xi = _constant_xi(restitution)
    _check_dim(dim)
    g2 = contact_value(_eta(density, radius, dim, eta), dim=dim)
    sigma = 2.0 * radius
    if dim == 3:
        d_enskog = 3.0 / (8.0 * density * g2 * sigma**2)
    else:
        d_enskog = 1.0 / (2.0 * density * g2 * sigma)
    return 4.0 * d_enskog * np.sqrt(np.asarray(temperature0) / (math.pi * mass)) / (1.0 + xi) ** 2


class LangevinCoefficients(NamedTuple):
    """Friction gamma0, diffusivity D0 (per dimension) and Haff time tau0 of a gas."""

    gamma0: float
    D0: float
    tau0: float


@keyword_only(
    "n", "radius", "volume", "xi", "temperature0", "mass", "dim", renamed={"xi": "restitution"}
)
def langevin_coefficients(
    *,
    n: float,
    radius: float,
    volume: float,
    restitution: float,
    temperature0: float,
    mass: float = 1.0,
    dim: int = 3,
) -> LangevinCoefficients:
    """gamma0, D0, tau0 of a gas of n particles in a box of the given volume, as the thesis
    derives them for its Langevin and UDSBM models: D0 (2.52), ``gamma0 = T0 / (m D0)``
    (2.55), tau0 (2.45; infinite for xi = 1)."""
    xi = _constant_xi(restitution)
    density = n / volume
    d0 = float(
        diffusion_d0(
            density=density,
            radius=radius,
            restitution=xi,
            temperature0=temperature0,
            mass=mass,
            dim=dim,
        )
    )
    gamma0 = temperature0 / (mass * d0)
    tau0 = float(
        haff_tau0(
            density=density,
            radius=radius,
            restitution=xi,
            temperature0=temperature0,
            mass=mass,
            dim=dim,
        )
    )
    return LangevinCoefficients(gamma0, d0, tau0)
