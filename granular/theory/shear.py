"""Uniform shear flow (USF) of a granular gas: the steady state of a sheared gas of inelastic
hard spheres (disks) in which viscous heating balances collisional cooling.

Navier-Stokes order (``usf_shear_rate``, ``usf_temperature``, ``usf_viscosity``): the energy
balance

    d T / dt = -(2 / (d n)) P_xy gamma - zeta T = 0,   P_xy = -eta gamma   (Navier-Stokes)
    =>  gamma^2 eta = (d / 2) n T zeta,

with Garzo & Dufty's Enskog viscosity and cooling rate of the homogeneous cooling state
(Phys. Rev. E 59, 5895 (1999), eqs. (7.4), (7.6), (7.8) in the first Sonine approximation with
a2 = 0: ``theory.shear_viscosity``, ``theory.cooling_rate``).  Both scale as sqrt(T), so
the balance fixes the reduced shear rate gamma* = gamma sigma / sqrt(T / m) for each
restitution and packing, and the temperature as T = m (gamma sigma / gamma*)^2.

The steady USF is not a Navier-Stokes state: its shear rate is set by the inelasticity,
gamma* ~ sqrt(1 - xi^2), so the velocity distribution is anisotropic (normal-stress
differences, zero at Navier-Stokes order) and the viscosity shear-thinned (Santos, Garzo &
Dufty, Phys. Rev. E 69, 061303 (2004); Montanero, Garzo, Alam & Luding, Granular Matter 8,
103 (2006), Enskog theory against MD in 2D and 3D).  Those papers' closed forms (Grad's
method, linear in the anisotropy) could not be read for this version (only the stored
pages' openings were reachable), so ``usf_enskog`` solves the same Enskog
kinetic equation with a stated closure instead, without further approximation:

- the exact steady balance of the kinetic second moments, a (delta_ix P^k_yj + delta_jx
  P^k_yi) = Lambda_ij, and the collisional stress P^c, both collision integrals of the
  Enskog equation (contact value chi, the mean flow's difference a sigma s_y across a
  contact included exactly);
- closed with the anisotropic (triaxial) Gaussian of covariance P^k / (n m) for the
  peculiar velocities (the closure of Jenkins & Richman, J. Fluid Mech. 192, 313 (1988),
  and of Saha & Alam, J. Fluid Mech. 795, 549 (2016); to first order in the anisotropy it is
  Grad's);
- the collision integrals then reduce to truncated-Gaussian moments along each contact
  direction, integrated by quadrature (granular/theory/_usf_enskog.py), and the d + 1
  steady equations are solved for the anisotropy and gamma*.

Checks (tests/test_theory_usf.py): at xi = 1 and a -> 0 its linear response is Enskog's
first-Sonine viscosity (``theory.enskog_viscosity``) and its pressure the virial
(Carnahan-Starling's chi) to 1e-9; as xi -> 1 its gamma* and eta* approach the
Navier-Stokes ones above linearly in 1 - xi (Garzo & Dufty's coefficients, which include
the collisional-transfer terms); its cooling rate at zero shear is Garzo & Dufty's zeta*.
In the dilute limit, linearised in the anisotropy, it gives the closed Grad form of
``usf_grad_dilute``.  The closure's own uncertainty is second order in the anisotropy:
``usf_grad_dilute`` and the dilute ``usf_enskog`` differ by 1.3 % in gamma* at xi = 0.9.
"""

from __future__ import annotations

import math
from typing import NamedTuple

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


class USFState(NamedTuple):
    """The steady uniform shear flow of ``usf_enskog`` (flow x, gradient y).  For array
    input each field is an array over the broadcast inputs (``stress`` with two trailing
    axes)."""

    shear_rate: FloatOrArray  # gamma* = gamma sigma / sqrt(T / m)
    viscosity: FloatOrArray  # eta* = -P_xy sigma^(d-1) / (gamma sqrt(m T))
    pressure: FloatOrArray  # p / (n T), p = tr(P) / d
    n1: FloatOrArray  # (P_xx - P_yy) / p
    n2: FloatOrArray  # (P_yy - P_zz) / p (0 in 2D)
    stress: np.ndarray  # P_ij / p, kinetic + collisional
    kinetic_stress: np.ndarray  # P^k_ij / p


