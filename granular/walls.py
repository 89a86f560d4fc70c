"""Moving walls of a walled box: a vibrating wall, the energy source of a vibro-fluidised bed.

``VibratingWall(axis, side, amplitude, angular_frequency, phase=0.0, waveform="sine")`` is a
Scene's ``vibrating_wall``: the face of the box on ``side`` of ``axis`` moves along the axis as

    X(t) = c + A f(omega t + phase),   c = lower + A  (side "lower"),  upper - A  ("upper"),

f = sin (``"sine"``, as in McNamara & Luding 1998 and Kumaran 1998) or the symmetric triangle
wave of the same period and peaks (``"triangle"``: f = (2/pi) asin(sin), the wall moving at
the constant speed +-(2/pi) A omega, the "symmetric sawtooth" of the small-amplitude theory).
The wall therefore sweeps [lower, lower + 2A] (or [upper - 2A, upper]) and never leaves the box
or its cell grid; a particle reaching it is reflected in the wall's frame with the scene's
``wall_restitution`` (csrc/vibwall.h, docs/vibrated.md).

The engine reports the work the wall does (``Simulation.stats["wall_work"]``) and the energy
the collisions dissipate (``stats["collision_loss"]``); the kinetic energy changes by exactly
their difference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Integral
from typing import Any

from ._params import check_positive
from .restitution import RestitutionLaw
from .restitution import describe as _describe_law
from .restitution import from_description as _law_from_description

SIDES = ("lower", "upper")
WAVEFORMS = ("sine", "triangle")

# float64 times the wall's phase omega t to omega ulp(t); the engine refuses a run past the
# time where that exceeds 2^-26 rad (csrc/vibwall.h GR_VIB_PHASE_RESOLUTION).
PHASE_RESOLUTION = 2.0**-26


@dataclass(frozen=True)
class VibratingWall:
    """A wall of a walled box moving along its axis (a vibrating floor or piston).

    Parameters
    ----------
    axis : int
        The axis the wall is normal to (0 = x, 1 = y, 2 = z), < the scene's dimension.
    side : {"lower", "upper"}
        Which face of that axis moves.
    amplitude : float
        A > 0 [L]: the wall sweeps 2A from the face inwards, centred A inside it.
    angular_frequency : float
        omega > 0 [1 / (L sqrt(m/eps))]: the period is 2 pi / omega.
    phase : float, default 0.0
        phi [rad] at t = 0, kept modulo 2 pi (``math.fmod``: the sign stays).
    waveform : {"sine", "triangle"}, default "sine"
        f = sin, or the symmetric triangle wave with the same period, peaks and phase.
    """

    axis: int
    side: str
    amplitude: float
    angular_frequency: float
    phase: float = 0.0
    waveform: str = "sine"

    def __post_init__(self) -> None:
        if isinstance(self.axis, bool) or not isinstance(self.axis, Integral):
            raise TypeError(f"VibratingWall's axis must be an integer, got {self.axis!r}")
        if self.axis < 0:
            raise ValueError(f"VibratingWall's axis must be 0, 1 or 2, got {self.axis}")
        if self.side not in SIDES:
            raise ValueError(f"VibratingWall's side must be one of {SIDES}, got {self.side!r}")
        if self.waveform not in WAVEFORMS:
            raise ValueError(
                f"VibratingWall's waveform must be one of {WAVEFORMS}, got {self.waveform!r}"
            )
        amplitude = check_positive("amplitude", self.amplitude, "the vibrating wall's amplitude")
        omega = check_positive(
            "angular_frequency", self.angular_frequency, "the vibrating wall's angular frequency"
        )
        phase = float(self.phase)
        if not math.isfinite(phase):
            raise ValueError(f"VibratingWall's phase must be finite, got {self.phase!r}")
        # kept modulo 2 pi: the engine times the wall by omega t + phase, whose rounding a
        # phase of 1e16 (ulp 2 rad) would swamp
        phase = math.fmod(phase, 2.0 * math.pi)
        if not (math.isfinite(amplitude * omega) and math.isfinite(amplitude * omega * omega)):
            raise ValueError(
                f"VibratingWall's peak speed A omega = {amplitude:g} * {omega:g} and "
                "acceleration A omega^2 must be finite"
            )
        object.__setattr__(self, "axis", int(self.axis))
        object.__setattr__(self, "amplitude", amplitude)
        object.__setattr__(self, "angular_frequency", omega)
        object.__setattr__(self, "phase", phase)

    @property
    def period(self) -> float:
        """2 pi / omega [L sqrt(m/eps)]."""
        return 2.0 * math.pi / self.angular_frequency

    @property
    def peak_velocity(self) -> float:
        """The wall's largest speed: A omega (sine), (2/pi) A omega (triangle)."""
        v = self.amplitude * self.angular_frequency
        return v if self.waveform == "sine" else 2.0 * v / math.pi

    @property
    def mean_square_velocity(self) -> float:
        """<U^2> over a period: (A omega)^2 / 2 (sine), ((2/pi) A omega)^2 (triangle)."""
        v = self.amplitude * self.angular_frequency
        return 0.5 * v * v if self.waveform == "sine" else (2.0 * v / math.pi) ** 2

    @property
    def max_time(self) -> float:
        """The latest time float64 times the wall's phase to 2^-26 rad: a run may not go
        beyond it (about 2^26 / omega, ten million periods)."""
        return PHASE_RESOLUTION / self.angular_frequency * 2.0**52

    def position(self, t: Any, lower: float, upper: float) -> Any:
        """The wall's position X(t) on a box from ``lower`` to ``upper`` along its axis."""
        import numpy as np

        centre = upper - self.amplitude if self.side == "upper" else lower + self.amplitude
        return centre + self.amplitude * self._wave(
            np.asarray(t) * self.angular_frequency + self.phase
        )

    def velocity(self, t: Any) -> Any:
        """The wall's velocity U(t) along its axis."""
        import numpy as np

        theta = np.asarray(t) * self.angular_frequency + self.phase
        v = self.amplitude * self.angular_frequency
        if self.waveform == "sine":
            return v * np.cos(theta)
        u = np.mod(theta / (2.0 * np.pi), 1.0)
        return np.where((u < 0.25) | (u >= 0.75), 2.0 / np.pi, -2.0 / np.pi) * v

    def _wave(self, theta: Any) -> Any:
        import numpy as np

        if self.waveform == "sine":
            return np.sin(theta)
        u = np.mod(theta / (2.0 * np.pi), 1.0)
        return np.where(u < 0.25, 4.0 * u, np.where(u < 0.75, 2.0 - 4.0 * u, 4.0 * u - 4.0))

    def at_time(self, t: float) -> VibratingWall:
        """The same wall with its clock moved to ``t``: phase phi + omega t (modulo 2 pi),
        so that a new Simulation of a state at time t sees the wall where it was."""
        phase = math.fmod(self.phase + self.angular_frequency * float(t), 2.0 * math.pi)
        return VibratingWall(
            self.axis, self.side, self.amplitude, self.angular_frequency, phase, self.waveform
        )

    def _engine(self) -> dict[str, Any]:
        """The wall as the engine takes it (``_core.EDMD``'s ``vibrating_wall``)."""
        return dict(
            axis=self.axis,
            side=SIDES.index(self.side),
            waveform=WAVEFORMS.index(self.waveform),
            amplitude=self.amplitude,
            omega=self.angular_frequency,
            phase=self.phase,
        )

    def _description(self) -> dict[str, Any]:
        return {
            "wall": "VibratingWall",
            "axis": self.axis,
            "side": self.side,
            "amplitude": self.amplitude,
            "angular_frequency": self.angular_frequency,
            "phase": self.phase,
            "waveform": self.waveform,
        }


