"""Viscoelastic granular gases: the restitution series' cooling law, diffusion and MSD."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import restitution as _restitution
from .._params import keyword_only
from ._numerics import FloatOrArray
from .haff import LangevinCoefficients, collision_frequency, diffusion_d0

# Two parts.  (1) The homogeneous cooling of a gas of viscoelastic spheres, whose restitution
# depends on the normal impact speed g (Brilliantov, Spahn, Hertzsch & Poeschel, PRE 53, 5382
# (1996); the series of Schwager & Poeschel, PRE 57, 650 (1998)):
#
#     eps(g) = 1 - C1 A kappa^(2/5) g^(1/5) + C2 A^2 kappa^(4/5) g^(2/5) - ...,
#
# A the dissipative constant (a time), kappa = (3/2)^(3/2) Y sqrt(R_eff) / (m_eff (1 - nu^2))
# from Young's modulus Y, Poisson's ratio nu and the effective radius and mass.  Everything
# here depends on them only through the one material number ``a_kappa`` = A kappa^(2/5)
# (units of (time/length)^(1/5)), the coefficient of g^(1/5) in 1 - eps over C1.  The
# series is one in the dimensionless delta = a_kappa (4T/m)^(1/10) (a_kappa times the
# 1/5-th power of the mean squared normal impact speed 4T/m of a Maxwellian gas): it holds
# while delta << 1, i.e. for impacts slow against the speed at which eps would vanish.
# Brilliantov & Poeschel (Kinetic Theory of Granular Gases, OUP 2004, ch. 8; PRE 61, 5573
# (2000)) write their small parameter with the thermal speed in another normalisation; it
# is the same combination up to a numerical factor, so the cooling law below is theirs.
#
# The power-law UDSBM that models such a gas (exponent 5/6) is in ``udsbm``.

# the engine's constants (granular/restitution.py, csrc/restitution.h), so theory and the
# law applied at every collision are one: C1 = 1.15345, C2 = (3/5) C1^2 = 0.79827
VISCOELASTIC_C1 = _restitution.C1


VISCOELASTIC_C2 = _restitution.C2


def _collision_moment(p: float, temperature: FloatOrArray, mass: float) -> FloatOrArray:
    """<g^p> over collisions of a Maxwellian gas, g the normal impact speed: collisions
    weight the normal relative velocity (a Gaussian of variance 2T/m) by g, so g has the
    density (g/s^2) exp(-g^2 / 2 s^2), s^2 = 2T/m, and <g^p> = (4T/m)^(p/2) Gamma(1 + p/2)
    (p = 2 gives 4T/m: the constant-xi loss (1 - xi^2) T of ``haff_tau0``)."""
    return (4.0 * np.asarray(temperature, dtype=np.float64) / mass) ** (p / 2) * math.gamma(
        1 + p / 2
    )


# a_kappa arguments take the number or the engine's law (``restitution.Viscoelastic``)
AKappa = float | _restitution.Viscoelastic


def _check_a_kappa(a_kappa: AKappa) -> float:
    """a_kappa as a float: a ``Viscoelastic`` law gives its ``a_kappa`` (A kappa^(2/5), the
    same number: the engine's delta = A kappa^(2/5) v^(1/5)); another law is refused."""
    if isinstance(a_kappa, _restitution.Viscoelastic):
        return a_kappa.a_kappa
    if isinstance(a_kappa, _restitution.RestitutionLaw):
        raise TypeError(
            f"the viscoelastic theory needs a Viscoelastic law or its a_kappa, got {a_kappa!r}"
        )
    a_kappa = float(a_kappa)
    if not (a_kappa >= 0 and math.isfinite(a_kappa)):
        raise ValueError(
            f"a_kappa (A kappa^(2/5), the viscoelastic dissipation) must be >= 0 and finite, "
            f"got {a_kappa}"
        )
    return a_kappa


@keyword_only("temperature")
def viscoelastic_delta(
    temperature: FloatOrArray, *, a_kappa: AKappa, mass: float = 1.0
) -> FloatOrArray:
    """The small parameter of the viscoelastic restitution series at a temperature,
    ``delta = a_kappa (4 T / m)^(1/10)``: 1 - eps at the mean squared impact speed is about
    C1 delta.  The series, and every viscoelastic formula here, needs delta << 1.

    Parameters
    ----------
    a_kappa : A kappa^(2/5) of eps(g) = 1 - C1 A kappa^(2/5) g^(1/5) + ... (Schwager &
        Poeschel 1998), in (time/length)^(1/5): ``Viscoelastic.a_kappa``, or the law itself
    temperature, mass : T (k_B = 1) and the particle mass

    Returns
    -------
    delta, dimensionless
    """
    return _check_a_kappa(a_kappa) * (4.0 * np.asarray(temperature, dtype=np.float64) / mass) ** 0.1


@keyword_only("temperature")
def viscoelastic_cooling_rate(
    temperature: FloatOrArray,
    *,
    a_kappa: AKappa,
    density: float,
    radius: float,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
    order: int = 1,
) -> FloatOrArray:
    """Cooling rate zeta(T) of a viscoelastic gas, dT/dt = -zeta(T) T, in the Maxwellian
    approximation, to first or second order in the restitution series.

    Each collision of equal masses loses (m/4)(1 - eps(g)^2) g^2; averaged over collisions
    (``_collision_moment``) and multiplied by the collision frequency omega(T) of
    ``collision_frequency`` over the dimension (as ``haff_tau0`` does for constant xi),
    with 1 - eps^2 = 2 C1 u - (C1^2 + 2 C2) u^2 + O(u^3), u = a_kappa g^(1/5):

        zeta_1 = (2/d) C1 Gamma(21/10) omega(T) delta(T),
        zeta_2 = -(1/d) (C1^2 + 2 C2) Gamma(11/5) omega(T) delta(T)^2,

    delta(T) = a_kappa (4T/m)^(1/10) (``viscoelastic_delta``).  zeta_1 ~ T^(3/5) gives the
    T^(-5/3) law (``viscoelastic_temperature``).

    Parameters
    ----------
    temperature : T [eps]
    a_kappa : A kappa^(2/5) [(time/L)^(1/5)], or a ``restitution.Viscoelastic`` law (see
        ``viscoelastic_delta``)
    density : number density N / V (N / A in 2D) [L^-d]
    radius, mass, dim, eta : as for ``collision_frequency``
    order : 1 (zeta_1) or 2 (zeta_1 + zeta_2)

    Returns
    -------
    zeta(T), the rate of dT/dt = -zeta T

    Raises
    ------
    ValueError
        For a negative or non-finite a_kappa, or an order other than 1 or 2.

    References
    ----------
    Schwager & Poeschel, PRE 57, 650 (1998) (the series, C1, C2); Brilliantov & Poeschel,
    PRE 61, 5573 (2000) and Kinetic Theory of Granular Gases (OUP 2004), ch. 8 (the
    cooling of viscoelastic particles, there with the Sonine correction a2 of the velocity
    distribution, neglected here: a relative effect of order delta on zeta).
    """
    a_kappa = _check_a_kappa(a_kappa)
    if order not in (1, 2):
        raise ValueError(f"order must be 1 or 2, got {order}")
    T = np.asarray(temperature, dtype=np.float64)
    omega = collision_frequency(
        density=density, radius=radius, temperature=T, mass=mass, dim=dim, eta=eta
    )
    delta = a_kappa * (4.0 * T / mass) ** 0.1
    zeta = 2.0 / dim * VISCOELASTIC_C1 * math.gamma(2.1) * omega * delta
    if order == 2:
        c = VISCOELASTIC_C1**2 + 2 * VISCOELASTIC_C2
        zeta = zeta - c * math.gamma(2.2) * omega * delta**2 / dim
    return zeta[()] if np.ndim(zeta) == 0 else zeta


@keyword_only()
def viscoelastic_tau0(
    *,
    a_kappa: AKappa,
    density: float,
    radius: float,
    temperature0: float,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
) -> float:
    """Time scale tau0' of the viscoelastic cooling law, ``tau0' = 5 / (3 zeta_1(T0))``
    (``viscoelastic_cooling_rate``, order 1): dT/dt = -zeta_1(T0) (T/T0)^(3/5) T integrates
    to T0 (1 + t/tau0')^(-5/3).  Infinite for a_kappa = 0 (elastic).

    Parameters
    ----------
    a_kappa : A kappa^(2/5) [(time/L)^(1/5)], or a ``restitution.Viscoelastic`` law (see
        ``viscoelastic_delta``)
    density : number density N / V (N / A in 2D) [L^-d]
    radius, temperature0, mass, dim, eta : as for ``haff_tau0``

    Returns
    -------
    tau0'

    Raises
    ------
    ValueError
        For a negative or non-finite a_kappa.

    References
    ----------
    Brilliantov & Poeschel, Kinetic Theory of Granular Gases (OUP 2004), ch. 8; Schwager
    & Poeschel, PRE 57, 650 (1998).
    """
    zeta = float(
        viscoelastic_cooling_rate(
            temperature0,
            a_kappa=a_kappa,
            density=density,
            radius=radius,
            mass=mass,
            dim=dim,
            eta=eta,
        )
    )
    return math.inf if zeta == 0.0 else 5.0 / (3.0 * zeta)


@keyword_only("t")
def viscoelastic_temperature(t: FloatOrArray, *, temperature0: float, tau0: float) -> FloatOrArray:
    """Leading-order cooling of viscoelastic particles, ``T0 (1 + t/tau0')^(-5/3)``
    (tau0' from ``viscoelastic_tau0``): Haff's law T0 (1 + t/tau0)^-2 with the exponent
    of eps(g)'s g^(1/5).  Valid for delta(T0) << 1, in the homogeneous cooling state (no
    clusters); its relative error is of order delta(T(t)), which decays as t^(-1/6), so
    the law becomes exact at late times (the gas grows more elastic as it cools).

    References
    ----------
    Schwager & Poeschel, PRE 57, 650 (1998); Brilliantov & Poeschel, Kinetic Theory of
    Granular Gases (OUP 2004), ch. 8.
    """
    return temperature0 * (1.0 + np.asarray(t, dtype=np.float64) / tau0) ** (-5.0 / 3.0)


@keyword_only("temperature")
def viscoelastic_cooling_time(
    temperature: FloatOrArray,
    *,
    temperature0: float,
    a_kappa: AKappa,
    density: float,
    radius: float,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
) -> FloatOrArray:
    """Time at which the gas has cooled from T0 to T under the second-order rate
    zeta_1 + zeta_2 (``viscoelastic_cooling_rate``, order 2), exactly.

    With y = (T/T0)^(1/10), alpha = zeta_1(T0) and beta = -zeta_2(T0) (> 0), the rate is
    zeta = y^6 (alpha - beta y) and dt = -10 dy / (y^7 (alpha - beta y)); by partial fractions

        t = 10 [ sum_{k=0}^{5} beta^k (y^(k-6) - 1) / ((6 - k) alpha^(k+1))
                 - r ln y + r ln((alpha - beta y) / (alpha - beta)) ],   r = beta^6 / alpha^7,

    which is (5/3)((T/T0)^(-3/5) - 1) / alpha, the leading order, for beta = 0.

    Raises
    ------
    ValueError
        If zeta_2 is not smaller than zeta_1 at T0 (delta too large for the series).
    """
    material: dict[str, Any] = dict(
        a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta
    )
    alpha = float(viscoelastic_cooling_rate(temperature0, **material))
    beta = alpha - float(viscoelastic_cooling_rate(temperature0, **material, order=2))
    if 0.0 < alpha <= beta:
        delta0 = float(viscoelastic_delta(temperature0, a_kappa=a_kappa, mass=mass))
        raise ValueError(
            f"the second-order term of the restitution series ({beta:.3g}) is not smaller than "
            f"the first ({alpha:.3g}): delta = {delta0:.3g} is too large for the series"
        )
    y = (np.asarray(temperature, dtype=np.float64) / temperature0) ** 0.1
    if np.any((y <= 0) | (y > 1)):
        raise ValueError("temperature must lie in (0, T0]")
    if alpha == 0.0:
        return np.where(y == 1, 0.0, math.inf)
    out = np.zeros_like(y)
    for k in range(6):
        out += beta**k * (y ** (k - 6) - 1) / ((6 - k) * alpha ** (k + 1))
    r = beta**6 / alpha**7
    out += -r * np.log(y) + r * np.log1p(beta * (1 - y) / (alpha - beta))
    out = 10.0 * out
    return out[()] if out.ndim == 0 else out


@keyword_only("t")
def viscoelastic_temperature_second_order(
    t: FloatOrArray,
    *,
    temperature0: float,
    a_kappa: AKappa,
    density: float,
    radius: float,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
) -> FloatOrArray:
    """T(t) with the next correction of the restitution series: the inverse of
    ``viscoelastic_cooling_time`` (bisection to rounding between the leading-order laws
    with rates zeta_1 and zeta_1 + zeta_2 at T0, which bracket it).  Its difference from
    ``viscoelastic_temperature`` is relative O(delta(T0)) early and decays like delta(T(t))
    ~ t^(-1/6).  Maxwellian approximation (see ``viscoelastic_cooling_rate``)."""
    material: dict[str, Any] = dict(
        a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta
    )
    alpha = float(viscoelastic_cooling_rate(temperature0, **material))
    beta = alpha - float(viscoelastic_cooling_rate(temperature0, **material, order=2))
    t = np.asarray(t, dtype=np.float64)
    if np.any(t < 0):
        raise ValueError("t must be >= 0")
    if alpha == 0.0:  # elastic: no cooling
        return temperature0 * np.ones_like(t)[()]
    # y^6 (alpha - beta) <= zeta / ... : cooling with rate alpha y^6 is the faster bound
    lo = (1 + 0.6 * alpha * t) ** (-1 / 6)
    hi = (1 + 0.6 * max(alpha - beta, 0.0) * t) ** (-1 / 6)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        late = (
            viscoelastic_cooling_time(
                temperature0 * np.maximum(mid, 1e-300) ** 10,
                temperature0=temperature0,
                **material,
            )
            > t
        )  # cooled to mid only after t: at t it is still warmer
        lo = np.where(late, mid, lo)
        hi = np.where(late, hi, mid)
    out = temperature0 * (0.5 * (lo + hi)) ** 10
    return out[()] if out.ndim == 0 else out


@keyword_only("t")
def viscoelastic_diffusion(t: FloatOrArray, *, D0: float, tau0: float) -> FloatOrArray:
    """Self-diffusion coefficient of the viscoelastic gas, ``D(t) = D0 (1 + t/tau0')^(-5/6)``.

    Enskog's D ~ sqrt(T) / (n g2 sigma^2) (``diffusion_d0``) with T(t) of
    ``viscoelastic_temperature``; D0 is ``diffusion_d0`` at T0 with xi = 1, the
    leading order in delta (the constant-xi factor 4/(1 + xi)^2 tends to 1 as eps -> 1;
    its first-order correction and the Sonine one are of relative order delta(T(t)),
    vanishing as t^(-1/6)).  tau0' from ``viscoelastic_tau0``.

    References
    ----------
    Brilliantov & Poeschel, PRE 61, 1716 (2000) "Self-diffusion in granular gases" and
    Kinetic Theory of Granular Gases (OUP 2004), ch. 14; Bodrova, Chechkin, Cherstvy &
    Metzler, PCCP 17, 21791 (2015).
    """
    return D0 * (1.0 + np.asarray(t, dtype=np.float64) / tau0) ** (-5.0 / 6.0)


@keyword_only("t")
def msd_viscoelastic(t: FloatOrArray, *, D0: float, tau0: float, dim: int = 3) -> FloatOrArray:
    """MSD of the viscoelastic gas, total over ``dim``, from D(t) of
    ``viscoelastic_diffusion``: ``2 d int_0^t D = 12 d D0 tau0' ((1 + t/tau0')^(1/6) - 1)``,
    for t much longer than the mean collision time (it misses the ballistic start, as the
    thesis' 2.80 does for constant xi).  Late times: ``12 d D0 tau0'^(5/6) t^(1/6)``
    (``msd_viscoelastic_asymptote``), subdiffusion with exponent 1/6.

    References
    ----------
    Brilliantov & Poeschel, Kinetic Theory of Granular Gases (OUP 2004), ch. 14; Bodrova
    et al., PCCP 17, 21791 (2015).
    """
    u = np.log1p(np.asarray(t, dtype=np.float64) / tau0)
    return 12.0 * dim * D0 * tau0 * np.expm1(u / 6.0)


@keyword_only("t")
def msd_viscoelastic_asymptote(
    t: FloatOrArray, *, D0: float, tau0: float, dim: int = 3
) -> FloatOrArray:
    """Late-time power law of ``msd_viscoelastic``: ``12 d D0 tau0'^(5/6) t^(1/6)``; the
    full expression falls short of it by the factor (1 + tau0'/t)^(1/6) - (tau0'/t)^(1/6)
    (0.785 at t = 10^4 tau0', 0.853 at 10^5, 0.900 at 10^6), so it is within 10% only from
    t ~ 10^6 tau0' on -- fit late exponents, or compare with the full expression."""
    return 12.0 * dim * D0 * tau0 ** (5.0 / 6.0) * np.asarray(t, dtype=np.float64) ** (1.0 / 6.0)


@keyword_only("t")
def msd_viscoelastic_second_order(
    t: FloatOrArray,
    *,
    temperature0: float,
    a_kappa: AKappa,
    density: float,
    radius: float,
    mass: float = 1.0,
    dim: int = 3,
    eta: float | None = None,
    points: int = 4000,
) -> FloatOrArray:
    """MSD of the viscoelastic gas with the first correction in delta: ``2 d int_0^t D``
    with Enskog's D at the temperature of ``viscoelastic_temperature_second_order`` and
    the restitution factor of ``diffusion_d0``, 4 / (1 + eps_eff)^2, at

        eps_eff(T) = 1 - C1 Gamma(21/10) delta(T),

    the restitution averaged as the tagged particle's momentum loss weighs it: a collision
    takes (1 + eps(g)) g / 2 of its normal relative velocity g, and its velocity's decay
    rate is the collision average of (1 + eps(g)) g^2 / 2 over that of g^2, i.e. (1 +
    eps_eff) / 2 with <g^(11/5)> / <g^2> = Gamma(21/10) (4T/m)^(1/10)
    (``_collision_moment``; the same average as zeta_1's, derived here, not found printed).
    ``msd_viscoelastic`` is this with both corrections dropped; they raise the MSD by a
    relative O(delta(T(t))) that decays like t^(-1/6), and lower its late local slope
    towards 1/6.  Neglected: O(delta^2), the Sonine a2, velocity correlations beyond
    Enskog's (percent level at eta ~ 0.07).  The integral is the trapezoidal rule on
    ``points`` log-spaced times (relative error < 1e-4 at the default).

    Parameters
    ----------
    t : times >= 0 [L sqrt(m/eps)]
    density : number density N / V (N / A in 2D) [L^-d]
    temperature0, a_kappa, radius, mass, dim, eta : as for
        ``viscoelastic_temperature_second_order``
    points : nodes of the quadrature

    Returns
    -------
    MSD at t, total over dim

    References
    ----------
    Brilliantov & Poeschel, PRE 61, 1716 (2000) and Kinetic Theory of Granular Gases (OUP
    2004), ch. 14 (the leading order); Schwager & Poeschel, PRE 57, 650 (1998) (C1).
    """
    t = np.asarray(t, dtype=np.float64)
    if np.any(t < 0):
        raise ValueError("t must be >= 0")
    t_max = float(np.max(t)) if t.size else 0.0
    if t_max == 0.0:
        return np.zeros_like(t)[()]
    material: dict[str, Any] = dict(
        a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta
    )
    tau = viscoelastic_tau0(temperature0=temperature0, **material)
    start = min(1e-6 * (tau if math.isfinite(tau) else t_max), 1e-3 * t_max)
    grid = np.concatenate([[0.0], np.geomspace(start, t_max, points)])
    T = viscoelastic_temperature_second_order(grid, temperature0=temperature0, **material)
    half_loss = (
        0.5 * VISCOELASTIC_C1 * math.gamma(2.1) * viscoelastic_delta(T, a_kappa=a_kappa, mass=mass)
    )
    D = np.asarray(
        diffusion_d0(
            density=density,
            radius=radius,
            restitution=1.0,
            temperature0=T,
            mass=mass,
            dim=dim,
            eta=eta,
        )
        / (1.0 - half_loss) ** 2
    )
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (D[1:] + D[:-1]) * np.diff(grid))])
    out = 2.0 * dim * np.interp(t, grid, integral)
    return out[()] if out.ndim == 0 else out