@keyword_only("eta")
def usf_enskog(eta: FloatOrArray, *, restitution: FloatOrArray, dim: int = 3) -> USFState:
    """The steady uniform shear flow of the Enskog equation closed with the anisotropic
    Gaussian (module docstring): the reduced shear rate, shear viscosity, pressure and
    normal-stress differences.

    Parameters
    ----------
    eta : float or array
        Packing fraction (area fraction in 2D), in [0, 1): the contact value chi is
        ``theory.contact_value(eta)``.
    restitution : float or array in [0, 1)
        Constant coefficient of restitution xi (dimensionless).  At 1 there is no steady
        state (an elastic gas heats): gamma* = 0 and the other fields are NaN.
    dim : 2 or 3

    Returns
    -------
    USFState
        ``shear_rate`` gamma* = gamma sigma / sqrt(T/m), ``viscosity`` eta* = -P_xy
        sigma^(d-1) / (gamma sqrt(m T)), ``pressure`` p / (n T), ``n1`` = (P_xx - P_yy) / p,
        ``n2`` = (P_yy - P_zz) / p, ``stress`` P_ij / p and ``kinetic_stress`` P^k_ij / p
        (dimensionless; T the peculiar temperature tr(P^k) / (d n)).
    """
    from . import _usf_enskog
    from .equation_of_state import contact_value

    _check_dim(dim)
    phi_b, xi_b = np.broadcast_arrays(
        np.asarray(eta, dtype=np.float64), np.asarray(restitution, dtype=np.float64)
    )
    unit = math.pi / 6.0 if dim == 3 else math.pi / 4.0  # sigma = 1
    fields = np.full((*phi_b.shape, 5), np.nan)
    stress = np.full((*phi_b.shape, dim, dim), np.nan)
    kinetic = np.full((*phi_b.shape, dim, dim), np.nan)
    for idx in np.ndindex(phi_b.shape):
        phi, xi = float(phi_b[idx]), float(xi_b[idx])
        if xi == 1.0:
            fields[idx][0] = 0.0
            continue
        n = phi / unit
        chi = float(contact_value(phi, dim=dim))
        guess = float(usf_shear_rate(phi, restitution=xi, dim=dim))
        cov, a = _usf_enskog.solve(n, chi, xi, dim, guess)
        _, pc = _usf_enskog.moments(cov, a, n, chi, xi, dim)
        p_tensor = n * cov + pc
        p = float(np.trace(p_tensor)) / dim
        stress[idx] = p_tensor / p
        kinetic[idx] = n * cov / p
        n2 = (p_tensor[1, 1] - p_tensor[2, 2]) / p if dim == 3 else 0.0
        fields[idx] = (a, -p_tensor[0, 1] / a, p / n, (p_tensor[0, 0] - p_tensor[1, 1]) / p, n2)
    g, visc, pres, n1, n2 = (_scalar_or_array(fields[..., k]) for k in range(5))
    return USFState(g, visc, pres, n1, n2, stress, kinetic)


class USFGrad(NamedTuple):
    """The dilute Grad solution of ``usf_grad_dilute``."""

    shear_rate: FloatOrArray  # a / nu0, nu0 = n T / eta0
    viscosity: FloatOrArray  # eta / eta0
    pxx: FloatOrArray  # P_xx / p
    pyy: FloatOrArray  # P_yy / p (= P_zz / p)


@keyword_only()
def usf_grad_dilute(*, restitution: FloatOrArray, dim: int = 3) -> USFGrad:
    """The steady uniform shear flow of the dilute (Boltzmann) gas by Grad's method with the
    collision moment linear in the anisotropy (derived here from the moment equations;
    the Navier-Stokes-order coefficients are Garzo & Dufty's at chi = 1, a2 = 0)::

        zeta* = (d+2)/(4d) (1 - xi^2),   nu* = 3/(4d) (1 + xi)(1 - xi + 2d/3)
        (a/nu0)^2 = (d/2) zeta* nu*^2 / (nu* - zeta*),   eta/eta0 = (nu* - zeta*) / nu*^2
        P_xx/p = 1 + (d-1) zeta*/nu*,   P_yy/p = P_zz/p = 1 - zeta*/nu*

    (the yy balance gives P_yy, the xy balance P_xy = -a P_yy / nu, and the trace the
    energy balance -a P_xy = (d/2) zeta p).  eta0 = (d+2) Gamma(d/2) sqrt(m T) / (8
    pi^((d-1)/2) sigma^(d-1)) is the elastic first-Sonine viscosity and nu0 = n T / eta0.
    The closure keeps no second-order anisotropy, so P_yy = P_zz here; ``usf_enskog``'s
    dilute limit agrees with it to second order in 1 - xi.

    Parameters
    ----------
    restitution : float or array in [0, 1]
        Constant coefficient of restitution xi (dimensionless); 1 gives the equilibrium
        (zero shear rate, eta = eta0, isotropic).
    dim : 2 or 3

    Returns
    -------
    USFGrad
        ``shear_rate`` a / nu0, ``viscosity`` eta / eta0, ``pxx`` and ``pyy`` (P / p), all
        dimensionless.
    """
    _check_dim(dim)
    xi = np.asarray(restitution, dtype=np.float64)
    d = dim
    zeta = (d + 2) / (4 * d) * (1.0 - xi**2)
    nu = 3.0 / (4 * d) * (1.0 + xi) * (1.0 - xi + 2.0 * d / 3.0)
    a = np.sqrt(0.5 * d * zeta * nu**2 / (nu - zeta))
    return USFGrad(
        _scalar_or_array(a),
        _scalar_or_array((nu - zeta) / nu**2),
        _scalar_or_array(1.0 + (d - 1) * zeta / nu),
        _scalar_or_array(1.0 - zeta / nu),
    )


def _scalar_or_array(x):
    x = np.asarray(x, dtype=np.float64)
    return float(x) if x.ndim == 0 else x
