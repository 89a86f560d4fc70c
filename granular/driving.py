"""The random driving force of a Scene (``Scene(..., driving=...)``): random velocity kicks
at random times that keep a granular gas in a non-equilibrium steady state.

- :class:`WhiteNoise`: the "white-noise thermostat" (Williams & MacKintosh 1996, Phys. Rev.
  E 54, R9; van Noije & Ernst 1998, Granular Matter 1, 57): every particle's velocity
  diffuses with ``<dv_a dv_b> = xi0^2 dt delta_ab``, heating each particle by
  ``d m xi0^2 / 2`` per unit time on average (``dT/dt = m xi0^2`` for ``T = m <v^2> / d``).
- :class:`PairThermostat`: a momentum-conserving Andersen-like thermostat at temperature T
  (a random pair's relative velocity drawn anew from the Maxwellian), for elastic gases
  (an inelastic gas reaches a steady state below T).

How the engine does it, exactly (csrc/drive.h): kicks are events at the times of a Poisson
process in which each particle is kicked ``rate`` times per unit time on average; each kick
picks a random pair and gives it equal and opposite momenta (the total momentum is kept
exactly), then predicts the pair's events anew.  White noise is the limit of many small
kicks: one kick's velocity variance per component is ``s^2 = xi0^2 / rate``, and the
first correction to the white-noise Fokker-Planck equation is of relative order
``s^2 m / (2 T)`` (the fourth Kramers-Moyal term).  The heating is exact for any kick
size, but a2 is small: kicks of variance T/(50 m) shift it by +0.003 at xi = 0.8 in 3D,
a third of a2.  So either take ``rate >~ 500 m xi0^2 / T``, or compare with
``theory.sonine_a2_driven(kick=m xi0^2 / (rate T))``, which includes the kicks' size.
Kicks cost about what collisions do (each predicts two particles; docs/driven.md).

Both are small immutable values that compare by value and pickle; a checkpoint and a GSD
file store them as their JSON description (``describe``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import _core
from ._params import check_positive
from ._scales import SCALE_HI, SCALE_LO

# integers below 2^53 are held exactly by the engine's double (csrc/drive.h)
SEED_LIMIT = 2**53


def _scale(name: str, value: float, meaning: str) -> float:
    """``value`` if within the scale limits float64's collision arithmetic carries
    (granular/_scales.py), else ValueError naming it."""
    if not SCALE_LO <= value <= SCALE_HI:
        raise ValueError(
            f"{name} {value:g} is outside {SCALE_LO:g} .. {SCALE_HI:g} ({meaning}): choose "
            "units nearer the gas' own"
        )
    return value


def _seed(seed: Any) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | float) or seed != int(seed):
        raise TypeError(f"seed must be an integer in [0, 2^53), got {seed!r}")
    if not 0 <= int(seed) < SEED_LIMIT:
        raise ValueError(f"seed must be an integer in [0, 2^53), got {seed!r}")
    return int(seed)


@dataclass(frozen=True)
class WhiteNoise:
    """Random kicks that heat a gas as white noise of strength ``xi0^2`` (a Scene's
    ``driving``).

    Parameters
    ----------
    strength : float
        xi0^2 > 0 [L^2 / T^3 in the units of docs/conventions.md: speed^2 per unit time],
        each velocity component's diffusion: ``<dv_a^2> = xi0^2 dt``.  The heating per
        particle is ``d m xi0^2 / 2`` per unit time (``heating``).
    rate : float
        Kicks each particle receives per unit time on average, > 0 [1 / time].  Each kick
        changes a velocity component by a Gaussian of variance ``strength / rate`` (equal
        masses); white noise needs ``rate >> m * strength / T``.
    seed : int, default 0
        The kicks' random numbers, an integer in [0, 2^53): the same seed gives the same
        kicks bit for bit.

    Notes
    -----
    Mixtures: each kick gives the pair momenta +-dp, dp = 2 mu s z (mu the reduced mass,
    z standard normal, s^2 = strength / rate), so equal masses get velocity kicks of
    variance s^2, and the pair's relative velocity always gets 4 s^2.
    """

    strength: float
    rate: float
    seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "strength", check_positive("strength", self.strength, "the noise's xi0^2")
        )
        object.__setattr__(
            self, "rate", check_positive("rate", self.rate, "kicks per particle per unit time")
        )
        object.__setattr__(self, "seed", _seed(self.seed))
        _scale("strength", self.strength, "the noise's xi0^2")
        _scale("rate", self.rate, "kicks per particle per unit time")
        _scale("strength / rate", self.strength / self.rate, "one kick's velocity variance")

    def heating(self, dim: int, mass: float = 1.0) -> float:
        """Mean energy input per particle per unit time, ``dim * mass * strength / 2``
        (equal masses)."""
        return 0.5 * dim * mass * self.strength

    def kick_variance(self) -> float:
        """One kick's velocity variance per component (equal masses), ``strength / rate``."""
        return self.strength / self.rate

    def _engine(self) -> dict[str, float]:
        return {
            "drive_kind": float(_core.DRIVE_WHITE_NOISE),
            "drive_rate": self.rate,
            "drive_strength": self.strength,
            "drive_seed": float(self.seed),
        }

    def describe(self) -> dict[str, Any]:
        """A JSON-able description (``from_description`` gives it back bit for bit)."""
        return {
            "driving": "WhiteNoise",
            "strength": self.strength,
            "rate": self.rate,
            "seed": self.seed,
        }


