"""An elastic gas of hard disks or spheres in equilibrium under uniform gravity: the
hydrostatic density profile along the field.

Hydrostatic balance dP/dz = -n m g (z against the field, g its magnitude) with the equation of
state P = n T Z(eta) at a uniform temperature T (an elastic gas in equilibrium) is, by
the isothermal Gibbs-Duhem relation dP = n d(mu), the constancy of the chemical potential
plus the potential energy, mu(n(z)) + m g z = const (the local-density approximation of
equilibrium statistical mechanics; Hansen & McDonald, *Theory of Simple Liquids*, 4th ed.
2013, on the chemical potential from the equation of state).  With mu / T = ln(n Lambda^d) +
mu_ex(eta) / T and mu_ex / T = integral_0^eta (Z(x) - 1) / x dx + Z(eta) - 1:

    ln eta(z) + mu_ex(eta(z)) / T = c - z / l,    l = T / (m g)  (the scale height),

c fixed by the number of particles between two heights.  The equations of state are
granular's own (``theory.compressibility_factor``): Carnahan-Starling in 3D (Carnahan &
Starling, J. Chem. Phys. 51, 635 (1969)), whose excess chemical potential is
``(8 eta - 9 eta^2 + 3 eta^3) / (1 - eta)^3``; Henderson's in 2D (Henderson, Mol. Phys.
30, 971 (1975)), Z = (1 + eta^2/8) / (1 - eta)^2, whose integral gives
``(9/8) eta / (1 - eta) - (7/8) ln(1 - eta) + Z - 1``.  In the dilute limit the profile is
the barometric exp(-z / l).

In 3D ``approximation="kolafa"`` takes Kolafa's equation of state instead, Carnahan-Starling
with its eta^3 term corrected towards the simulated pressures of the hard-sphere fluid,
Z = (1 + eta + eta^2 - (2/3) eta^3 (1 + eta)) / (1 - eta)^3 (J. Kolafa, given in T. Boublik
and I. Nezbeda, Collect. Czech. Chem. Commun. 51, 2301 (1986)).  Its
excess free energy is the integral (5/3) ln(1 - eta) + eta (34 - 33 eta + 4 eta^2) /
(6 (1 - eta)^2), so mu_ex / T adds Z - 1 = (4 eta - 2 eta^2 + eta^3/3 - (2/3) eta^4) /
(1 - eta)^3.  Z_Kolafa - Z_CS = eta^3 (1 - 2 eta) / (3 (1 - eta)^3): 0.13 % of Z at
eta = 0.2, 0.26 % at 0.3, at most 0.30 % (at eta = 0.36) in the fluid (up to 0.494).

Validity: the local-density approximation holds where the density changes little over a
diameter (l >> sigma); within a diameter or two of a floor or ceiling the hard wall
layers the gas (the contact theorem puts P / T at contact), which it does not describe.
Compare away from the walls, with the number counted there (``bottom``, ``top``)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._params import keyword_only
from ._numerics import _check_dim

# the equations of state each dimension offers, its default first
_EQUATIONS = {3: ("carnahan-starling", "kolafa"), 2: ("henderson",)}


def _equation(approximation: str | None, dim: int) -> str:
    """The equation of state named by ``approximation`` (None: the dimension's default)."""
    _check_dim(dim)
    if approximation is None:
        return _EQUATIONS[dim][0]
    if approximation not in _EQUATIONS[dim]:
        raise ValueError(
            f"approximation must be one of {_EQUATIONS[dim]} in {dim}D, got {approximation!r}"
        )
    return approximation


@keyword_only("eta", "dim", "approximation")
def excess_chemical_potential(
    eta: ArrayLike, *, dim: int = 3, approximation: str | None = None
) -> float | NDArray[np.float64]:
    """Excess chemical potential mu_ex / T of the hard-sphere or hard-disk fluid at packing
    fraction eta, in units of T (module docstring: the closed forms of the integral of
    (Z - 1) / eta plus Z - 1).

    Parameters
    ----------
    eta : array_like
        Packing fraction, in [0, 1).
    dim : int
        2 or 3.
    approximation : str, optional
        The equation of state: in 3D ``"carnahan-starling"`` (the default, granular's
        ``compressibility_factor``) or ``"kolafa"``; in 2D ``"henderson"`` (the default).
    """
    eos = _equation(approximation, dim)
    x = np.asarray(eta, dtype=np.float64)
    if np.any((x < 0) | (x >= 1)):
        raise ValueError("packing fraction must lie in [0, 1)")
    out = _mu_ex(x, eos)
    return out[()] if out.ndim == 0 else out


def _mu_ex(x: NDArray[np.float64], eos: str) -> NDArray[np.float64]:
    if eos == "carnahan-starling":
        return x * (8 - 9 * x + 3 * x**2) / (1 - x) ** 3
    if eos == "kolafa":
        free = 5 / 3 * np.log1p(-x) + x * (34 - 33 * x + 4 * x**2) / (6 * (1 - x) ** 2)
        return free + x * (4 - 2 * x + x**2 / 3 - 2 / 3 * x**3) / (1 - x) ** 3
    return 9 / 8 * x / (1 - x) - 7 / 8 * np.log1p(-x) + (1 + x**2 / 8) / (1 - x) ** 2 - 1


def _compressibility_slope(x: NDArray[np.float64], eos: str) -> NDArray[np.float64]:
    """d(eta Z)/d eta, T times the derivative of ln eta + mu_ex / T in ln eta (> 0)."""
    if eos == "carnahan-starling":  # eta Z = (eta + eta^2 + eta^3 - eta^4) / (1 - eta)^3
        return (1 + 4 * x + 4 * x**2 - 4 * x**3 + x**4) / (1 - x) ** 4
    if eos == "kolafa":  # eta Z = (eta + eta^2 + eta^3 - (2/3) eta^4 (1 + eta)) / (1 - eta)^3
        return (1 + 4 * x + 4 * x**2 - 8 / 3 * x**3 * (1 + x) + 4 / 3 * x**5) / (1 - x) ** 4
    return (1 + x + x**2 / 8 * (3 - x)) / (1 - x) ** 3  # eta (1 + eta^2/8) / (1 - eta)^2


def _eta_at(
    level: NDArray[np.float64], eos: str, guess: NDArray[np.float64] | None = None
) -> NDArray[np.float64]:
    """eta with ln eta + mu_ex(eta) / T = level, elementwise: Newton's method in
    u = ln eta (the left side increases from -inf to +inf on (0, 1), with slope
    d(eta Z)/d eta), kept inside a bracket that bisection narrows where Newton would
    leave it.  The root lies below min(level, 0) (mu_ex >= 0) and above level - 1000 for
    any level up to 1000 - mu_ex there.  ``guess``: a start for eta (a nearby solution)."""
    level = np.asarray(level, dtype=np.float64)
    lo = level - 1000.0
    hi = np.minimum(level, -1e-12)
    u = np.minimum(level, math.log(0.5)) if guess is None else np.clip(np.log(guess), lo, hi)
    for _ in range(100):
        eta = np.exp(u)
        f = u + _mu_ex(eta, eos) - level
        lo = np.where(f < 0, u, lo)
        hi = np.where(f < 0, hi, u)
        step = u - f / _compressibility_slope(eta, eos)
        inside = (step > lo) & (step < hi)
        new = np.where(inside, step, 0.5 * (lo + hi))
        if np.all(np.abs(new - u) <= 1e-13 * np.maximum(1.0, np.abs(u))):
            u = new
            break
        u = new
    return np.exp(u)


@keyword_only(
    "z", "n", "area", "bottom", "top", "radius", "mass", "gravity", "temperature", "dim",
    "approximation",
)  # fmt: skip
def hydrostatic_density(
    z: ArrayLike,
    *,
    n: float,
    area: float,
    bottom: float,
    top: float,
    radius: float,
    mass: float = 1.0,
    gravity: float,
    temperature: float,
    dim: int = 3,
    approximation: str | None = None,
) -> float | NDArray[np.float64]:
    """Number density n(z) of an elastic hard-disk/sphere gas in equilibrium under gravity,
    at heights z against the field (module docstring: ln eta + mu_ex / T = c - z / l).

    Parameters
    ----------
    z : array_like
        Heights of the centres along the axis opposite to g [L].
    n : float
        Number of particles whose centres lie between ``bottom`` and ``top``.
    area : float
        The cross-section (a length in 2D) those centres spread over [L^(d-1)].
    bottom, top : float
        The heights between which ``n`` is counted (for a whole box, its floor and
        ceiling less the radius) [L].
    radius : float
        Particle radius [L].
    mass : float
        Particle mass [m].
    gravity : float
        The magnitude of the acceleration g [eps/(m L)].
    temperature : float
        The uniform temperature T [eps].
    dim : int
        2 or 3.
    approximation : str, optional
        The equation of state (``excess_chemical_potential``): in 3D
        ``"carnahan-starling"`` (the default) or ``"kolafa"``; in 2D ``"henderson"``.

    Returns
    -------
    float or ndarray
        n(z) [L^-d], 0 outside [bottom, top].
    """
    eos = _equation(approximation, dim)
    for name, value in (("area", area), ("gravity", gravity)):
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be positive and finite, got {value}")
    if not (top > bottom):
        raise ValueError(f"top must lie above bottom, got bottom = {bottom}, top = {top}")
    unit = 4.0 / 3.0 * math.pi * radius**3 if dim == 3 else math.pi * radius**2
    scale = temperature / (mass * gravity)
    if not n * unit / (area * (top - bottom)) < 1:
        raise ValueError("more particles than fit between bottom and top")
    # the profile on a grid fine against the scale height (Simpson's rule, an odd number
    # of points), c found by bisection on the count
    points = 2 * int(min(max(1000, 20 * (top - bottom) / scale), 100_000)) + 1
    grid = np.linspace(bottom, top, points)
    h = grid[1] - grid[0]
    weights = np.ones_like(grid)
    weights[1:-1:2], weights[2:-1:2] = 4.0, 2.0
    weights *= h / 3.0

    # c by Newton's method on the count (d eta / dc = eta / d(eta Z)/d eta), from the
    # ideal gas' value, kept inside a bracket that bisection narrows where Newton would
    # leave it
    height = top - bottom
    lo, hi = -800.0, 50.0
    c = math.log(n * unit / (area * scale * -math.expm1(-height / scale)))
    c = min(max(c, lo + 1.0), hi - 1.0)
    eta = None
    for _ in range(200):
        eta = _eta_at(c - (grid - bottom) / scale, eos, eta)
        miss = float(area * np.sum(weights * eta) / unit) - n
        slope = float(area * np.sum(weights * eta / _compressibility_slope(eta, eos)) / unit)
        if miss < 0:
            lo = c
        else:
            hi = c
        step = c - miss / slope
        new = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(new - c) <= 1e-13 * max(1.0, abs(c)):
            c = new
            break
        c = new
    zz = np.asarray(z, dtype=np.float64)
    eta = _eta_at(np.full(zz.shape, c) - (zz - bottom) / scale, eos)
    out = np.where((zz >= bottom) & (zz <= top), eta / unit, 0.0)
    return out[()] if out.ndim == 0 else out
