"""Uniform shear flow (USF) of a granular gas at the Navier-Stokes level: the steady state
of a sheared gas of inelastic hard spheres (disks) in which viscous heating balances
collisional cooling, from the energy balance

    d T / dt = -(2 / (d n)) P_xy gamma - zeta T = 0,   P_xy = -eta gamma   (Navier-Stokes)
    =>  gamma^2 eta = (d / 2) n T zeta,

with Garzo & Dufty's Enskog viscosity and cooling rate of the homogeneous cooling state
(Phys. Rev. E 59, 5895 (1999), eqs. (7.4), (7.6), (7.8) in the first Sonine approximation with
a2 = 0: ``theory.shear_viscosity``, ``theory.cooling_rate``).  Both scale as sqrt(T), so
the balance fixes the reduced shear rate gamma* = gamma sigma / sqrt(T / m) for each
restitution and packing, and the temperature as T = m (gamma sigma / gamma*)^2.

What this is not: the Enskog kinetic theory of USF (Montanero, Garzo, Santos & Brey,
J. Fluid Mech. 389, 391 (1999); Santos, Garzo & Dufty, Phys. Rev. E 69, 061303 (2004);
Montanero, Garzo, Alam & Luding, Granular Matter 8, 103 (2006)).  The steady USF is not
a Navier-Stokes state: its shear rate is set by the inelasticity, gamma* ~ sqrt(1 - xi^2),
so it is small only for nearly elastic grains; at xi = 0.7 the velocity distribution is
anisotropic (normal-stress differences, zero at Navier-Stokes order) and the viscosity
shear-thinned.  Those papers' closed forms could not be looked up for this version (only
their abstracts were reachable), so they are not implemented; granular's reproduce rows
state how far the simulated USF lies from this Navier-Stokes balance.
"""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .clustering import cooling_rate, shear_viscosity


def _reduced(eta, restitution, dim):
    """(n sigma^d, eta*, zeta*) at sigma = m = T = 1: the reduced density, Garzo-Dufty
    viscosity and cooling rate."""
    _check_dim(dim)
    r = 0.5
    unit = 4.0 / 3.0 * math.pi * r**3 if dim == 3 else math.pi * r**2
    density = np.asarray(eta, dtype=np.float64) / unit
    kw = dict(density=density, radius=r, restitution=restitution, temperature=1.0, dim=dim, eta=eta)
    return density, shear_viscosity(**kw), cooling_rate(**kw)


@keyword_only("eta")
def usf_shear_rate(eta: FloatOrArray, *, restitution: FloatOrArray, dim: int = 3) -> FloatOrArray:
    """The reduced shear rate gamma* = gamma sigma / sqrt(T / m) of the steady uniform shear
    flow at Navier-Stokes order (module docstring)::

        gamma*^2 = (d / 2) n* zeta* / eta*

    with n* = n sigma^d and eta*, zeta* Garzo & Dufty's viscosity and cooling rate reduced
    by sigma, m and T.  Zero at restitution 1 (an elastic gas has no steady state: it
    heats).

    Parameters
    ----------
    eta : float or array
        Packing fraction (area fraction in 2D), in [0, 1).
    restitution : float in [0, 1]
        Constant coefficient of restitution xi (dimensionless).
    dim : 2 or 3

    Returns
    -------
    float or array
        gamma* (dimensionless).
    """
    density, visc, zeta = _reduced(eta, restitution, dim)
    return np.sqrt(0.5 * dim * density * zeta / visc)


@keyword_only("shear_rate")
def usf_temperature(
    shear_rate: FloatOrArray,
    *,
    eta: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
) -> FloatOrArray:
    """The steady temperature of a granular gas sheared at ``shear_rate`` at Navier-Stokes
    order: T = m (gamma sigma / gamma*)^2 with gamma* = ``usf_shear_rate`` (sigma = 2 r).
    Infinite at restitution 1.

    Parameters
    ----------
    shear_rate : float or array
        The shear rate gamma = d u_x / d y (1 / time), > 0.
    eta : float
        Packing fraction (area fraction in 2D), in [0, 1).
    radius : float
        Particle radius (L).
    restitution : float in [0, 1]
        Constant coefficient of restitution xi (dimensionless).
    mass : float
        Particle mass (m).
    dim : 2 or 3

    Returns
    -------
    float or array
        T, an energy (k_B = 1).
    """
    g = usf_shear_rate(eta, restitution=restitution, dim=dim)
    with np.errstate(divide="ignore"):
        return mass * (np.asarray(shear_rate) * 2.0 * np.asarray(radius) / g) ** 2


@keyword_only("eta")
def usf_viscosity(eta: FloatOrArray, *, restitution: FloatOrArray, dim: int = 3) -> FloatOrArray:
    """The reduced shear viscosity eta* = eta sigma^(d-1) / sqrt(m T) at Navier-Stokes order:
    Garzo & Dufty's (``theory.shear_viscosity``) reduced, independent of T.  In USF the
    measured -P_xy / gamma falls below it as the shear thins the gas (Enskog USF theory,
    module docstring).

    Parameters
    ----------
    eta : float or array
        Packing fraction (area fraction in 2D), in [0, 1).
    restitution : float in [0, 1]
        Constant coefficient of restitution xi (dimensionless).
    dim : 2 or 3

    Returns
    -------
    float or array
        eta* (dimensionless).
    """
    return _reduced(eta, restitution, dim)[1]
