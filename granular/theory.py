"""Analytic results the simulations are checked against.

Equation numbers refer to the thesis: A. Gjersvoll, *Simulation methods for granular gas
dynamics in periodic three-dimensional systems*, master's thesis, NTNU, 2020 ([G20]).
Conventions: k_B = 1, so temperature is energy, ``T = 2 <E_kin> / d`` per particle and
``<v_a^2> = T / m`` per velocity component.  **Every MSD here is the total over the d
dimensions**: the thesis derives one-dimensional MSDs and multiplies by 3 (2.56); divide
by ``dim`` for one component.  All functions accept NumPy arrays for ``t``.

Validity: the kinetic-theory coefficients (collision frequency, Haff's tau0, D0, gamma0)
are Enskog's, for a homogeneous gas (for xi < 1 the homogeneous cooling state) in the
Maxwellian approximation -- they neglect the non-Gaussian (Sonine a2) correction of a
granular gas, a percent-level effect for xi >= 0.5 that grows towards small xi -- and use
approximate contact values g2 (Carnahan-Starling in 3D, Henderson's in 2D), good to
about 1% up to eta = 0.4 (3D) and 0.5 (2D).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import restitution as _restitution

# what the formulas return: a float for scalar arguments, else an array of their shape
FloatOrArray = float | NDArray[np.float64]


# -- geometry and equilibrium structure ---------------------------------------------------


def packing_fraction(
    n: FloatOrArray, radius: FloatOrArray, volume: FloatOrArray, dim: int = 3
) -> FloatOrArray:
    """Fraction of the volume (area in 2D) covered by n particles of the given radius
    (2.44): ``eta = n (4/3) pi r^3 / V`` in 3D, ``n pi r^2 / A`` in 2D."""
    _check_dim(dim)
    unit = 4.0 / 3.0 * math.pi * radius**3 if dim == 3 else math.pi * radius**2
    return n * unit / volume


def contact_value(eta: FloatOrArray, dim: int = 3) -> FloatOrArray:
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


def compressibility_factor(eta: FloatOrArray, dim: int = 3) -> FloatOrArray:
    """Equation of state Z = P / (n T) of hard spheres (Carnahan-Starling,
    ``1 + 4 eta g2``) or disks (Henderson, ``1 + 2 eta g2``): the collision virial's
    prediction with the approximate contact value."""
    return 1 + (4.0 if dim == 3 else 2.0) * np.asarray(eta) * contact_value(eta, dim)


# -- collisions, Haff's law, transport coefficients ----------------------------------------


def _eta(density, radius, dim, eta):
    return packing_fraction(density, radius, 1.0, dim) if eta is None else eta


def collision_frequency(
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
    g2 = contact_value(_eta(density, radius, dim, eta), dim)
    sigma = 2.0 * radius
    geometry = 4.0 * sigma**2 if dim == 3 else 2.0 * sigma
    return geometry * math.sqrt(math.pi) * g2 * density * np.sqrt(np.asarray(temperature) / mass)


def collision_time(
    density: FloatOrArray,
    radius: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Mean time between collisions of one particle, ``1 / collision_frequency`` (2.42)."""
    return 1.0 / collision_frequency(density, radius, temperature, mass, dim, eta)


def _constant_xi(xi):
    """A formula for a constant restitution given a law: say what to use instead."""
    if isinstance(xi, _restitution.RestitutionLaw):
        raise TypeError(
            f"xi must be a number (a constant restitution), got a {type(xi).__name__}; for "
            "a viscoelastic gas use theory.viscoelastic_* with the law, or "
            "langevin.coefficients_from_scene(scene)"
        )
    return xi


