"""Analytic results the simulations are checked against.

Equation numbers refer to the thesis (A. Gjersvoll, NTNU 2020) in ``shared/seeds``.
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
from numpy.typing import NDArray

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


# -- the end of homogeneous cooling: the shear instability (issue 15) ----------------------
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
