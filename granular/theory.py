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
