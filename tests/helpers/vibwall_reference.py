"""A slow, obvious vibrating wall: the wall's position from its formula, and a particle's
first contact with it found by brute force -- the gap evaluated on a fine grid of times,
the first sign change bisected.  Written from the definition (docs/vibrated.md), not from
granular/walls.py or csrc/vibwall.h: the reference the engine's exact search is tested
against.  A grid step of a small fraction of the period finds every hit deeper than the
gap's change over a step's curvature (A omega^2 step^2 / 8); tests keep away from grazes
shallower than that, or compare those with the closed form."""

import numpy as np


def wave(theta, waveform):
    """sin, or the triangle wave with sin's peaks and period."""
    if waveform == "sine":
        return np.sin(theta)
    return 2.0 / np.pi * np.arcsin(np.sin(theta))


def slope(theta, waveform):
    """d wave / d theta."""
    if waveform == "sine":
        return np.cos(theta)
    return 2.0 / np.pi * np.sign(np.cos(theta))


def position(wall, t, lo, hi):
    """X(t) of ``wall`` (a granular.VibratingWall's numbers) on an axis from lo to hi."""
    A = wall.amplitude
    centre = hi - A if wall.side == "upper" else lo + A
    return centre + A * wave(wall.angular_frequency * t + wall.phase, wall.waveform)


def velocity(wall, t):
    theta = wall.angular_frequency * t + wall.phase
    return wall.amplitude * wall.angular_frequency * slope(theta, wall.waveform)


def gap(wall, t, lo, hi, x, r):
    """The distance from the particle's surface to the wall (< 0: through it)."""
    X = position(wall, t, lo, hi)
    return (X - x - r) if wall.side == "upper" else (x - r - X)


def first_hit(wall, lo, hi, t0, x0, v0, r, horizon, points_per_period=20_000):
    """The first time tau in (0, horizon] after t0 at which a particle at x0 with constant
    velocity v0 along the wall's axis touches the wall, to ~1e-15 of the period; inf if it
    does not.  The gap at tau = 0 counts as >= 0 (a particle just reflected sits on it)."""
    period = 2.0 * np.pi / wall.angular_frequency
    step = period / points_per_period
    start = 0.0
    while start < horizon:
        k = np.arange(1, min(200_000, int((horizon - start) / step) + 2) + 1)
        tau = start + k * step
        g = gap(wall, t0 + tau, lo, hi, x0 + v0 * tau, r)
        below = np.flatnonzero(g <= 0.0)
        if below.size:
            j = below[0]
            a = start if j == 0 else tau[j - 1]
            b = tau[j]
            for _ in range(200):
                m = 0.5 * (a + b)
                if m <= a or m >= b:
                    break
                if gap(wall, t0 + m, lo, hi, x0 + v0 * m, r) <= 0.0:
                    b = m
                else:
                    a = m
            return b if b <= horizon else np.inf
        start = tau[-1]
    return np.inf