@keyword_only()
def viscoelastic_langevin_coefficients(
    *,
    n: float,
    radius: float,
    volume: float,
    a_kappa: AKappa,
    temperature0: float,
    mass: float = 1.0,
    dim: int = 3,
) -> LangevinCoefficients:
    """gamma0, D0 and tau0' of the power-law UDSBM model of a viscoelastic gas, to run
    with ``langevin.run(..., exponent=5/6)``: D0 Enskog's at T0 (``diffusion_d0``, xi = 1),
    gamma0 = T0 / (m D0) as the thesis' (2.55), tau0' = ``viscoelastic_tau0``.  Then
    D gamma ~ (1 + t/tau0')^(-5/3) is the cooling law and D the D(t) of
    ``viscoelastic_diffusion`` (Bodrova et al., PCCP 17, 21791 (2015))."""
    density = n / volume
    d0 = float(
        diffusion_d0(
            density=density,
            radius=radius,
            restitution=1.0,
            temperature0=temperature0,
            mass=mass,
            dim=dim,
        )
    )
    tau0 = viscoelastic_tau0(
        a_kappa=a_kappa,
        density=density,
        radius=radius,
        temperature0=temperature0,
        mass=mass,
        dim=dim,
    )
    return LangevinCoefficients(temperature0 / (mass * d0), d0, tau0)
