"""The velocity distribution of a granular gas in its first Sonine approximation: the second
Sonine coefficient a2 of the homogeneous cooling state and of the white-noise driven state,
and the driven gas' steady temperature.

Scaled velocities c = v / v0, v0 = sqrt(2 T / m), and F(c) = phi(c) [1 + a2 S2(c^2)] with the
Maxwellian phi and S2(x) = x^2/2 - (d+2) x/2 + d (d+2)/8, so that ``<c^4> = d (d+2) (1 + a2)/4``:
``a2 = d <v^4> / ((d+2) <v^2>^2) - 1`` (granular.moments measures it).

The collision moments mu_p = -int dc c^p I(F, F) (I the Boltzmann-Enskog collision integral
of smooth inelastic hard spheres, restitution alpha), to first order in a2 and in units of a
common factor K (Brilliantov & Poeschel, Phys. Rev. E 61, 2809 (2000), their mu2 and mu4 in
3D; van Noije & Ernst, Granular Matter 1, 57 (1998), for any d):

    mu2 / K = (1 - alpha^2) (1 + 3 a2 / 16)
    mu4 / K = (1 - alpha^2) (d + 3/2 + alpha^2)
              + a2 [(3/32) (1 - alpha^2) (10 d + 39 + 10 alpha^2) + (d - 1)(1 + alpha)]

(in 3D the bracket is Brilliantov & Poeschel's (3/32)(1 - alpha^2)(69 + 10 alpha^2) + 2 (1 + alpha);
tests/test_sonine.py integrates the collision moments by Monte Carlo and checks every
coefficient).  A steady scaled distribution needs:

- homogeneous cooling: mu4 = (d + 2) (1 + a2) mu2 (the scaled distribution does not change
  while T decays); linearised in a2 this gives van Noije & Ernst's
  ``a2 = 16 (1 - alpha)(1 - 2 alpha^2) / (9 + 24 d - alpha (41 - 8 d) + 30 alpha^2 (1 - alpha))``;
- white noise (dT/dt = m xi0^2 - zeta T, the noise adding 2 (d+2) xi0^2 <v^2> to d<v^4>/dt):
  mu4 = (d + 2) mu2, linear in a2 already: van Noije & Ernst's
  ``a2 = 16 (1 - alpha)(1 - 2 alpha^2)
  / (73 + 56 d - 3 alpha (35 + 8 d) + 30 alpha^2 (1 - alpha))``.

Both vanish for elastic gases and change sign at alpha = 1/sqrt(2).  ``approximation=
"nonlinear"`` solves the cooling state's condition without linearising the product
(1 + a2) mu2 (the root nearest the linear one): the size of that difference is a measure
of the first-order theory's own uncertainty.  Brilliantov & Poeschel (2000) also keep the
a2^2 terms of mu2 and mu4 themselves (their stable root is close to the linear one), and
Brilliantov & Poeschel (Europhys. Lett. 74, 424 (2006)) show that the Sonine expansion
itself breaks down for alpha below about 0.6, where a3 and higher grow as large as a2 and
the overpopulated high-energy tail dominates: there no first-order a2 is reliable
(docs/driven.md).  Those a2^2 coefficients are not implemented here.

Dense gases (Enskog): the contact value chi multiplies every collision moment alike, so
a2 does not depend on the density; the temperature does, through the collision frequency.
"""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .haff import _constant_xi, collision_frequency

APPROXIMATIONS = ("linear", "nonlinear", "maxwell")


def _coefficients(alpha, dim):
    """(a0, a1, b0, b1): mu2 / K = a0 + a1 a2 and mu4 / K = b0 + b1 a2 (module docstring)."""
    alpha = np.asarray(alpha, dtype=np.float64)
    loss = 1.0 - alpha**2
    a0 = loss
    a1 = 3.0 / 16.0 * loss
    b0 = loss * (dim + 1.5 + alpha**2)
    b1 = 3.0 / 32.0 * loss * (10 * dim + 39 + 10 * alpha**2) + (dim - 1) * (1.0 + alpha)
    return a0, a1, b0, b1


