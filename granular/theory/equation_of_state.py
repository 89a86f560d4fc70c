"""Geometry and equilibrium structure of hard disks and spheres: packing fraction, contact
value of the pair correlation, equation of state, adsorption at a flat wall."""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim


@keyword_only("n", "radius", "volume", "dim")
def packing_fraction(
    *, n: FloatOrArray, radius: FloatOrArray, volume: FloatOrArray, dim: int = 3
) -> FloatOrArray:
    """Fraction of the volume (area in 2D) covered by n particles of the given radius
    (2.44): ``eta = n (4/3) pi r^3 / V`` in 3D, ``n pi r^2 / A`` in 2D."""
    _check_dim(dim)
    unit = 4.0 / 3.0 * math.pi * radius**3 if dim == 3 else math.pi * radius**2
    return n * unit / volume


@keyword_only("eta", "dim")
def contact_value(eta: FloatOrArray, *, dim: int = 3) -> FloatOrArray:
    """Contact value g2 of the equilibrium pair correlation function of hard spheres/disks.

    3D: Carnahan-Starling ``(2 - eta) / (2 (1 - eta)^3)`` (2.43).  2D: Henderson's
    ``(1 - 7 eta / 16) / (1 - eta)^2``.
    """
    _check_dim(dim)
    eta = np.asarray(eta, dtype=np.float64)
    if np.any((eta < 0) | (eta >= 1)):
        raise ValueError("packing fraction must lie in [0, 1)")
    g = (2 - eta) / (2 * (1 - eta) ** 3) if dim == 3 else (1 - 7 * eta / 16) / (1 - eta) ** 2
    return g[()] if g.ndim == 0 else g


@keyword_only("eta", "dim")
def compressibility_factor(eta: FloatOrArray, *, dim: int = 3) -> FloatOrArray:
    """Equation of state Z = P / (n T) of hard spheres (Carnahan-Starling,
    ``1 + 4 eta g2``) or disks (Henderson, ``1 + 2 eta g2``): the collision virial's
    prediction with the approximate contact value."""
    return 1 + (4.0 if dim == 3 else 2.0) * np.asarray(eta) * contact_value(eta, dim=dim)


# Pieprzyk, Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019):
# their fit of the hard-sphere fluid's Z to molecular dynamics, Z = 1 + sum c_k x^k in
# x = eta / (1 - eta), as the powers k and coefficients c_k
PIEPRZYK_EOS = (
    (1, 4.0),
    (2, 6.0),
    (3, 2.3647684),
    (4, -0.8698551),
    (5, 1.1062803),
    (6, -1.1014221),
    (7, 0.66605866),
    (8, -0.03633431),
    (10, -0.20965164),
    (14, 0.10555569),
    (22, -0.00872380),
)


@keyword_only("eta")
def pieprzyk_compressibility(eta: FloatOrArray) -> FloatOrArray:
    """The hard-sphere fluid's equation of state Z = P / (n T) from molecular dynamics:
    Pieprzyk, Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019),
    their fit ``Z = 1 + 4 x + 6 x^2 + 2.3647684 x^3 - ... - 0.0087238 x^22`` in
    ``x = eta / (1 - eta)`` (``PIEPRZYK_EOS``; 3D, the stable and metastable fluid).  The
    coefficients were read from the implementation of this equation of state in the
    Enskog-theory code of one of its authors (pyenskog, M. N. Bannerman): the paper's body
    could not be read here.  Its low-density expansion has the exact virial coefficients
    4, 10 and 18.3648 eta^3 (B4 / b^3); at packing 0.30 it lies 0.3 % above
    Carnahan-Starling (``compressibility_factor``).  The contact value of the pair
    correlation follows as ``g(sigma) = (Z - 1) / (4 eta)``, and with it the collision
    frequency, exactly: ``4 sqrt(pi) n sigma^2 g(sigma) sqrt(T / m)``.

    Parameters
    ----------
    eta : float or array
        Packing fraction in [0, 1).
    """
    eta = np.asarray(eta, dtype=np.float64)
    if np.any((eta < 0) | (eta >= 1)):
        raise ValueError("packing fraction must lie in [0, 1)")
    x = eta / (1.0 - eta)
    z = np.ones_like(x)
    for k, c in PIEPRZYK_EOS:
        z = z + c * x**k
    return z[()] if z.ndim == 0 else z


@keyword_only("density", "radius", "dim")
def wall_adsorption(*, density: float, radius: float, dim: int = 3) -> float:
    """Excess number of hard disks/spheres per unit length (2D) or area (3D) of a flat hard
    wall, to first order in the density: ``(2/3) n^2 sigma^3`` in 2D, ``(pi/4) n^2 sigma^4``
    in 3D (sigma = 2 r).  A particle near the wall misses the neighbours the wall excludes,
    so to first order rho(x) / n - 1 = n A(x), A(x) the part of its exclusion disk/sphere
    beyond the plane the centres reach; integrated over x that is int_0^sigma of the
    segment (cap) area of height h, 2 sigma^3 / 3 (pi sigma^4 / 4).  A gas of N particles
    in a walled box is therefore less dense in its bulk than N over the area its centres
    reach (2% for the Brownian-motion note's 150 disks; checked against EDMD in
    tests/test_brownian_tracer.py).  Second order in the density is neglected."""
    _check_dim(dim)
    sigma = 2.0 * radius
    return density**2 * (2.0 / 3.0 * sigma**3 if dim == 2 else math.pi / 4.0 * sigma**4)
