"""A heavy tracer in a gas of light hard disks/spheres (Brownian motion): contact value at
its surface, friction and Langevin coefficients."""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _check_dim
from .equation_of_state import compressibility_factor, contact_value, packing_fraction
from .haff import LangevinCoefficients

# A disk or sphere of radius R and mass M among gas particles of radius r and mass m at
# number density n and temperature T feels, on average, the friction force -M gamma V.
# Derivation (Rayleigh's heavy-particle limit, Enskog's uncorrelated collisions): a gas
# particle with velocity v meets the tracer with relative velocity g = v - V at contact
# normal e (from the tracer to it) at the rate n chi sigma^(d-1) |g.e| per unit solid
# angle (sigma = R + r, chi the gas density at contact over n) and gives it the impulse
# 2 mu (g.e) e (mu = m M / (m + M)).  Over the half sphere of approaching normals,
# int (g.e)^2 e dOmega = |g| g c_d with c_d = pi^((d-1)/2) / Gamma((d+3)/2) (4/3 in 2D,
# pi/2 in 3D); to first order in V the Maxwellian average of |v - V| (v - V) is
# -<|v|> (d+1)/d V.  Hence M gamma = 2 mu n chi sigma^(d-1) c_d <|v|> (d+1)/d, which with
# <|v|> from the relative-velocity Maxwellian (temperature T, mass mu) is
#
#     M gamma = (4/d) pi^((d-1)/2) / Gamma(d/2) n chi sigma^(d-1) sqrt(2 mu T):
#     3D: (8/3) n chi sigma^2 sqrt(2 pi mu T)   (Epstein 1924's specular drag, Phys. Rev.
#         23, 710, for chi = 1 and mu = m; Enskog's value in Bocquet, Piasecki & Hansen,
#         J. Stat. Phys. 76, 505 (1994));
#     2D: 2 n chi sigma sqrt(2 pi mu T).
#
# Both are kT / D_12 with D_12 the first Chapman-Enskog (first Sonine) approximation of
# the tracer's diffusion coefficient (Chapman & Cowling, The Mathematical Theory of
# Non-Uniform Gases, 3rd ed. 1970, ch. 10 and 16; d-dimensional intruder diffusion in
# Gomez Gonzalez, Yuste & Garzo, arXiv:2409.08726, whose equations were not at hand here),
# and for a tracer equal to the gas particles they reduce to diffusion_d0 at xi = 1
# (D = kT / (M gamma)).  The 2D form is derived here, not found printed; tests/test_theory.py
# checks it against the collision integral summed by brute force and against diffusion_d0.
#
# Validity: exact for t -> 0 in equilibrium (Enskog's collision rate with the exact
# contact value gives the initial decay of the velocity autocorrelation of hard cores);
# at later times correlated collisions (ring collisions, hydrodynamic backflow) lower the
# friction of a large tracer, the more so the smaller the gas' mean free path against R
# (Bocquet et al. 1994's "dynamical correction"; Hynes, Kapral & Weinberg, J. Chem. Phys.
# 70, 1456 (1979)); the Langevin form (exponential velocity relaxation) needs m / M << 1.


@keyword_only("eta", "tracer_radius", "radius", "dim")
def tracer_contact_value(
    eta: FloatOrArray, *, tracer_radius: float, radius: float, dim: int = 3
) -> FloatOrArray:
    """Contact value chi of the gas' pair correlation at the surface of one large tracer
    (infinitely dilute) in a one-component hard-disk/sphere gas at packing fraction eta.

    The "universal" quadratic form of Santos, Yuste & Lopez de Haro (J. Chem. Phys. 117,
    5785 (2002)): chi = G(eta, z) with z = 2 R / (R + r) for a tracer of
    radius R in gas of radius r, quadratic in z through the exact limits G(eta, 0) =
    1 / (1 - eta) (a point tracer), G(eta, 1) = the gas' own contact value
    (``contact_value``: Henderson 2D, Carnahan-Starling 3D) and G(eta, 2) = Z, the
    compressibility factor (a flat hard wall, the contact theorem).  Luding & Santos
    (arXiv:cond-mat/0407015, 2004) compare it and Jenkins & Mancini's linear form (J. Appl.
    Mech. 54, 27 (1987)) with MD of hard-disk mixtures: both agree with it closely, this one
    better at high density.  For the Brownian seed's tracer the two differ by 0.9%."""
    _check_dim(dim)
    if not (tracer_radius > 0 and radius > 0):
        raise ValueError("radii must be positive")
    z = 2.0 * tracer_radius / (tracer_radius + radius)
    eta = np.asarray(eta, dtype=np.float64)
    g0 = 1.0 / (1.0 - eta)
    g1 = contact_value(eta, dim=dim)
    g2 = compressibility_factor(eta, dim=dim)
    g = g0 + z * (-3.0 * g0 + 4.0 * g1 - g2) / 2.0 + z * z * (g0 - 2.0 * g1 + g2) / 2.0
    return g[()] if g.ndim == 0 else g


