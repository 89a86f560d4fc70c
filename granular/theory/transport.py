"""Transport coefficients of the elastic hard-sphere (hard-disk) fluid: Enskog's shear
viscosity and self-diffusion coefficient as functions of the packing fraction, and the
finite-size correction of a self-diffusion coefficient measured in a periodic box.

Enskog's theory (Chapman & Cowling, *The Mathematical Theory of Non-Uniform Gases*, 3rd
ed. 1970, sections 16.41-16.5; Gass, J. Chem. Phys. 54, 1898 (1971) for disks) assumes
uncorrelated binary collisions: it is exact at low density and misses the correlated
collisions (ring and vortex effects) of a dense fluid, by a few percent up to eta ~ 0.2
and by tens of percent near freezing.  The high-precision MD values of Pieprzyk,
Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019) measure that
difference: ``pieprzyk_diffusion`` returns their self-diffusion coefficients at the
densities they tabulate (their viscosities could not be found, see docs/stress.md).
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


# Pieprzyk, Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019): the
# hard-sphere fluid's self-diffusion coefficient D* = D sqrt(m / T) / sigma at n sigma^3, as
# transcribed in a public analysis script (the paper's table itself could not be read)
PIEPRZYK_DIFFUSION = (
    (0.10, 1.94786), (0.15, 1.24636), (0.20, 0.89989), (0.25, 0.69308), (0.30, 0.55523),
    (0.35, 0.45527), (0.40, 0.37845), (0.45, 0.31663), (0.50, 0.265009), (0.55, 0.221105),
    (0.60, 0.183259), (0.65, 0.150317), (0.70, 0.121081), (0.75, 0.095425), (0.80, 0.072934),
    (0.85, 0.053298), (0.86, 0.049608), (0.87, 0.046203), (0.88, 0.042720), (0.89, 0.039478),
    (0.90, 0.036254), (0.91, 0.033286), (0.92, 0.030326), (0.93, 0.027419), (0.94, 0.024746),
    (0.95, 0.022134), (0.96, 0.019695), (0.97, 0.017357), (0.98, 0.015082), (0.99, 0.013013),
    (1.00, 0.011053), (1.01, 0.009222),
)  # fmt: skip


@keyword_only("eta")
def pieprzyk_diffusion(
    eta: FloatOrArray,
    *,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
) -> FloatOrArray:
    """The hard-sphere fluid's self-diffusion coefficient from molecular dynamics, Pieprzyk,
    Bannerman, Branka, Chudak & Heyes, Phys. Chem. Chem. Phys. 21, 6886 (2019), at the
    densities they tabulate only: n sigma^3 = 0.10, 0.15, ..., 0.85, then 0.86 to 1.01 in
    steps of 0.01 (``PIEPRZYK_DIFFUSION``; beyond freezing, n sigma^3 = 0.94, the metastable
    fluid).  3D only.  A table, not a formula: any other packing fraction is refused.

    The values are as transcribed in a public analysis script, which names the paper but
    not the table; the paper's table itself could not be read.  They are very probably the
    infinite-system values: Lue's MD at n sigma^3 = 0.5 and N = 1372 (doi:10.1063/1.1834498,
    as DynamO's tests quote it), 0.247, corrected to infinite N by
    ``diffusion_infinite_system`` with eta* = 0.58 gives 0.2655 against the table's 0.2650.
    Compare them with D measured in a periodic box after that correction.

    Parameters
    ----------
    eta : float or array
        Packing fraction, pi n sigma^3 / 6 at a tabulated n sigma^3 (to 1e-9 in n sigma^3):
        e.g. ``math.pi * 0.5 / 6``.
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
    density = 6.0 * np.asarray(eta, dtype=np.float64) / math.pi  # n sigma^3
    table = np.array(PIEPRZYK_DIFFUSION)
    index = np.abs(density[..., None] - table[:, 0]).argmin(axis=-1)
    off = np.abs(density - table[index, 0]) > 1e-9
    if np.any(off):
        bad = float(np.asarray(eta)[off].flat[0] if np.ndim(eta) else eta)
        raise ValueError(
            f"pieprzyk_diffusion is a table: packing fraction {bad:g} (n sigma^3 = "
            f"{6.0 * bad / math.pi:.6g}) is not tabulated; allowed: pi n / 6 with n sigma^3 "
            "one of 0.10, 0.15, ..., 0.85 and 0.86, 0.87, ..., 1.01"
        )
    sigma = 2.0 * np.asarray(radius)
    d = table[index, 1] * sigma * np.sqrt(np.asarray(temperature) / np.asarray(mass))
    return d[()] if np.ndim(d) == 0 else d