def haff_tau0(
    density: FloatOrArray,
    radius: FloatOrArray,
    xi: FloatOrArray,
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
    xi = _constant_xi(xi)
    if not 0.0 <= xi <= 1.0:
        raise ValueError("xi must lie in [0, 1]")
    if xi == 1.0:
        return math.inf
    omega = collision_frequency(density, radius, temperature0, mass, dim, eta)
    return 2 * dim / ((1.0 - xi**2) * omega)


def haff_temperature(
    t: FloatOrArray, temperature0: FloatOrArray, tau0: FloatOrArray
) -> FloatOrArray:
    """Haff's law ``T(t) = T0 / (1 + t/tau0)^2`` (2.40), homogeneous cooling state."""
    t = np.asarray(t, dtype=np.float64)
    return temperature0 / (1.0 + t / tau0) ** 2


def diffusion_d0(
    density: FloatOrArray,
    radius: FloatOrArray,
    xi: FloatOrArray,
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
    xi = _constant_xi(xi)
    _check_dim(dim)
    g2 = contact_value(_eta(density, radius, dim, eta), dim)
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


def langevin_coefficients(
    n: float,
    radius: float,
    volume: float,
    xi: float,
    temperature0: float,
    mass: float = 1.0,
    dim: int = 3,
) -> LangevinCoefficients:
    """gamma0, D0, tau0 of a gas of n particles in a box of the given volume, as the thesis
    derives them for its Langevin and UDSBM models: D0 (2.52), ``gamma0 = T0 / (m D0)``
    (2.55), tau0 (2.45; infinite for xi = 1)."""
    xi = _constant_xi(xi)
    density = n / volume
    d0 = float(diffusion_d0(density, radius, xi, temperature0, mass, dim))
    gamma0 = temperature0 / (mass * d0)
    tau0 = float(haff_tau0(density, radius, xi, temperature0, mass, dim))
    return LangevinCoefficients(gamma0, d0, tau0)


# -- mean squared displacements -------------------------------------------------------------


def _x_plus_expm1(x):
    """``x + expm1(-x)`` without cancellation for small x (a series there)."""
    x = np.asarray(x, dtype=np.float64)
    small = np.abs(x) < 1e-3
    xs = np.where(small, x, 0.0)
    series = xs**2 / 2 - xs**3 / 6 + xs**4 / 24 - xs**5 / 120
    return np.where(small, series, x + np.expm1(-np.where(small, 1.0, x)))


def _one_minus_exp_over(x):
    """``(1 - exp(-x)) / x``, equal to 1 at x = 0."""
    x = np.asarray(x, dtype=np.float64)
    safe = np.where(x == 0, 1.0, x)
    return np.where(x == 0, 1.0, -np.expm1(-safe) / safe)


def msd_langevin(
    t: FloatOrArray, D0: float, gamma0: float, dim: int = 3, v0_sq: FloatOrArray | None = None
) -> FloatOrArray:
    """MSD of a molecular gas and of the underdamped Langevin equation (2.68), total over
    ``dim`` dimensions: ``d [2 D0 t + (2 D0/gamma0)(exp(-gamma0 t) - 1)]``.

    ``v0_sq`` is the initial mean squared velocity per component; by default the thermal
    ``T0/m = D0 gamma0`` of (2.68).  Otherwise the VACF gains
    ``(v0_sq - D0 gamma0) exp(-gamma0 (t1 + t2))`` (2.101) and the MSD
    ``d (v0_sq - D0 gamma0) ((1 - exp(-gamma0 t)) / gamma0)^2``.
    Limits: ballistic ``d v0_sq t^2`` for t << 1/gamma0, diffusive ``2 d D0 t`` for
    t >> 1/gamma0.
    """
    t = np.asarray(t, dtype=np.float64)
    x = gamma0 * t
    out = 2.0 * D0 / gamma0 * _x_plus_expm1(x)
    if v0_sq is not None:
        out = out + (v0_sq - D0 * gamma0) * (t * _one_minus_exp_over(x)) ** 2
    return dim * out


def msd_granular(
    t: FloatOrArray, D0: float, gamma0: float, tau0: float, dim: int = 3
) -> FloatOrArray:
    """MSD of a granular gas in the homogeneous cooling state (2.79), total over ``dim``:
    ``d 2 D0 tau0 [ln(1 + t/tau0) + ((1 + t/tau0)^(-gamma0 tau0) - 1) / (gamma0 tau0)]``.

    From the VACF (2.77), Maxwellian start at T0.  Limits: ballistic ``d (T0/m) t^2`` for
    t << tau0 and 1/gamma0; ultraslow ``2 d D0 tau0 ln(t/tau0)`` for t >> tau0.  Equals
    ``msd_langevin`` for tau0 = inf.
    """
    if math.isinf(tau0):
        return msd_langevin(t, D0, gamma0, dim)
    a = gamma0 * tau0
    u = np.log1p(np.asarray(t, dtype=np.float64) / tau0)
    return dim * 2.0 * D0 * tau0 * _x_plus_expm1(a * u) / a


def udsbm_v0_sq(D0: float, gamma0: float, tau0: float) -> float:
    """The "correct" initial mean squared velocity per component of UDSBM (App. C):
    ``(T0/m) gamma0 tau0 / (gamma0 tau0 - 1)``, the value for which the VACF is (2.111)
    from t = 0 on and the MSD is (2.113).  Needs gamma0 tau0 > 1."""
    a = gamma0 * tau0
    if not a > 1:
        raise ValueError("UDSBM needs gamma0 * tau0 > 1")
    return D0 * gamma0 * a / (a - 1)


def msd_udsbm(
    t: FloatOrArray, D0: float, gamma0: float, tau0: float, dim: int = 3, v0_sq: float | None = None
) -> FloatOrArray:
    """MSD of underdamped scaled Brownian motion, total over ``dim`` dimensions.

    With ``v0_sq = None`` (default) the particles start with App. C's initial speed
    (``udsbm_v0_sq``) and the result is (2.113):
    ``2 D0 a^2 / (a - 1)^2 [tau0 ln(1 + t/tau0) + tau0 ((1 + t/tau0)^(1-a) - 1) / (a - 1)]``
    per dimension, a = gamma0 tau0 > 1.  Another initial mean squared velocity per
    component adds ``(v0_sq - udsbm_v0_sq) (int_0^t (1 + s/tau0)^-a ds)^2`` (the
    transient of the UDSBM solution, see ``granular.langevin``).
    """
    a = gamma0 * tau0
    if not a > 1:
        raise ValueError("UDSBM needs gamma0 * tau0 > 1")
    t = np.asarray(t, dtype=np.float64)
    u = np.log1p(t / tau0)
    out = 2.0 * D0 * a**2 * tau0 / (a - 1) ** 3 * _x_plus_expm1((a - 1) * u)
    if v0_sq is not None:
        # int_0^t (1 + s/tau0)^-a ds = tau0 (1 - exp(-(a - 1) u)) / (a - 1)
        integral = tau0 * u * _one_minus_exp_over((a - 1) * u)
        out = out + (v0_sq - udsbm_v0_sq(D0, gamma0, tau0)) * integral**2
    return dim * out


def udsbm_increment_msd(
    lag: FloatOrArray,
    start: FloatOrArray,
    D0: float,
    gamma0: float,
    tau0: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Mean squared displacement of UDSBM over [start, start + lag], total over ``dim``
    dimensions -- the quantity a time average over windows starting at ``start`` collects
    (thesis 2.114-2.119).  At start = 0 it is ``msd_udsbm``.

    Per dimension, with w = 1 + start/tau0, W = 1 + (start + lag)/tau0, a = gamma0 tau0 and
    vc = ``udsbm_v0_sq``: the mean squared velocity is ``vc / w^2 + (v0_sq - vc) / w^(2a)``
    and ``<v(s) v(s')> = <v^2>(s) (w / w')^a`` (VACF 2.111 plus the start's transient);
    integrated twice, with u = ln(W/w) and b = a - 1, ``2 tau0^2 vc (b u + exp(-b u) - 1)
    / b^2 + (v0_sq - vc) (tau0 w^-b (1 - exp(-b u)) / b)^2``, evaluated without the
    cancellation of W^x - w^x at lags short against tau0 + start (u = log1p(lag / (tau0 +
    start))).  ``v0_sq = None``: App. C's start (vc), whose increments scale:
    ``msd_udsbm(lag / w)``.
    """
    b = gamma0 * tau0 - 1.0
    vc = udsbm_v0_sq(D0, gamma0, tau0)
    v0_sq = vc if v0_sq is None else v0_sq
    start = np.asarray(start, dtype=np.float64)
    w = 1.0 + start / tau0
    u = np.log1p(np.asarray(lag, dtype=np.float64) / (tau0 + start))
    stationary = 2.0 * tau0**2 * vc * _x_plus_expm1(b * u) / b**2
    transient = (v0_sq - vc) * (tau0 * w ** (-b) * u * _one_minus_exp_over(b * u)) ** 2
    return dim * (stationary + transient)


def msd_ballistic(
    t: FloatOrArray, temperature: float, mass: float = 1.0, dim: int = 3
) -> FloatOrArray:
    """Short-time limit of every MSD here: free flight, ``d (T/m) t^2``."""
    return dim * temperature / mass * np.asarray(t, dtype=np.float64) ** 2


def msd_diffusive(
    t: FloatOrArray, D0: float, dim: int = 3, gamma0: float | None = None
) -> FloatOrArray:
    """Einstein's long-time limit of a molecular gas, ``2 d D0 t`` (2.46); with gamma0 the
    exact asymptote of (2.68), ``2 d D0 (t - 1/gamma0)``."""
    shift = 0.0 if gamma0 is None else 1.0 / gamma0
    return 2.0 * dim * D0 * (np.asarray(t, dtype=np.float64) - shift)


def msd_logarithmic(
    t: FloatOrArray, D0: float, tau0: float, dim: int = 3, gamma0: float | None = None
) -> FloatOrArray:
    """Long-time limit of a granular gas, ``2 d D0 tau0 ln(1 + t/tau0)`` (2.80); with gamma0
    the exact asymptote of (2.79), ``2 d D0 tau0 (ln(1 + t/tau0) - 1/(gamma0 tau0))``."""
    shift = 0.0 if gamma0 is None else 1.0 / (gamma0 * tau0)
    return 2.0 * dim * D0 * tau0 * (np.log1p(np.asarray(t, dtype=np.float64) / tau0) - shift)


# -- Maxwell-Boltzmann ----------------------------------------------------------------------


def maxwell_boltzmann_pdf(
    speed: FloatOrArray, temperature: float, mass: float = 1.0, dim: int = 3
) -> FloatOrArray:
    """Speed density of a gas in equilibrium (2.30 in 2D, 2.32 in 3D):
    2D ``(m v / T) exp(-m v^2 / 2T)``; 3D ``4 pi v^2 (m / 2 pi T)^(3/2) exp(-m v^2 / 2T)``."""
    _check_dim(dim)
    v = np.asarray(speed, dtype=np.float64)
    b = mass / temperature
    if dim == 2:
        return b * v * np.exp(-0.5 * b * v * v)
    return 4 * math.pi * v * v * (b / (2 * math.pi)) ** 1.5 * np.exp(-0.5 * b * v * v)


def maxwell_boltzmann_moments(
    temperature: float, mass: float = 1.0, dim: int = 3
) -> dict[str, float]:
    """Expectation values of Table 2.2: mean speed, mean squared speed, standard deviation
    of the speed and most probable speed."""
    _check_dim(dim)
    s = temperature / mass
    mean = math.sqrt(math.pi * s / 2) if dim == 2 else math.sqrt(8 * s / math.pi)
    mean_sq = dim * s
    return {
        "mean": mean,
        "mean_sq": mean_sq,
        "std": math.sqrt(mean_sq - mean**2),
        "most_probable": math.sqrt(s) if dim == 2 else math.sqrt(2 * s),
    }


def _check_dim(dim):
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")


# -- the end of homogeneous cooling: the shear instability ---------------------------------
#
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


def cooling_rate(
    density: FloatOrArray,
    radius: FloatOrArray,
    xi: FloatOrArray,
    temperature: FloatOrArray,
    mass: FloatOrArray = 1.0,
    dim: int = 3,
    eta: FloatOrArray | None = None,
) -> FloatOrArray:
    """Cooling rate zeta of the homogeneous cooling state, ``dT/dt = -zeta T``:
    ``zeta = (1 - xi^2) omega / d`` with omega the Enskog collision frequency (2.42); the
    same Maxwellian estimate as ``haff_tau0`` (``zeta(T0) = 2 / tau0``), equal to Garzo &
    Dufty's ``zeta* = (d + 2) / (4 d) chi (1 - xi^2)`` at a2 = 0 in units of ``n T / eta0``."""
    xi = _constant_xi(xi)
    xi = np.asarray(xi, dtype=np.float64)
    if np.any((xi < 0) | (xi > 1)):
        raise ValueError("xi must lie in [0, 1]")
    omega = collision_frequency(density, radius, temperature, mass, dim, eta)
    return (1.0 - xi**2) * omega / dim


def shear_viscosity(
    density: FloatOrArray,
    radius: FloatOrArray,
    xi: FloatOrArray,
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
    xi = _constant_xi(xi)
    _check_dim(dim)
    xi = np.asarray(xi, dtype=np.float64)
    phi = _eta(density, radius, dim, eta)
    chi = contact_value(phi, dim)
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


def critical_box_size(
    density: FloatOrArray,
    radius: FloatOrArray,
    xi: FloatOrArray,
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
        Number density N / V.
    radius : float
    xi : float in [0, 1]
        Coefficient of restitution.
    dim : 2 or 3
    eta : float, optional
        Packing fraction (default: from density and radius).

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
    xi = _constant_xi(xi)
    xi = np.asarray(xi, dtype=np.float64)
    zeta = cooling_rate(density, radius, xi, 1.0, 1.0, dim, eta)
    visc = shear_viscosity(density, radius, xi, 1.0, 1.0, dim, eta)
    with np.errstate(divide="ignore"):
        lc = 2 * math.pi * np.sqrt(2 * visc / (density * zeta))
    return lc[()] if np.ndim(lc) == 0 else lc


def shear_mode_growth(
    t: FloatOrArray, tau0: FloatOrArray, box: FloatOrArray, critical: FloatOrArray
) -> FloatOrArray:
    """Factor by which the energy of the slowest shear mode (k = 2 pi / box) grows relative
    to the thermal energy by time t in linear theory, ``(1 + t/tau0)^(2 (1 - (L_c/L)^2))``:
    its rate ``(zeta/2)(1 - k^2/k_c^2)`` integrated over Haff's law, where
    ``int zeta/2 dt = ln(1 + t/tau0)``.  Below 1 (decay) for a box below L_c."""
    t = np.asarray(t, dtype=np.float64)
    q2 = (np.asarray(critical, dtype=np.float64) / box) ** 2
    return (1.0 + t / tau0) ** (2.0 * (1.0 - q2))


def shear_mode_level(box: FloatOrArray, critical: FloatOrArray) -> FloatOrArray:
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


# == Viscoelastic granular gases and UDSBM with power-law coefficients =====================
#
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
# (2) Underdamped scaled Brownian motion with gamma0 (1 + t/tau0)^-a and D0 (1 + t/tau0)^-a
# (``granular.langevin``, ``exponent`` a): a = 1 is the thesis' UDSBM, a = 5/6 the
# viscoelastic gas' counterpart (Bodrova, Chechkin, Cherstvy & Metzler, PCCP 17, 21791
# (2015); Bodrova et al., Sci. Rep. 6, 30520 (2016)).  Its second moments are computed here
# from their exact linear ODEs (no closed form for a != 1), its TAMSD and
# ergodicity-breaking parameter from the exact position covariance.
#
# Every function of both parts takes its parameters by keyword (only t, T or the lag is
# positional): they are floats of similar size in orders that differ from haff_tau0's and
# msd_udsbm's, so a swapped a_kappa and density, or a dim landing on exponent, would
# otherwise give a plausible wrong number without an error.

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
    temperature : T
    a_kappa : A kappa^(2/5), or a ``restitution.Viscoelastic`` law (see ``viscoelastic_delta``)
    density, radius, mass, dim, eta : as for ``collision_frequency``
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
    omega = collision_frequency(density, radius, T, mass, dim, eta)
    delta = a_kappa * (4.0 * T / mass) ** 0.1
    zeta = 2.0 / dim * VISCOELASTIC_C1 * math.gamma(2.1) * omega * delta
    if order == 2:
        c = VISCOELASTIC_C1**2 + 2 * VISCOELASTIC_C2
        zeta = zeta - c * math.gamma(2.2) * omega * delta**2 / dim
    return zeta[()] if np.ndim(zeta) == 0 else zeta


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
    a_kappa : A kappa^(2/5), or a ``restitution.Viscoelastic`` law (see ``viscoelastic_delta``)
    density, radius, temperature0, mass, dim, eta : as for ``haff_tau0``

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
    material = dict(a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta)
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
    material = dict(a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta)
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


def msd_viscoelastic_asymptote(
    t: FloatOrArray, *, D0: float, tau0: float, dim: int = 3
) -> FloatOrArray:
    """Late-time power law of ``msd_viscoelastic``: ``12 d D0 tau0'^(5/6) t^(1/6)``; the
    full expression falls short of it by the factor (1 + tau0'/t)^(1/6) - (tau0'/t)^(1/6)
    (0.785 at t = 10^4 tau0', 0.853 at 10^5, 0.900 at 10^6), so it is within 10% only from
    t ~ 10^6 tau0' on -- fit late exponents, or compare with the full expression."""
    return 12.0 * dim * D0 * tau0 ** (5.0 / 6.0) * np.asarray(t, dtype=np.float64) ** (1.0 / 6.0)


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
    t : times >= 0
    temperature0, a_kappa, density, radius, mass, dim, eta : as for
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
    material = dict(a_kappa=a_kappa, density=density, radius=radius, mass=mass, dim=dim, eta=eta)
    tau = viscoelastic_tau0(temperature0=temperature0, **material)
    start = min(1e-6 * (tau if math.isfinite(tau) else t_max), 1e-3 * t_max)
    grid = np.concatenate([[0.0], np.geomspace(start, t_max, points)])
    T = viscoelastic_temperature_second_order(grid, temperature0=temperature0, **material)
    half_loss = (
        0.5 * VISCOELASTIC_C1 * math.gamma(2.1) * viscoelastic_delta(T, a_kappa=a_kappa, mass=mass)
    )
    D = diffusion_d0(density, radius, 1.0, T, mass, dim, eta) / (1.0 - half_loss) ** 2
    integral = np.concatenate([[0.0], np.cumsum(0.5 * (D[1:] + D[:-1]) * np.diff(grid))])
    out = 2.0 * dim * np.interp(t, grid, integral)
    return out[()] if out.ndim == 0 else out


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
    d0 = float(diffusion_d0(density, radius, 1.0, temperature0, mass, dim))
    tau0 = viscoelastic_tau0(
        a_kappa=a_kappa,
        density=density,
        radius=radius,
        temperature0=temperature0,
        mass=mass,
        dim=dim,
    )
    return LangevinCoefficients(temperature0 / (mass * d0), d0, tau0)


# -- UDSBM with power-law coefficients: moments, TAMSD, ergodicity breaking --------------------


def _check_powerlaw(gamma0, D0, tau0, exponent):
    for name, value in (("gamma0", gamma0), ("D0", D0)):
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be positive and finite, got {value}")
    if not tau0 > 0:
        raise ValueError(f"tau0 must be positive (inf: constant coefficients), got {tau0}")
    if not (exponent > 0 and math.isfinite(exponent)):
        raise ValueError(f"exponent must be positive and finite, got {exponent}")


def _powerlaw_ode(gamma0, tau0, exponent, v0_sq_reduced, t_max_reduced):
    """Dense solution of the second-moment ODEs in units of 1/gamma0 (time), D0/gamma0
    (x^2), D0 (x v), D0 gamma0 (v^2): with g = w^-a, w = 1 + t/tau0,
    d<x^2> = 2 <xv>, d<xv> = <v^2> - g <xv>, d<v^2> = -2 g <v^2> + 2 g^3 (the noise
    2 D gamma^2).  DOP853 at rtol 1e-12.  Constant coefficients (tau0 = inf): the closed
    forms of the Langevin model (2.68 with the start's transient), no integration."""
    from scipy.integrate import solve_ivp

    if math.isinf(tau0):
        excess = v0_sq_reduced - 1.0

        def langevin(s):
            s = np.asarray(s, dtype=np.float64)
            omc, e = -np.expm1(-s), np.exp(-s)
            xx = 2.0 * _x_plus_expm1(s) + excess * omc**2
            return np.array([xx, omc + excess * e * omc, 1.0 + excess * e * e])

        return langevin

    c = 1.0 / (gamma0 * tau0)  # w = 1 + c s, s = gamma0 t

    def rhs(s, y):
        g = (1.0 + c * s) ** -exponent
        return [2.0 * y[1], y[2] - g * y[1], -2.0 * g * y[2] + 2.0 * g**3]

    sol = solve_ivp(
        rhs,
        (0.0, max(t_max_reduced, 1e-12)),
        [0.0, 0.0, v0_sq_reduced],
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        dense_output=True,
    )
    if not sol.success:  # pragma: no cover - DOP853 on this smooth linear system
        raise RuntimeError(f"moment ODE failed: {sol.message}")
    return sol.sol


def powerlaw_udsbm_moments(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    v0_sq: float | None = None,
) -> tuple[FloatOrArray, FloatOrArray, FloatOrArray]:
    """<x^2>, <x v>, <v^2> per dimension of UDSBM with power-law coefficients,
    dv = -gamma(t) v dt + sqrt(2 D(t)) gamma(t) dW, gamma = gamma0 w^-a, D = D0 w^-a,
    w = 1 + t/tau0, from x = 0 and <v^2> = v0_sq (default D0 gamma0, thermal).

    The exact moment equations d<x^2>/dt = 2<xv>, d<xv>/dt = <v^2> - gamma <xv>,
    d<v^2>/dt = -2 gamma <v^2> + 2 D gamma^2 (Ito) integrated numerically (relative
    error ~1e-11): for a != 1 they have no elementary closed form (the velocity
    propagator exp(-gamma0 tau0 (w^(1-a) - 1)/(1 - a)) leads to incomplete gamma
    functions).  For a = 1 this is the thesis' (2.113) / ``msd_udsbm`` (tested), for
    tau0 = inf the Langevin (2.68).

    References
    ----------
    Bodrova, Chechkin, Cherstvy, Safdari, Sokolov & Metzler, "Underdamped scaled Brownian
    motion: (non-)existence of the overdamped limit in anomalous diffusion", Sci. Rep. 6,
    30520 (2016) (UDSBM with power-law coefficients); thesis App. C and (2.111)-(2.113) for a = 1.
    """
    _check_powerlaw(gamma0, D0, tau0, exponent)
    t = np.asarray(t, dtype=np.float64)
    if np.any(t < 0) or not np.all(np.isfinite(t)):
        raise ValueError("t must be finite and >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    s = gamma0 * t
    sol = _powerlaw_ode(gamma0, tau0, exponent, v0 / (D0 * gamma0), float(np.max(s, initial=0.0)))
    y = sol(s.reshape(-1)).reshape((3, *t.shape))
    xx, xv, vv = y[0] * D0 / gamma0, y[1] * D0, y[2] * D0 * gamma0
    if t.ndim == 0:
        return float(xx), float(xv), float(vv)
    return xx, xv, vv


def msd_powerlaw_udsbm(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Ensemble MSD of UDSBM with power-law coefficients, total over ``dim``:
    ``dim <x^2>`` of ``powerlaw_udsbm_moments`` (see there).  Late times, for a < 1:
    ``msd_powerlaw_udsbm_asymptote``."""
    xx, _, _ = powerlaw_udsbm_moments(
        t, D0=D0, gamma0=gamma0, tau0=tau0, exponent=exponent, v0_sq=v0_sq
    )
    return dim * np.asarray(xx) if np.ndim(xx) else dim * xx


def msd_powerlaw_udsbm_asymptote(
    t: FloatOrArray, *, D0: float, tau0: float, exponent: float, dim: int = 3
) -> FloatOrArray:
    """Overdamped limit of the power-law UDSBM MSD for a < 1, total over ``dim``:
    ``2 d int_0^t D = 2 d D0 tau0 ((1 + t/tau0)^(1-a) - 1) / (1 - a)``, ~ t^(1-a) (t^(1/6)
    for the viscoelastic a = 5/6).

    Why it holds for a < 1 only: gamma(t) t ~ t^(1-a) grows, so the velocity relaxes ever
    faster against the age and the overdamped limit exists; the underdamped MSD exceeds
    this by a term that grows more slowly (relative O(1/(gamma(t) t))).  For a = 1 the
    ratio gamma t stays gamma0 tau0 and the MSD is larger by (gamma0 tau0 / (gamma0 tau0 -
    1))^2 (thesis 2.113; Bodrova et al., Sci. Rep. 6, 30520 (2016): the overdamped limit does
    not exist); for a > 1 the motion ends ballistic.

    Raises
    ------
    ValueError
        For exponent outside (0, 1).
    """
    if not 0 < exponent < 1:
        raise ValueError(f"the overdamped asymptote needs 0 < exponent < 1, got {exponent}")
    u = np.log1p(np.asarray(t, dtype=np.float64) / tau0)
    b = 1.0 - exponent
    return 2.0 * dim * D0 * tau0 * np.expm1(b * u) / b


# Gauss-Legendre nodes for the propagator integral K: panels [0, 1/2], [1/2, 1], [1, 2], ...
_GL_X, _GL_W = np.polynomial.legendre.leggauss(20)


def _powerlaw_propagator_integral(start, gap, gamma0, tau0, exponent):
    """K(s, h) = int_s^{s+h} exp(-int_s^u gamma) du, the factor of <x(s) v(s)> in
    <x(s) x(s+h)> = <x^2>(s) + <xv>(s) K (the velocity correlation decays with the
    propagator after s).  Closed forms for tau0 = inf, (1 - exp(-gamma0 h))/gamma0, and
    a = 1, tau0 w (1 - (w/W)^(A-1))/(A - 1) (A = gamma0 tau0, w = 1 + s/tau0,
    W = 1 + (s+h)/tau0); for a < 1, in phi = int_s^u gamma, K = (w^a/gamma0) int_0^Phi
    exp(-phi) (1 + (1-a) phi / (A w^(1-a)))^(a/(1-a)) dphi by 20-point Gauss-Legendre on
    doubling panels; for a > 1 the same in z = ln(W/w) (relative error < 1e-9 against
    scipy quad, a = 1.2 to 3, tests/test_theory_viscoelastic.py)."""
    s, h = np.broadcast_arrays(
        np.asarray(start, dtype=np.float64), np.asarray(gap, dtype=np.float64)
    )
    if math.isinf(tau0):
        return -np.expm1(-gamma0 * h) / gamma0
    A = gamma0 * tau0
    w = 1.0 + s / tau0
    lr = np.log1p(h / (tau0 + s))  # ln(W / w)
    if exponent == 1.0:
        if A == 1.0:
            return tau0 * w * lr
        return tau0 * w * -np.expm1(-(A - 1) * lr) / (A - 1)
    b = 1.0 - exponent
    wb = w**b
    if exponent > 1.0:
        # gamma's integral converges: in phi the integrand has a singular end, so integrate
        # in z = ln(W/w) instead, du = (tau0 + s) e^z dz, on panels doubling from the
        # relaxation scale 1 / (A w^b) of the start
        z0 = 0.5 / (A * wb)
        total = np.zeros(np.shape(s))
        k = 0
        while True:
            a_ = np.minimum(z0 * (2.0**k - 1.0), lr)
            b_ = np.minimum(z0 * (2.0 ** (k + 1) - 1.0), lr)
            if not np.any(b_ > a_):
                break
            half = 0.5 * (b_ - a_)
            z = (a_ + half)[..., None] + half[..., None] * _GL_X
            f = np.exp(z - A * wb[..., None] * np.expm1(b * z) / b)
            total += half * (f @ _GL_W)
            k += 1
        return (tau0 + s) * total
    phi_end = A * wb * np.expm1(b * lr) / b
    scale = b / (A * wb)
    total = np.zeros(np.shape(s))
    lo = 0.0
    hi = 0.5
    top = float(np.max(phi_end, initial=0.0))
    while lo < top:
        a_ = np.minimum(lo, phi_end)
        b_ = np.minimum(hi, phi_end)
        half = 0.5 * (b_ - a_)
        if np.any(half > 0):
            phi = (a_ + half)[..., None] + half[..., None] * _GL_X
            base = np.maximum(1.0 + scale[..., None] * phi, 0.0)
            f = np.exp(-phi) * base ** (exponent / b)
            total += half * (f @ _GL_W)
        lo, hi = hi, 2 * hi
    return w**exponent / gamma0 * total


def _powerlaw_gamma_integral(t0, t1, gamma0, tau0, exponent):
    """int_{t0}^{t1} gamma, gamma = gamma0 (1 + t/tau0)^-a, accurate for short spans
    (log1p / expm1, no difference of large numbers)."""
    if math.isinf(tau0):
        return gamma0 * (t1 - t0)
    lr = np.log1p((t1 - t0) / (tau0 + t0))  # ln(W / w)
    A = gamma0 * tau0
    if exponent == 1.0:
        return A * lr
    b = 1.0 - exponent
    return A * (1.0 + t0 / tau0) ** b * np.expm1(b * lr) / b


def _covariance_on_grid(times, sol, D0, gamma0, tau0, exponent, block=512):
    """<x(T_i) x(T_j)> per dimension for all pairs of the sorted distinct ``times``, (N, N).

    For T_i <= T_j it is <x^2>(T_i) + <xv>(T_i) K(T_i, T_j - T_i), and the propagator
    integral splits over the grid's segments: K(T_i, T_j - T_i) = sum_{m=i}^{j-1}
    exp(-int_{T_i}^{T_m} gamma) kappa_m with kappa_m = K(T_m, T_{m+1} - T_m) (one call of
    ``_powerlaw_propagator_integral`` per segment, not per pair).  The exponentials are
    <= 1 (no overflow) and the sum adds positive terms (relative rounding ~N eps).  Cost
    O(N^2) in array operations, rows in blocks to bound the memory."""
    n = times.size
    y = sol(gamma0 * times)
    xx, xv = y[0] * D0 / gamma0, y[1] * D0
    if n == 1:
        return xx.reshape(1, 1).copy()
    kappa = _powerlaw_propagator_integral(times[:-1], np.diff(times), gamma0, tau0, exponent)
    # G_m = int_{T_0}^{T_m} gamma, summed from accurate per-segment integrals
    seg = _powerlaw_gamma_integral(times[:-1], times[1:], gamma0, tau0, exponent)
    g = np.concatenate([[0.0], np.cumsum(seg)])
    cov = np.empty((n, n))
    cols = np.arange(n - 1)
    for lo in range(0, n, block):
        rows = np.arange(lo, min(lo + block, n))
        # term[i, m] = exp(G_i - G_m) kappa_m for m >= i, 0 before
        term = np.exp(np.minimum(g[rows, None] - g[None, :-1], 0.0)) * kappa
        term[cols[None, :] < rows[:, None]] = 0.0
        k = np.zeros((rows.size, n))
        np.cumsum(term, axis=1, out=k[:, 1:])  # k[i, j] = sum_{m < j} term[i, m]
        cov[rows] = xx[rows, None] + xv[rows, None] * k
    # the upper triangle (T_i <= T_j) is right; mirror it block by block (no N^2 temporaries)
    for lo in range(0, n, block):
        hi = min(lo + block, n)
        cov[lo:hi, :lo] = cov[:lo, lo:hi].T
        diag = cov[lo:hi, lo:hi]
        cov[lo:hi, lo:hi] = np.triu(diag) + np.triu(diag, 1).T
    return cov


def powerlaw_udsbm_increment_msd(
    lag: FloatOrArray,
    *,
    start: FloatOrArray,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Mean squared displacement over [start, start + lag] of UDSBM with power-law
    coefficients, total over ``dim``: ``<x^2>(s+lag) - <x^2>(s) - 2 <xv>(s) K(s, lag)``
    per dimension, with K the integral of the velocity propagator over the lag (the
    thesis' 2.116-2.118: the cross term <x(s) x(s+lag)> = <x^2>(s) + <xv>(s) K).  Moments
    from ``powerlaw_udsbm_moments``; their difference loses digits when the increment is
    small against <x^2>(s) (relative error ~1e-11 <x^2>(s) / increment).  Equals
    ``udsbm_increment_msd`` for a = 1 (tested)."""
    _check_powerlaw(gamma0, D0, tau0, exponent)
    lag, start = np.broadcast_arrays(
        np.asarray(lag, dtype=np.float64), np.asarray(start, dtype=np.float64)
    )
    if np.any(lag < 0) or np.any(start < 0):
        raise ValueError("lag and start must be >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _powerlaw_ode(
        gamma0, tau0, exponent, v0 / (D0 * gamma0), float(gamma0 * np.max(start + lag, initial=0))
    )
    y0 = sol((gamma0 * start).reshape(-1)).reshape((3, *start.shape))
    y1 = sol((gamma0 * (start + lag)).reshape(-1)).reshape((3, *start.shape))
    k = _powerlaw_propagator_integral(start, lag, gamma0, tau0, exponent)
    out = dim * ((y1[0] - y0[0]) * D0 / gamma0 - 2.0 * y0[1] * D0 * k)
    return out[()] if out.ndim == 0 else out


def udsbm_ergodicity_breaking(
    lag: float,
    *,
    starts: ArrayLike,
    D0: float,
    gamma0: float,
    tau0: float = math.inf,
    exponent: float = 1.0,
    dim: int = 3,
    v0_sq: float | None = None,
) -> float:
    """Ergodicity-breaking parameter EB = Var(TAMSD) / <TAMSD>^2 of the time-averaged MSD
    over windows [s_j, s_j + lag] (the engine's, or a fine grid for the continuous-time
    average of the thesis' 2.115), for UDSBM with power-law coefficients (a = 1 the
    thesis' UDSBM, tau0 = inf the Langevin model).

    The process is Gaussian with zero mean, so with C_jk the covariance per dimension of
    the increments of windows j and k (from ``<x(t1) x(t2)>``, see
    ``powerlaw_udsbm_increment_msd``) and d independent dimensions, Isserlis' theorem gives
    ``Cov(|dx_j|^2, |dx_k|^2) = 2 d C_jk^2`` and

        EB = 2 sum_jk C_jk^2 / (d (sum_j C_jj)^2).

    EB -> 0 for an ergodic process as t_stop / lag grows (Brownian motion: 4 lag / (3 d
    t_stop), He, Burov, Metzler & Barkai, PRL 101, 058101 (2008)); UDSBM's stays finite
    (Bodrova et al., PCCP 17, 21791 (2015); Safdari, Cherstvy, Chechkin, Bodrova & Metzler,
    "Ageing underdamped scaled Brownian motion", arXiv:1609.07246).
    Cost O(len(starts)^2) array operations (``_covariance_on_grid``): 0.3-0.6 s for 2000
    windows; memory 3-6 M^2 doubles (the covariance on up to 2 M times and C: 100-190 MB
    for 2000 windows).

    Parameters
    ----------
    lag : the lag
    starts : (M,) window starts
    D0, gamma0, tau0, exponent, v0_sq : the model (see ``powerlaw_udsbm_moments``)
    dim : dimensions summed in ``|dx|^2``

    Returns
    -------
    EB
    """
    _check_powerlaw(gamma0, D0, tau0, exponent)
    s = np.asarray(starts, dtype=np.float64).reshape(-1)
    if not lag > 0 or s.size == 0 or np.any(s < 0):
        raise ValueError("need lag > 0 and at least one window start >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _powerlaw_ode(gamma0, tau0, exponent, v0 / (D0 * gamma0), gamma0 * (s.max() + lag))
    # the covariance once on the distinct window ends (at most 2 M, far fewer when the
    # windows overlap on the sample grid), then the increments' C_jk by indexing
    times = np.unique(np.concatenate([s, s + lag]))
    i0, i1 = np.searchsorted(times, s), np.searchsorted(times, s + lag)
    cov = _covariance_on_grid(times, sol, D0, gamma0, tau0, exponent)
    c = cov[np.ix_(i1, i1)]
    c -= cov[np.ix_(i1, i0)]
    c -= cov[np.ix_(i0, i1)]
    c += cov[np.ix_(i0, i0)]
    return float(2.0 * np.vdot(c, c) / (dim * np.trace(c) ** 2))


# -- a heavy tracer in a gas of light hard disks/spheres (Brownian motion) ------------------
#
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


def tracer_contact_value(
    eta: FloatOrArray, tracer_radius: float, radius: float, dim: int = 3
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
    g1 = contact_value(eta, dim)
    g2 = compressibility_factor(eta, dim)
    g = g0 + z * (-3.0 * g0 + 4.0 * g1 - g2) / 2.0 + z * z * (g0 - 2.0 * g1 + g2) / 2.0
    return g[()] if g.ndim == 0 else g


def tracer_friction(
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
        Number density n of the gas where the tracer is (centres per area or volume).
    radius, mass : float
        The gas particles' r and m.
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
    Derived in the comment above this function (Rayleigh's heavy particle with Enskog's
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
        eta = packing_fraction(density, radius, 1.0, dim)
        chi = float(tracer_contact_value(eta, tracer_radius, radius, dim))
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


def tracer_langevin_coefficients(
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
    g = tracer_friction(density, radius, tracer_radius, tracer_mass, temperature, mass, dim, chi)
    return LangevinCoefficients(g, temperature / (tracer_mass * g), math.inf)


def wall_adsorption(density: float, radius: float, dim: int = 3) -> float:
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