def _approximation(approximation, allowed):
    if approximation not in allowed:
        raise ValueError(f"approximation must be one of {allowed}, got {approximation!r}")
    return approximation


@keyword_only()
def sonine_a2_cooling(
    *, restitution: FloatOrArray, dim: int = 3, approximation: str = "linear"
) -> FloatOrArray:
    """Second Sonine coefficient a2 of the homogeneous cooling state (module docstring).

    Parameters
    ----------
    restitution : float or array
        Constant coefficient of restitution xi = alpha in [0, 1] (dimensionless).
    dim : int
        2 or 3.
    approximation : {"linear", "nonlinear", "maxwell"}
        "linear": van Noije & Ernst (1998)'s first-order result,
        ``16 (1 - xi)(1 - 2 xi^2) / (9 + 24 d - xi (41 - 8 d) + 30 xi^2 (1 - xi))``
        (Brilliantov & Poeschel 2000 in 3D); "nonlinear": the same truncated moment equation
        mu4 = (d+2)(1+a2) mu2 solved as the quadratic it is; "maxwell": 0.

    Returns
    -------
    float or array
        a2 (dimensionless): negative for xi > 1/sqrt(2), positive below.
    """
    _check_dim(dim)
    _approximation(approximation, APPROXIMATIONS)
    alpha = np.asarray(_constant_xi(restitution), dtype=np.float64)
    if approximation == "maxwell":
        return _scalar(np.zeros_like(alpha))
    if approximation == "linear":
        a2 = (
            16.0
            * (1.0 - alpha)
            * (1.0 - 2.0 * alpha**2)
            / (9.0 + 24.0 * dim - alpha * (41.0 - 8.0 * dim) + 30.0 * alpha**2 * (1.0 - alpha))
        )
        return _scalar(a2)
    # (d+2)(1+x)(a0 + a1 x) = b0 + b1 x, per unit (1 - alpha^2) where that is not 0
    a0, a1, b0, b1 = _coefficients(alpha, dim)
    with np.errstate(divide="ignore", invalid="ignore"):
        q2 = (dim + 2) * a1
        q1 = (dim + 2) * (a0 + a1) - b1
        q0 = (dim + 2) * a0 - b0
        root = np.sqrt(q1**2 - 4.0 * q2 * q0)
        # the root nearest the linear one, -q0 / q1, in a form without cancellation
        a2 = np.where(q2 == 0.0, -q0 / q1, 2.0 * q0 / (-q1 - np.sign(q1) * root))
    return _scalar(np.where(alpha == 1.0, 0.0, a2))


