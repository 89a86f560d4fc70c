"""Transport coefficients of the elastic hard-sphere (hard-disk) fluid: Enskog's shear
viscosity and self-diffusion coefficient as functions of the packing fraction, and the
finite-size correction of a self-diffusion coefficient measured in a periodic box.

Enskog's theory (Chapman & Cowling, *The Mathematical Theory of Non-Uniform Gases*, 3rd
ed. 1970, sections 16.41-16.5; Gass, J. Chem. Phys. 54, 1898 (1971) for disks) assumes
uncorrelated binary collisions: it is exact at low density and misses the correlated
collisions (ring and vortex effects) of a dense fluid, by a few percent up to eta ~ 0.2
and by tens of percent near freezing.  The high-precision MD values of Pieprzyk,
Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019) measure that
difference; their tables are not reproduced here (see docs/stress.md: they could not be
looked up for this version, so granular compares with Enskog and states the deviation).
``speedy_diffusion`` gives an older empirical representation of MD self-diffusion
(Speedy 1987), which Sigurgeirsson & Heyes (2003) found to fit their N ~ 500 data: a
finite-system reference, not an infinite-N one.
"""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .clustering import shear_viscosity
from .haff import diffusion_d0

# Yeh & Hummer, J. Phys. Chem. B 108, 15873 (2004), eq. 13: the periodic images' hydrodynamic
# self-interaction in a cubic box, xi_EW (Ewald sum of the Oseen tensor)
YEH_HUMMER_XI = 2.837297


def _density(eta, radius, dim):
    unit = 4.0 / 3.0 * math.pi * np.asarray(radius) ** 3 if dim == 3 else math.pi * radius**2
    return np.asarray(eta, dtype=np.float64) / unit


@keyword_only("eta")
def enskog_viscosity(
    eta: FloatOrArray,
    *,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
) -> FloatOrArray:
    """Enskog's shear viscosity of elastic hard spheres (disks) in the first Sonine
    approximation, ``shear_viscosity`` at restitution 1::

        3D: eta_E = eta0 [(1 + 8 phi chi / 5)^2 / chi + 768 phi^2 chi / (25 pi)],
            eta0 = (5 / (16 sigma^2)) sqrt(m T / pi)    (Chapman & Cowling 16.41)
        2D: eta_E = eta0 [(1 + phi chi)^2 / chi + 8 phi^2 chi / pi],
            eta0 = (1 / (2 sigma)) sqrt(m T / pi)       (Gass 1971)

    with sigma = 2 r and chi = ``contact_value(phi)`` (Carnahan-Starling in 3D,
    Henderson in 2D).  Higher Sonine orders raise eta0 by 1.6 % in 3D (Chapman & Cowling
    10.21: 1.016) and by about 2 % in 2D.

    Parameters
    ----------
    eta : float or array
        Packing fraction (area fraction in 2D), in [0, 1).
    radius : float
        Particle radius (L).
    temperature : float
        Temperature T, an energy (k_B = 1).
    mass : float
        Particle mass (m).
    dim : 2 or 3

    Returns
    -------
    The shear viscosity, in m / (L^(d-2) time).
    """
    _check_dim(dim)
    return shear_viscosity(
        density=_density(eta, radius, dim),
        radius=radius,
        restitution=1.0,
        temperature=temperature,
        mass=mass,
        dim=dim,
        eta=eta,
    )


@keyword_only("eta")
def enskog_diffusion(
    eta: FloatOrArray,
    *,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
) -> FloatOrArray:
    """Enskog's self-diffusion coefficient of elastic hard spheres (disks), first Sonine
    approximation, ``D_E = 3 / (8 n chi sigma^2) sqrt(T / (pi m))`` in 3D (Chapman &
    Cowling 16.5; the thesis' 2.50) and ``1 / (2 n chi sigma) sqrt(T / (pi m))`` in 2D
    (Gass 1971): ``diffusion_d0`` at restitution 1.  Per dimension, ``<dx^2> = 2 D t``.
    Higher Sonine orders raise it by 1.9 % in 3D (Chapman & Cowling 10.21).

    Parameters
    ----------
    eta : float or array
        Packing fraction (area fraction in 2D), in [0, 1).
    radius, temperature, mass, dim
        As in ``enskog_viscosity``.

    Returns
    -------
    D in L^2 / time.
    """
    _check_dim(dim)
    return diffusion_d0(
        density=_density(eta, radius, dim),
        radius=radius,
        restitution=1.0,
        temperature0=temperature,
        mass=mass,
        dim=dim,
        eta=eta,
    )