def check_scene_wall(value: Any, n: int, d: int) -> VibratingWall | None:
    """A Scene's ``vibrating_wall`` as it keeps it: None, or a VibratingWall on one of its
    d axes (the engine checks the rest against the box and the particles)."""
    if value is None:
        return None
    if not isinstance(value, VibratingWall):
        raise TypeError(f"vibrating_wall must be None or a VibratingWall, got {value!r}")
    if value.axis >= d:
        raise ValueError(f"vibrating_wall's axis must be < the dimension {d}, got {value.axis}")
    return value


def engine_wall(value: VibratingWall | None) -> dict[str, Any]:
    """The Scene parameter's engine keyword."""
    return {"vibrating_wall": None if value is None else value._engine()}


# -- descriptions (checkpoints and GSD files store the scene's parameters as JSON) ---------


def describe(value: Any) -> Any:
    """``restitution.describe``, which also describes a VibratingWall (as
    ``{"wall": "VibratingWall", its arguments}``) and None."""
    if isinstance(value, VibratingWall):
        return value._description()
    if value is None:
        return None
    return _describe_law(value)


def from_description(description: Any) -> Any:
    """The inverse of ``describe``; ValueError for a description it does not know."""
    if isinstance(description, dict) and "wall" in description:
        args = dict(description)
        if args.pop("wall") != "VibratingWall":
            raise ValueError(f"unknown wall {description['wall']!r}")
        return VibratingWall(**args)
    if description is None:
        return None
    return _law_from_description(description)


def is_described(value: Any) -> bool:
    """Whether a GSD file keeps ``value`` as JSON text (a law or a wall)."""
    return isinstance(value, RestitutionLaw | VibratingWall)