@keyword_only(
    "density", "radius", "tracer_radius", "tracer_mass", "temperature", "mass", "dim", "chi"
)
def tracer_friction(
    *,
    density: float,
    radius: float,
    tracer_radius: float,
    tracer_mass: float,
    temperature: float,
    mass: float = 1.0,
    dim: int = 3,
    chi: float | None = None,
) -> float:
    """Friction rate gamma (1 / time) of a heavy tracer in a gas of hard disks/spheres, from
    kinetic theory: ``M gamma = (4/d) pi^((d-1)/2) / Gamma(d/2) n chi (R + r)^(d-1)
    sqrt(2 mu T)``, i.e. 2D ``2 n chi (R + r) sqrt(2 pi mu T) / M``, 3D (Epstein drag)
    ``(8/3) n chi (R + r)^2 sqrt(2 pi mu T) / M``, with mu = m M / (m + M).

    Parameters
    ----------
    density : float
        Number density n of the gas where the tracer is (centres per area or volume) [L^-d].
    radius, mass : float
        The gas particles' r [L] and m [m].
    tracer_radius, tracer_mass : float
        The tracer's R and M.
    temperature : float
        T (k_B = 1).
    dim : 2 or 3
    chi : float, optional
        Gas density at the tracer's surface over n; by default ``tracer_contact_value`` at
        the gas' packing fraction.

    Returns
    -------
    float
        gamma; the tracer's velocity relaxes as exp(-gamma t), its diffusivity per
        dimension is ``T / (M gamma)`` (see ``tracer_langevin_coefficients``).

    References
    ----------
    Derived in the comment at the top of this module (Rayleigh's heavy particle with Enskog's
    collision rate); P. S. Epstein, Phys. Rev. 23, 710 (1924) (3D, dilute);
    L. Bocquet, J. Piasecki & J.-P. Hansen, J. Stat. Phys. 76, 505 (1994) (the Enskog
    friction and its correction); S. Chapman & T. G. Cowling (1970), first approximation
    to the diffusion coefficient of a binary mixture, kT / D_12.

    Validity: exact at short times; at times beyond 1 / gamma correlated collisions lower
    the friction of a tracer large against the gas' mean free path (see the comment); the
    Langevin form needs m / M << 1.
    """
    _check_dim(dim)
    for name, value in (
        ("density", density),
        ("radius", radius),
        ("tracer_radius", tracer_radius),
        ("tracer_mass", tracer_mass),
        ("temperature", temperature),
        ("mass", mass),
    ):
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be positive and finite, got {value}")
    if chi is None:
        eta = packing_fraction(n=density, radius=radius, volume=1.0, dim=dim)
        chi = float(tracer_contact_value(eta, tracer_radius=tracer_radius, radius=radius, dim=dim))
    mu = mass * tracer_mass / (mass + tracer_mass)
    sigma = tracer_radius + radius
    geometry = 4.0 / dim * math.pi ** ((dim - 1) / 2) / math.gamma(dim / 2)
    return (
        geometry
        * density
        * chi
        * sigma ** (dim - 1)
        * math.sqrt(2.0 * mu * temperature)
        / (tracer_mass)
    )


@keyword_only(
    "density", "radius", "tracer_radius", "tracer_mass", "temperature", "mass", "dim", "chi"
)
def tracer_langevin_coefficients(
    *,
    density: float,
    radius: float,
    tracer_radius: float,
    tracer_mass: float,
    temperature: float,
    mass: float = 1.0,
    dim: int = 3,
    chi: float | None = None,
) -> LangevinCoefficients:
    """gamma0 = ``tracer_friction``, D0 = T / (M gamma0) (Einstein) and tau0 = inf of a heavy
    tracer in an elastic gas: the coefficients of ``msd_langevin`` for its MSD."""
    g = tracer_friction(
        density=density,
        radius=radius,
        tracer_radius=tracer_radius,
        tracer_mass=tracer_mass,
        temperature=temperature,
        mass=mass,
        dim=dim,
        chi=chi,
    )
    return LangevinCoefficients(g, temperature / (tracer_mass * g), math.inf)