@keyword_only("box")
def diffusion_infinite_system(
    box: FloatOrArray,
    *,
    diffusion: FloatOrArray,
    viscosity: FloatOrArray,
    temperature: FloatOrArray,
) -> FloatOrArray:
    """The self-diffusion coefficient of an infinite system from D_L measured in a cubic
    periodic box of side L (3D only), Yeh & Hummer 2004 eq. 13::

        D_inf = D_L + xi T / (6 pi eta L),   xi = 2.837297

    The correction is the periodic images' hydrodynamic drag on a particle; use the
    fluid's shear viscosity (the measured one, or ``enskog_viscosity``).  In 2D there is
    no such limit (the velocity correlation's t^-1 tail makes D grow like ln L).

    Parameters
    ----------
    box : float or array
        Side L of the cubic box (L).
    diffusion : float or array
        D_L measured in that box (L^2 / time), per dimension: <dx^2> = 2 D t.
    viscosity : float or array
        Shear viscosity eta (m / (L time)).
    temperature : float or array
        Temperature T, an energy (k_B = 1).
    """
    return np.asarray(diffusion) + YEH_HUMMER_XI * np.asarray(temperature) / (
        6.0 * math.pi * np.asarray(viscosity) * np.asarray(box)
    )


# Speedy's singular density n sigma^3 at which his D vanishes (Mol. Phys. 62, 509 (1987))
SPEEDY_DENSITY_MAX = 1.09


@keyword_only("eta")
def speedy_diffusion(
    eta: FloatOrArray,
    *,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
) -> FloatOrArray:
    """Speedy's representation of the hard-sphere fluid's self-diffusion coefficient from
    computer simulations (R. J. Speedy, Mol. Phys. 62, 509 (1987)), 3D only::

        D / D0 = (1 / n) (1 - n / 1.09) [1 + n^2 (0.4 - 0.83 n^2)],
        D0 = (3/8) sigma sqrt(T / (pi m)),   n = rho sigma^3

    exact in the ideal-gas limit (D0 / n is the Boltzmann first-Sonine D) and vanishing at
    n = 1.09, the singular density of the paper's abstract.  The abstract defines D0 and n and
    states the singularity; the coefficients 0.4, 0.83, 1.09 are the published fit as it is
    used in public analysis scripts (the body of the paper could not be read here).
    Sigurgeirsson & Heyes (Mol. Phys. 101, 469 (2003)) report that it fits their N ~ 500
    data well: compare it with D measured at N ~ 500, not with the infinite-N limit.

    Parameters
    ----------
    eta : float or array
        Packing fraction in [0, 1) (n = 6 eta / pi; the formula is for the fluid, n <= 1.09,
        eta <= 0.571, and 0 beyond).
    radius : float or array
        Particle radius (L), sigma = 2 r.
    temperature : float or array
        Temperature T, an energy (k_B = 1).
    mass : float or array
        Particle mass (m).

    Returns
    -------
    D in L^2 / time, per dimension: <dx^2> = 2 D t.
    """
    n = 6.0 * np.asarray(eta, dtype=np.float64) / math.pi
    sigma = 2.0 * np.asarray(radius)
    d0 = 3.0 / 8.0 * sigma * np.sqrt(np.asarray(temperature) / (math.pi * np.asarray(mass)))
    with np.errstate(divide="ignore", invalid="ignore"):
        shape = np.clip(1.0 - n / SPEEDY_DENSITY_MAX, 0.0, None) * (
            1.0 + n**2 * (0.4 - 0.83 * n**2)
        )
        d = d0 / n * shape
    return np.where(n == 0.0, np.inf, d)
