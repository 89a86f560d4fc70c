"""The end of homogeneous cooling: the cooling rate, Enskog's shear viscosity of a granular
gas and the critical box size of the shear instability, with the linear growth of the
slowest shear mode."""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .equation_of_state import contact_value
from .haff import _constant_xi, _eta, collision_frequency

# Sources: Goldhirsch & Zanetti 1993, Phys. Rev. Lett. 70, 1619 (the instability); Brey,
# Ruiz-Montero & Cubero 1999, Phys. Rev. E 60, 3150 and Garzo 2005, Phys. Rev. E 72, 021106
# (linear stability of the Navier-Stokes equations about the homogeneous cooling state,
# dilute and Enskog); transport coefficients of the Enskog equation for inelastic hard
# spheres/disks from Garzo & Dufty 1999, Phys. Rev. E 59, 5895 (their eqs for eta*, in d
# dimensions as quoted in Garzo 2005).  Approximations: Navier-Stokes order (wavelengths
# long against the mean free path), first Sonine approximation with the HCS' fourth
# cumulant a2 set to 0 (the Maxwellian approximation of the rest of this module: a few
# percent for xi >= 0.3), Enskog's molecular chaos with the contact value ``contact_value``
# (moderate densities; velocity correlations near the threshold are neglected).


@keyword_only(
    "density", "radius", "xi", "temperature", "mass", "dim", "eta", renamed={"xi": "restitution"}
)
def cooling_rate(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Cooling rate zeta of the homogeneous cooling state, ``dT/dt = -zeta T``:
    ``zeta = (1 - xi^2) omega / d`` with omega the Enskog collision frequency (2.42); the
    same Maxwellian estimate as ``haff_tau0`` (``zeta(T0) = 2 / tau0``), equal to Garzo &
    Dufty's ``zeta* = (d + 2) / (4 d) chi (1 - xi^2)`` at a2 = 0 in units of ``n T / eta0``."""
    xi = _constant_xi(restitution)
    xi = np.asarray(xi, dtype=np.float64)
    omega = collision_frequency(
        density=density, radius=radius, temperature=temperature, mass=mass, dim=dim, eta=eta
    )
    return (1.0 - xi**2) * omega / dim


@keyword_only(
    "density", "radius", "xi", "temperature", "mass", "dim", "eta", renamed={"xi": "restitution"}
)
def shear_viscosity(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Enskog shear viscosity of a granular gas of inelastic hard spheres (disks), Garzo &
    Dufty 1999 (a2 = 0)::

        eta     = eta0 [ eta_k* (1 + 2^(d-1)/(d+2) phi chi (1+xi)) + d/(d+2) gamma* ]
        eta_k*  = (1 - 2^(d-2)/(d+2) (1+xi)(1-3 xi) phi chi) / (nu* - zeta*/2)
        nu*     = 3/(4d) chi (1 - xi + 2d/3)(1 + xi),  zeta* = (d+2)/(4d) chi (1 - xi^2)
        gamma*  = 2^(2d+1) / (pi (d+2)) phi^2 chi (1 + xi)

    with phi the packing fraction, chi = ``contact_value(phi)`` and eta0 the dilute elastic
    viscosity, ``(5 / (16 sigma^2)) sqrt(m T / pi)`` in 3D and ``(1 / (2 sigma)) sqrt(m T /
    pi)`` in 2D (sigma = 2 r).  At xi = 1 this is Enskog's first Sonine viscosity: 3D
    ``eta0 [(1 + 8 phi chi / 5)^2 / chi + 768 phi^2 chi / (25 pi)]`` (Chapman & Cowling),
    2D ``eta0 [(1 + phi chi)^2 / chi + 8 phi^2 chi / pi]`` (Gass 1971)."""
    xi = _constant_xi(restitution)
    _check_dim(dim)
    xi = np.asarray(xi, dtype=np.float64)
    phi = _eta(density, radius, dim, eta)
    chi = contact_value(phi, dim=dim)
    sigma = 2.0 * radius
    root = np.sqrt(mass * np.asarray(temperature) / math.pi)
    eta0 = 5.0 / (16.0 * sigma**2) * root if dim == 3 else root / (2.0 * sigma)
    d = dim
    nu = 3.0 / (4 * d) * chi * (1 - xi + 2 * d / 3) * (1 + xi)
    zeta = (d + 2) / (4 * d) * chi * (1 - xi**2)
    eta_k = (1 - 2 ** (d - 2) / (d + 2) * (1 + xi) * (1 - 3 * xi) * phi * chi) / (nu - zeta / 2)
    gamma = 2 ** (2 * d + 1) / (math.pi * (d + 2)) * phi**2 * chi * (1 + xi)
    return eta0 * (
        eta_k * (1 + 2 ** (d - 1) / (d + 2) * phi * chi * (1 + xi)) + d / (d + 2) * gamma
    )


@keyword_only("density", "radius", "xi", "dim", "eta", renamed={"xi": "restitution"})
def critical_box_size(
    *,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Side of a periodic box above which the homogeneous cooling state is unstable to shear
    modes (vortices), ``L_c = 2 pi / k_c``.

    A transverse velocity mode of wave number k decays by viscosity at the rate
    ``eta k^2 / (n m)`` while the thermal speed it is measured against decays at ``zeta /
    2``; it grows relative to the thermal motion when ``k < k_c``, ``k_c^2 = n m zeta / (2
    eta)`` (Goldhirsch & Zanetti 1993; Brey et al. 1999; Garzo 2005: ``k*_perp =
    sqrt(zeta* / (2 eta*))`` in reduced units).  The smallest wave number of a periodic box
    is 2 pi / L_max, so the box is unstable when L_max > L_c.  T and m cancel.  Dilute and
    weakly inelastic in 3D this is ``L_c = 2 pi lambda sqrt(15 pi / (16 (1 - xi^2)))``
    with the mean free path ``lambda = 1 / (sqrt(2) pi n sigma^2)``.  The longitudinal
    (clustering) mode goes unstable at a larger size, so L_c is where homogeneous cooling
    first ends.  Infinite at xi = 1.

    Parameters
    ----------
    density : float
        Number density N / V (N / A in 2D) [L^-d].
    radius : float
        Particle radius [L].
    restitution : float in [0, 1]
        Constant coefficient of restitution xi (dimensionless).
    dim : 2 or 3
    eta : float, optional
        Packing fraction (dimensionless; default: from density and radius).

    Returns
    -------
    float
        L_c, in the units of radius.

    References
    ----------
    Goldhirsch & Zanetti 1993, Phys. Rev. Lett. 70, 1619; Brey, Ruiz-Montero & Cubero 1999,
    Phys. Rev. E 60, 3150; Garzo 2005, Phys. Rev. E 72, 021106; Garzo & Dufty 1999, Phys.
    Rev. E 59, 5895.  Valid at Navier-Stokes order (L_c many mean free paths) and where the
    Enskog transport coefficients hold (packing fraction up to about 0.25 in 3D).
    """
    xi = _constant_xi(restitution)
    xi = np.asarray(xi, dtype=np.float64)
    zeta = cooling_rate(
        density=density, radius=radius, restitution=xi, temperature=1.0, mass=1.0, dim=dim, eta=eta
    )
    visc = shear_viscosity(
        density=density, radius=radius, restitution=xi, temperature=1.0, mass=1.0, dim=dim, eta=eta
    )
    with np.errstate(divide="ignore"):
        lc = 2 * math.pi * np.sqrt(2 * visc / (density * zeta))
    return lc[()] if np.ndim(lc) == 0 else lc


@keyword_only("t", "tau0", "box", "critical")
def shear_mode_growth(
    t: FloatOrArray, *, tau0: FloatOrArray, box: FloatOrArray, critical: FloatOrArray
) -> FloatOrArray:
    """Factor by which the energy of the slowest shear mode (k = 2 pi / box) grows relative
    to the thermal energy by time t in linear theory, ``(1 + t/tau0)^(2 (1 - (L_c/L)^2))``:
    its rate ``(zeta/2)(1 - k^2/k_c^2)`` integrated over Haff's law, where
    ``int zeta/2 dt = ln(1 + t/tau0)``.  Below 1 (decay) for a box below L_c."""
    t = np.asarray(t, dtype=np.float64)
    q2 = (np.asarray(critical, dtype=np.float64) / box) ** 2
    return (1.0 + t / tau0) ** (2.0 * (1.0 - q2))


@keyword_only("box", "critical")
def shear_mode_level(box: FloatOrArray, *, critical: FloatOrArray) -> FloatOrArray:
    """Level at which the transverse current correlation of the slowest shear mode
    (k = 2 pi / box, 1 for an uncorrelated gas) settles in the homogeneous cooling state of
    a box below the critical size: ``1 / (1 - (L / L_c)^2)`` -- linear fluctuating
    hydrodynamics with the elastic noise amplitude (van Noije, Ernst, Brito & Orza 1997,
    Phys. Rev. Lett. 79, 411), where the mode's relaxation rate in Haff's time
    ``(zeta/2)(k^2/k_c^2 - 1)`` balances the noise.  Infinite at and above L_c."""
    x2 = (np.asarray(box, dtype=np.float64) / critical) ** 2
    with np.errstate(divide="ignore"):
        level = np.where(x2 < 1, 1.0 / (1.0 - np.minimum(x2, 1.0)), np.inf)
    return level[()] if level.ndim == 0 else level