@dataclass(frozen=True)
class PairThermostat:
    """A momentum-conserving Andersen-like thermostat (a Scene's ``driving``): at the times
    of a Poisson process a random pair's relative velocity is drawn anew from the
    Maxwellian at ``temperature``, its centre-of-mass velocity kept.

    It leaves the canonical distribution of an elastic gas at ``temperature`` (with its
    total momentum) unchanged, so an elastic gas relaxes to it; an inelastic gas settles
    below it.  (Lowe's 1999 thermostat redraws only the component along the line of
    centres; this one redraws all of them.)

    Parameters
    ----------
    temperature : float
        T > 0 [eps], the Maxwellian's temperature (k_B = 1).
    rate : float
        Redraws each particle takes part in per unit time on average, > 0 [1 / time].
    seed : int, default 0
        The random numbers, an integer in [0, 2^53).
    """

    temperature: float
    rate: float
    seed: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(
            self,
            "temperature",
            check_positive("temperature", self.temperature, "the thermostat's temperature"),
        )
        object.__setattr__(
            self, "rate", check_positive("rate", self.rate, "redraws per particle per unit time")
        )
        object.__setattr__(self, "seed", _seed(self.seed))
        _scale("temperature", self.temperature, "the thermostat's temperature")
        _scale("rate", self.rate, "redraws per particle per unit time")

    def _engine(self) -> dict[str, float]:
        return {
            "drive_kind": float(_core.DRIVE_THERMOSTAT),
            "drive_rate": self.rate,
            "drive_strength": self.temperature,
            "drive_seed": float(self.seed),
        }

    def describe(self) -> dict[str, Any]:
        """A JSON-able description (``from_description`` gives it back bit for bit)."""
        return {
            "driving": "PairThermostat",
            "temperature": self.temperature,
            "rate": self.rate,
            "seed": self.seed,
        }


Driving = WhiteNoise | PairThermostat
_KINDS: dict[str, Any] = {"WhiteNoise": WhiteNoise, "PairThermostat": PairThermostat}

# the engine's keywords without driving (csrc/drive.h: kind 0 runs the plain loop)
NO_DRIVING: dict[str, float] = {
    "drive_kind": 0.0,
    "drive_rate": 0.0,
    "drive_strength": 0.0,
    "drive_seed": 0.0,
}


def check(value: Any) -> WhiteNoise | PairThermostat | None:
    """A Scene's ``driving`` as it keeps it: None, or a WhiteNoise or PairThermostat."""
    if value is None or isinstance(value, WhiteNoise | PairThermostat):
        return value
    raise TypeError(
        f"driving must be None, granular.WhiteNoise or granular.PairThermostat, got {value!r}"
    )


def engine_keywords(value: WhiteNoise | PairThermostat | None) -> dict[str, float]:
    """The engine's four driving keywords."""
    return dict(NO_DRIVING) if value is None else value._engine()


def is_description(description: Any) -> bool:
    """Whether a JSON value is a driving's description."""
    return isinstance(description, dict) and "driving" in description


def from_description(description: dict[str, Any]) -> WhiteNoise | PairThermostat:
    """The inverse of ``describe``; ValueError for a description it does not know."""
    args = dict(description)
    name = args.pop("driving", None)
    if name not in _KINDS:
        raise ValueError(f"unknown driving {name!r}")
    return _KINDS[name](**args)