@keyword_only()
def sonine_a2_driven(
    *,
    restitution: FloatOrArray,
    dim: int = 3,
    approximation: str = "linear",
    kick: FloatOrArray = 0.0,
) -> FloatOrArray:
    """Second Sonine coefficient a2 of the steady state heated by white noise (module
    docstring; granular.WhiteNoise drives a gas so).

    Parameters
    ----------
    restitution : float or array
        Constant coefficient of restitution xi in [0, 1] (dimensionless).
    dim : int
        2 or 3.
    approximation : {"linear", "maxwell"}
        "linear": van Noije & Ernst (1998),
        ``16 (1 - xi)(1 - 2 xi^2) / (73 + 56 d - 3 xi (35 + 8 d) + 30 xi^2 (1 - xi))``
        (the moment equation mu4 = (d+2) mu2 is linear in a2 to this order, so it has no
        "nonlinear" form); "maxwell": 0.
    kick : float or array
        For kicks of finite size (granular.WhiteNoise at a finite rate): one kick's velocity
        variance per component over T/m, ``m strength / (rate T)`` (0: white noise).  Each
        kick adds ``d (d+2) s^4`` to <v^4> besides the diffusion's ``2 (d+2) s^2 <v^2>``, so
        the steady state needs mu4 = (d + 2)(1 + kick/2) mu2 exactly (the fourth
        Kramers-Moyal term), which this solves to the same first order.

    Returns
    -------
    float or array
        a2 (dimensionless): smaller in size than the cooling state's (0.8 to 0.5 times it
        for xi from 0.9 to 0.5 in 3D).
    """
    _check_dim(dim)
    _approximation(approximation, ("linear", "maxwell"))
    alpha = np.asarray(_constant_xi(restitution), dtype=np.float64)
    if approximation == "maxwell":
        return _scalar(np.zeros_like(alpha))
    if np.all(np.asarray(kick) == 0.0):
        a2 = (
            16.0
            * (1.0 - alpha)
            * (1.0 - 2.0 * alpha**2)
            / (
                73.0
                + 56.0 * dim
                - 3.0 * alpha * (35.0 + 8.0 * dim)
                + 30.0 * alpha**2 * (1.0 - alpha)
            )
        )
        return _scalar(a2)
    a0, a1, b0, b1 = _coefficients(alpha, dim)
    g = (dim + 2) * (1.0 + 0.5 * np.asarray(kick, dtype=np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        a2 = (b0 - g * a0) / (g * a1 - b1)
    return _scalar(np.where(alpha == 1.0, 0.0, a2))


@keyword_only()
def driven_temperature(
    *,
    strength: FloatOrArray,
    density: FloatOrArray,
    radius: FloatOrArray,
    restitution: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
    approximation: str = "linear",
    kick: FloatOrArray = 0.0,
) -> FloatOrArray:
    """Steady temperature of a gas heated by white noise of strength xi0^2: the heating
    ``dT/dt = m xi0^2`` equals the collisional cooling ``zeta T`` with
    ``zeta = (1 - xi^2)(1 + 3 a2 / 16) omega(T) / d`` (omega the Enskog collision frequency,
    theory.collision_frequency, with the contact value of theory.contact_value; the factor
    1 + 3 a2 / 16 is mu2's, module docstring), so
    ``T = [d m xi0^2 / ((1 - xi^2)(1 + 3 a2/16) omega(T=1))]^(2/3)``.

    Parameters
    ----------
    strength : float or array
        The noise's xi0^2 [eps / (m time)]: each velocity component diffuses as
        ``<dv^2> = xi0^2 dt`` (granular.WhiteNoise's ``strength``).
    density : float or array
        Number density N/V [L^-d].
    radius : float or array
        Particle radius [L].
    restitution : float or array
        Constant coefficient of restitution xi in [0, 1] (1: no steady state, inf).
    mass : float or array
        Particle mass [m].
    dim : int
        2 or 3.
    eta : float or array, optional
        Packing fraction for the contact value (default: from density and radius).
    approximation : {"linear", "maxwell"}
        a2 from ``sonine_a2_driven`` (first order), or 0 (the Maxwellian estimate).
    kick : float or array
        One kick's velocity variance per component over T/m (``sonine_a2_driven``); 0:
        white noise.  The energy input does not depend on it, only a2 does.

    Returns
    -------
    float or array
        The steady granular temperature T [eps].
    """
    _approximation(approximation, ("linear", "maxwell"))
    xi = np.asarray(_constant_xi(restitution), dtype=np.float64)
    a2 = sonine_a2_driven(restitution=xi, dim=dim, approximation=approximation, kick=kick)
    omega1 = collision_frequency(
        density=density, radius=radius, temperature=1.0, mass=mass, dim=dim, eta=eta
    )
    with np.errstate(divide="ignore"):
        base = (
            dim * mass * np.asarray(strength) / ((1.0 - xi**2) * (1.0 + 3.0 * a2 / 16.0) * omega1)
        )
    return _scalar(base ** (2.0 / 3.0))


def _scalar(x):
    x = np.asarray(x, dtype=np.float64)
    return float(x) if x.ndim == 0 else x


# the value 1/sqrt(2) where a2 changes sign, for the docs and tests
A2_SIGN_CHANGE = 1.0 / math.sqrt(2.0)
