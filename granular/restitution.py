"""Restitution laws: the coefficient of normal restitution as a function of the normal
impact speed of a collision, ``v_n = |(v_j - v_i) * n|`` (n the unit normal at contact).

A Scene's ``restitution`` (pair collisions) and ``wall_restitution`` take a number, as
always, or one of these laws.  The engine (csrc/restitution.h) evaluates the law at every
collision; a number keeps the engine's constant-restitution loop, which runs no law code.

- :class:`ConstantRestitution`: a number written as a law (a Scene stores it as the number).
- :class:`Viscoelastic`: spheres with the dissipative Hertz contact force (Brilliantov,
  Spahn, Hertzsch & Poeschel 1996), eps(v) from the series of Schwager & Poeschel (1998).
- :class:`TabulatedRestitution`: a measured curve, interpolated linearly.

Each law is a small immutable value: it compares by value, pickles, and can be called on
speeds (``law(v)``) with NumPy, the slow obvious evaluation that the engine's is tested
against.
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._params import check_positive

# The engine owns the laws (csrc/restitution.h): their kind numbers, the viscoelastic
# series' coefficients and range and the largest table are read from it, never copied.
_KIND_VISCOELASTIC: int = _core.LAW_VISCOELASTIC
_KIND_TABLE: int = _core.LAW_TABLE

# eps = 1 - C1 delta + C2 delta^2, delta = A kappa^(2/5) v^(1/5) (Schwager & Poeschel 1998,
# Phys. Rev. E 57, 650; Brilliantov & Poeschel, Kinetic Theory of Granular Gases, 2004,
# ch. 6): C1 = Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10)), C2 = (3/5) C1^2
# (tests/test_restitution.py checks the engine's numbers against these formulas).
C1: float = _core.VISCO_C1
C2: float = _core.VISCO_C2
# The series is used up to this delta: for a contact that ends where the force vanishes
# (Schwager & Poeschel 2008) the first dropped term is +(4/15) delta^(5/2) and the error
# 0.0015 here (tests/test_restitution.py integrates the contact); past delta = C1 / (2 C2)
# = 0.72 the truncated series rises again.
DELTA_MAX: float = _core.VISCO_DELTA_MAX
# A table of at most this many points.
TABLE_MAX: int = _core.LAW_TABLE_MAX


class RestitutionLaw(abc.ABC):
    """Base of the restitution laws: eps(v_n) for normal impact speeds v_n >= 0.  A law
    says its value, whether it dissipates, how the engine takes it and what identifies it;
    equality and hashing follow from the last."""

    @abc.abstractmethod
    def __call__(self, speed: ArrayLike) -> NDArray[np.float64]:
        """eps at the given normal impact speeds (>= 0), as the engine applies it."""

    @property
    @abc.abstractmethod
    def loses_energy(self) -> bool:
        """Whether some collision loses kinetic energy under this law (eps < 1)."""

    @abc.abstractmethod
    def _engine(self) -> dict[str, Any] | None:
        """The law as the engine takes it (``_core.EDMD``'s ``law``, ``wall_law``): a dict
        of kind, scale, v_max, speeds and values, or None for a constant (the engine's
        own loop)."""

    @abc.abstractmethod
    def _key(self) -> tuple:
        """The numbers that identify the law (equality, hashing)."""

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash((type(self).__name__, self._key()))


class ConstantRestitution(RestitutionLaw):
    """A constant coefficient of restitution written as a law.

    ``Scene(restitution=ConstantRestitution(0.9))`` is ``Scene(restitution=0.9)``: the
    scene stores the number, and the engine runs its constant-restitution loop.

    Parameters
    ----------
    value : float
        The coefficient, in [0, 1] for pair collisions (a wall also takes values > 1).

    Raises
    ------
    ValueError
        If value is negative or not finite.
    """

    def __init__(self, value: float) -> None:
        from .errors import shown

        try:
            v = float(value)
        except (TypeError, ValueError):
            raise TypeError(f"a restitution must be a number, got {shown(value)}") from None
        if not (v >= 0 and math.isfinite(v)):
            raise ValueError(f"a restitution must be finite and >= 0, got {shown(value)}")
        self.value = v

    def __call__(self, speed: ArrayLike) -> NDArray[np.float64]:
        return np.full(np.shape(speed), self.value)

    @property
    def loses_energy(self) -> bool:
        return self.value < 1.0

    def _engine(self) -> None:
        """None: the engine's constant-restitution loop takes the number itself."""
        return None

    def _key(self) -> tuple:
        return (self.value,)

    def __repr__(self) -> str:
        return f"ConstantRestitution({self.value!r})"


class Viscoelastic(RestitutionLaw):
    """The restitution of viscoelastic spheres, eps falling from 1 as the impact speed grows.

    Spheres whose contact follows the dissipative Hertz force
    ``F = rho (xi^(3/2) + (3/2) A xi^(1/2) dxi/dt)``, ``rho = 2 Y sqrt(R_eff) / (3 (1 - nu^2))``
    (xi the compression; Brilliantov, Spahn, Hertzsch & Poeschel 1996) restitute with ::

        eps(v) = 1 - C1 delta + C2 delta^2,   delta = A kappa^(2/5) v^(1/5),
        kappa = (3/2)^(3/2) Y sqrt(R_eff) / (m_eff (1 - nu^2)),

    C1 = 1.15345, C2 = (3/5) C1^2 = 0.79827 (Schwager & Poeschel 1998), v the normal
    impact speed, R_eff and m_eff the reduced radius and mass.  Only ``A kappa^(2/5)``
    enters (``a_kappa``, the number ``granular.theory`` takes; pass the law itself to its
    viscoelastic functions); ``characteristic_speed`` ``(A kappa^(2/5))^-5`` is the speed
    at which delta = 1.

    The series is of order 2 in delta.  For a contact that ends where the force vanishes
    (the spheres separate before the overlap returns to zero; Schwager & Poeschel 2008) its
    next term is +(4/15) delta^(5/2) (checked by integrating the contact numerically,
    tests/test_restitution.py); it is used for delta <= 0.25 only (eps >= 0.76, error at
    most 0.0015, 0.2 %), i.e. speeds up to ``max_speed``.  A
    faster collision gets eps(max_speed), and the engine counts it
    (``Simulation.stats['law_clamped_collisions']``; ``Simulation.run`` warns): a gas
    whose collisions often exceed ``max_speed`` is outside this law.

    All pairs use the one ``A kappa^(2/5)``: exact for equal spheres; for a mixture kappa
    of each pair would differ, which this law does not model.  In 2D the same law is used
    for disks as a model choice: there is no Hertz law for disks.

    Parameters
    ----------
    damping : float
        The dissipative constant A (a time), > 0.
    kappa : float
        The Hertz constant kappa above (length^(-1/2) time^(-2)), > 0.

    Raises
    ------
    ValueError
        If damping or kappa is not positive and finite.

    References
    ----------
    N. V. Brilliantov, F. Spahn, J.-M. Hertzsch, T. Poeschel, Phys. Rev. E 53, 5382 (1996).

    T. Schwager, T. Poeschel, Phys. Rev. E 57, 650 (1998).

    T. Schwager, T. Poeschel, Phys. Rev. E 78, 051304 (2008).

    N. V. Brilliantov, T. Poeschel, Kinetic Theory of Granular Gases, OUP (2004), ch. 6.
    """

    def __init__(self, damping: float, kappa: float) -> None:
        self.damping = check_positive("damping", damping, "the dissipative constant A")
        self.kappa = check_positive("kappa", kappa, "the elastic constant kappa")
        self.scale = self.damping * self.kappa**0.4
        if not (self.scale > 0 and math.isfinite(self.scale)):
            raise ValueError(
                f"A kappa^(2/5) = {self.scale!r} is outside float64: choose other units"
            )

    @classmethod
    def from_material(
        cls, young: float, poisson: float, damping: float, radius: float, mass: float
    ) -> Viscoelastic:
        """The law for two equal spheres of a material.

        Parameters
        ----------
        young : float
            Young's modulus Y, > 0.
        poisson : float
            Poisson's ratio nu, in (-1, 0.5].
        damping : float
            The dissipative constant A, > 0.
        radius, mass : float
            Of each sphere: R_eff = radius / 2, m_eff = mass / 2.

        Returns
        -------
        Viscoelastic
            With kappa = (3/2)^(3/2) Y sqrt(R_eff) / (m_eff (1 - nu^2)).

        Raises
        ------
        ValueError
            If a parameter is out of range, or together they put kappa outside float64.
        """
        y = check_positive("young", young, "Young's modulus")
        r = check_positive("radius", radius, "each sphere's radius")
        m = check_positive("mass", mass, "each sphere's mass")
        nu = float(poisson)
        if not -1.0 < nu <= 0.5:
            from .errors import shown

            raise ValueError(f"poisson must lie in (-1, 0.5], got {shown(poisson)}")
        # each factor is a positive finite double, but their product or quotient can leave
        # float64 (m / 2 underflows to 0 for the smallest masses): say so, not divide by 0
        denominator = (m / 2) * (1 - nu * nu)
        kappa = 1.5**1.5 * y * math.sqrt(r / 2) / denominator if denominator > 0 else math.inf
        if not (kappa > 0 and math.isfinite(kappa)):
            from .errors import shown

            raise ValueError(
                f"young = {shown(y)}, radius = {shown(r)}, mass = {shown(m)} and poisson = "
                f"{shown(nu)} give the Hertz constant kappa = {shown(kappa)}, outside float64: "
                "give them in units where they are nearer 1"
            )
        return cls(damping, kappa)

    @classmethod
    def from_restitution(cls, restitution: float, speed: float) -> Viscoelastic:
        """The law whose eps at normal impact speed ``speed`` is ``restitution``.

        Only A kappa^(2/5) matters: the law returned has kappa = 1 and the damping that
        gives this value.

        Parameters
        ----------
        restitution : float
            eps at that speed, in [eps(delta = 0.25), 1) = [0.7615, 1).
        speed : float
            > 0.

        Returns
        -------
        Viscoelastic

        Raises
        ------
        ValueError
            If restitution lies outside the series' range or speed is not positive.
        """
        v = check_positive("speed", speed, "the impact speed at which restitution is given")
        e = float(restitution)
        lowest = 1.0 - C1 * DELTA_MAX + C2 * DELTA_MAX**2
        if not lowest <= e < 1.0:
            from .errors import shown

            raise ValueError(
                f"restitution must lie in [{lowest:.4f}, 1) for the viscoelastic series "
                f"(delta <= {DELTA_MAX}), got {shown(restitution)}"
            )
        delta = (C1 - math.sqrt(C1 * C1 - 4.0 * C2 * (1.0 - e))) / (2.0 * C2)
        return cls(delta / v**0.2, 1.0)

    @property
    def a_kappa(self) -> float:
        """A kappa^(2/5), the one material number of the law (``scale``), under the name
        ``granular.theory``'s viscoelastic functions give it: the cooling law, tau0', D(t)
        and the power-law UDSBM coefficients take this number or the law itself."""
        return self.scale

    @property
    def characteristic_speed(self) -> float:
        """(A kappa^(2/5))^-5: the impact speed at which delta would be 1."""
        return _power5(1.0 / self.scale)

    @property
    def max_speed(self) -> float:
        """The largest impact speed at which the series is used (delta = 0.25)."""
        return _power5(DELTA_MAX / self.scale)

    def delta(self, speed: ArrayLike) -> NDArray[np.float64]:
        """The expansion parameter A kappa^(2/5) v^(1/5) at impact speeds v >= 0."""
        return self.scale * np.asarray(speed, dtype=np.float64) ** 0.2

    def __call__(self, speed: ArrayLike) -> NDArray[np.float64]:
        v = np.minimum(np.asarray(speed, dtype=np.float64), self.max_speed)
        d = self.scale * v**0.2
        return 1.0 - C1 * d + C2 * d * d

    @property
    def loses_energy(self) -> bool:
        return True

    def _engine(self) -> dict[str, Any]:
        return dict(
            kind=_KIND_VISCOELASTIC,
            scale=self.scale,
            v_max=self.max_speed,
            speeds=np.empty(0),
            values=np.empty(0),
        )

    def _key(self) -> tuple:
        return (self.damping, self.kappa)

    def __repr__(self) -> str:
        return f"Viscoelastic(damping={self.damping!r}, kappa={self.kappa!r})"


def _power5(x: float) -> float:
    try:
        return x**5
    except OverflowError:
        return math.inf


class TabulatedRestitution(RestitutionLaw):
    """A restitution curve given as a table, e.g. measured: eps interpolated linearly in v.

    Between two points eps is interpolated linearly; below the first speed it is the first
    value, above the last the last (as ``numpy.interp``).  A table that should reach
    eps = 1 at rest must say so with a point (0, 1).

    Parameters
    ----------
    speeds : array_like
        Normal impact speeds, finite, >= 0 and strictly increasing (1 to 10^6 points).
    values : array_like
        eps at those speeds, each in [0, 1].

    Raises
    ------
    ValueError
        If the arrays differ in length, are empty or too long, contain NaN, or break the
        rules above (the message names the first offending point).
    """

    def __init__(self, speeds: ArrayLike, values: ArrayLike) -> None:
        x = np.array(speeds, dtype=np.float64, copy=True).reshape(-1)
        y = np.array(values, dtype=np.float64, copy=True).reshape(-1)
        if x.shape != y.shape:
            raise ValueError(f"speeds and values differ in length: {x.size} and {y.size}")
        if not 1 <= x.size <= TABLE_MAX:
            raise ValueError(f"a restitution table needs 1 to {TABLE_MAX} points, got {x.size}")
        bad = np.flatnonzero(~(np.isfinite(x) & (x >= 0)))
        if bad.size:
            raise ValueError(f"speeds must be finite and >= 0: speeds[{bad[0]}] = {x[bad[0]]}")
        bad = np.flatnonzero(np.diff(x) <= 0)
        if bad.size:
            k = bad[0] + 1
            raise ValueError(
                f"speeds must increase strictly: speeds[{k}] = {x[k]} after {x[k - 1]}"
            )
        bad = np.flatnonzero(~((y >= 0) & (y <= 1)))
        if bad.size:
            raise ValueError(f"values must lie in [0, 1]: values[{bad[0]}] = {y[bad[0]]}")
        x.setflags(write=False)
        y.setflags(write=False)
        self.speeds = x
        self.values = y

    def __call__(self, speed: ArrayLike) -> NDArray[np.float64]:
        return np.interp(np.asarray(speed, dtype=np.float64), self.speeds, self.values)

    @property
    def loses_energy(self) -> bool:
        return bool(np.any(self.values < 1.0))

    def _engine(self) -> dict[str, Any]:
        return dict(kind=_KIND_TABLE, scale=0.0, v_max=0.0, speeds=self.speeds, values=self.values)

    def _key(self) -> tuple:
        return (self.speeds.tobytes(), self.values.tobytes())

    def __repr__(self) -> str:
        if len(self.speeds) > 10:  # a measured curve of many points: a summary, not pages
            return (
                f"TabulatedRestitution(<{len(self.speeds)} points, speeds "
                f"{self.speeds[0]:g}..{self.speeds[-1]:g}, values "
                f"{self.values.min():g}..{self.values.max():g}>)"
            )
        return (
            f"TabulatedRestitution(speeds={self.speeds.tolist()!r}, "
            f"values={self.values.tolist()!r})"
        )


def loses_energy(restitution: float | RestitutionLaw) -> bool:
    """Whether a restitution (a number or a law) makes some collision lose energy."""
    if isinstance(restitution, RestitutionLaw):
        return restitution.loses_energy
    return restitution < 1.0


def heats(restitution: float | RestitutionLaw) -> bool:
    """Whether a wall restitution can add energy (a number > 1; laws stay in [0, 1])."""
    return not isinstance(restitution, RestitutionLaw) and restitution > 1.0


def engine_law(restitution: float | RestitutionLaw) -> dict[str, Any] | None:
    """The law as the engine takes it, or None for a number."""
    return restitution._engine() if isinstance(restitution, RestitutionLaw) else None


# -- a JSON-able description (checkpoints store a scene's parameters as JSON) -------------------

_LAWS: dict[str, Callable[..., RestitutionLaw]] = {
    "Viscoelastic": Viscoelastic,
    "TabulatedRestitution": TabulatedRestitution,
}


def describe(restitution: Any) -> Any:
    """A number as it is; a law as ``{"law": class name, its arguments}``, whose floats JSON
    writes in their shortest round-tripping form (so ``from_description`` gives the law back
    bit for bit); a scene's driving as its own ``describe()``; None as None."""
    if isinstance(restitution, Viscoelastic):
        return {"law": "Viscoelastic", "damping": restitution.damping, "kappa": restitution.kappa}
    if isinstance(restitution, TabulatedRestitution):
        return {
            "law": "TabulatedRestitution",
            "speeds": restitution.speeds.tolist(),
            "values": restitution.values.tolist(),
        }
    if isinstance(restitution, ConstantRestitution):  # (a Scene keeps it as its number)
        return restitution.value
    if isinstance(restitution, RestitutionLaw):
        raise TypeError(f"no description for the restitution law {restitution!r}")
    if hasattr(restitution, "describe"):  # a scene's driving (granular/driving.py)
        return restitution.describe()
    return restitution


def from_description(description: Any) -> Any:
    """The inverse of ``describe``; raises ValueError for a description it does not know."""
    if not isinstance(description, dict):
        return description
    if "driving" in description:  # a scene's driving (granular/driving.py)
        from .driving import from_description as driving

        return driving(description)
    args = dict(description)
    name = args.pop("law", None)
    if name not in _LAWS:
        raise ValueError(f"unknown restitution law {name!r}")
    return _LAWS[name](**args)


# The viscoelastic law's series holds for eps >= 0.76 only (DELTA_MAX):
# a constant xi is matched by a law only if at most this share of the initial collisions
# would be faster than the law's max_speed (and get the clamped eps).
MATCH_CLAMPED_SHARE: float = 0.01


def matched_viscoelastic(
    xi: float, temperature: float, mass: float = 1.0
) -> tuple[Viscoelastic | None, dict[str, float]]:
    """The viscoelastic law with the same mean restitution as a constant xi, or None.

    "Same mean restitution": eps(g) averaged over the initial collisions of a Maxwellian
    gas at ``temperature``, whose normal relative speeds g have the Rayleigh density
    g / s^2 exp(-g^2 / 2 s^2), s^2 = 2 T / m (collisions weight the Gaussian normal
    relative velocity by g).  The mean falls with the damping (bisection), down to about
    0.76, the law's clamp: a xi whose matched law would send more than
    ``MATCH_CLAMPED_SHARE`` of the initial collisions past ``max_speed`` is outside the
    law's range, and None is returned with the reason.  The speed-accuracy benchmark's
    collapse map compares a constant xi with the law matched this way.

    Parameters
    ----------
    xi : float
        The constant restitution to match (dimensionless, 0 < xi < 1).
    temperature : float
        The gas' temperature (energy, k_B = 1), which sets the impact speeds.
    mass : float
        The particle mass (mass units; equal masses).

    Returns
    -------
    (Viscoelastic or None, dict)
        The law (kappa = 1, the damping found) and {"mean_eps", "clamped_share"}; or None
        and the mean and share the closest law reached.
    """
    sd = math.sqrt(2.0 * temperature / mass)
    g = np.linspace(0.0, 12 * sd, 20_001)
    weight = g / sd**2 * np.exp(-(g**2) / (2 * sd**2))

    def mean_eps(damping):
        return float(np.trapezoid(Viscoelastic(damping, 1.0)(g) * weight, g))

    def clamped(law):
        return math.exp(-(law.max_speed**2) / (2 * sd**2))  # Rayleigh tail beyond max_speed

    lo, hi = 1e-6, 10.0
    if mean_eps(hi) > xi:  # even the strongest damping keeps the mean above xi
        law = Viscoelastic(hi, 1.0)
        return None, dict(mean_eps=mean_eps(hi), clamped_share=clamped(law))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mean_eps(mid) > xi else (lo, mid)
    law = Viscoelastic(lo, 1.0)
    info = dict(mean_eps=mean_eps(lo), clamped_share=clamped(law))
    return (law if info["clamped_share"] <= MATCH_CLAMPED_SHARE else None), info
