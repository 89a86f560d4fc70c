"""The magnitudes within which granular keeps each physical scale, so that float64 holds
every square, product and sum its arithmetic forms (used by scene and langevin).

float64 holds magnitudes from 2.2e-308 to 1.8e308.  A scale that gets squared or multiplied
by another (a length, a speed, a time, a rate) kept within SCALE_LO .. SCALE_HI, and each
product of two of them within SCALE_LO**2 .. SCALE_HI**2, leaves a factor of 1e28 below the
largest float64 for sums over particles, steps and windows, and for a gas that cools or
heats by many orders.
"""

from __future__ import annotations

SCALE_LO, SCALE_HI = 1e-140, 1e140


def check_range(
    name: str, value: float, lo: float, hi: float, arithmetic: str, advice: str
) -> None:
    """Raise ValueError unless ``lo <= value <= hi`` (NaN fails too), naming the quantity,
    its value, the range, the arithmetic that needs it (``arithmetic``, e.g. "the collision
    arithmetic") and what to do instead (``advice``)."""
    if not lo <= value <= hi:
        raise ValueError(
            f"{name} = {value:.3g} is outside {lo:g} .. {hi:g}, the range in which "
            f"{arithmetic} stays within float64: {advice}"
        )
