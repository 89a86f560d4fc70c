"""A slow, obvious event-driven MD in pure NumPy: the reference the C engine is tested
against.  Every step computes every pair's collision time over all 3^d periodic images
(or every wall time), moves all particles to the earliest event and applies the thesis'
collision rule (2.10-2.11) or wall rule (2.22).  O(N^2) per event: tests only.

A restitution may be a number or a law (anything callable on a normal impact speed, as
granular.restitution's laws are, evaluated with NumPy): eps(|dv . n|) for a pair, e_w(|v_a|)
for a wall.

A scene's random driving (granular.driving) is its kicks as events, from the engine's
random numbers (csrc/drive.h): the same pairs, times and velocity changes."""

import itertools
import math

import numpy as np


def pair_times(x, v, r, L, periodic):
    n, d = x.shape
    shifts = (
        np.array(list(itertools.product((-1, 0, 1), repeat=d))) * L
        if periodic
        else np.zeros((1, d))
    )
    best = np.full((n, n), np.inf)
    for s in shifts:
        dr = x[None, :, :] + s - x[:, None, :]  # dr[i, j] = x_j + s - x_i
        dv = v[None, :, :] - v[:, None, :]
        b = (dr * dv).sum(-1)
        a = (dv * dv).sum(-1)
        sig = r[:, None] + r[None, :]
        c = (dr * dr).sum(-1) - sig**2
        disc = b * b - a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            t = (-b - np.sqrt(disc)) / a
        ok = (b < 0) & (disc > 0) & (t >= -1e-12)
        best = np.minimum(best, np.where(ok, np.maximum(t, 0.0), np.inf))
    np.fill_diagonal(best, np.inf)
    return best


def run_scene(scene, t_stop, sample_times):
    """``run`` for a granular.Scene: its state, box, restitution and wall restitution."""
    return run(
        np.array(scene.positions),
        np.array(scene.velocities),
        scene.radii,
        scene.masses,
        scene.lower,
        scene.upper,
        scene.boundary == "periodic",
        scene.restitution,
        t_stop,
        sample_times,
        wall_e=scene.wall_restitution,
        driving=scene.driving,
    )


def _eps(restitution, speed):
    return float(restitution(speed)) if callable(restitution) else restitution


def kick_wait(driving, n, k):
    """The waiting time before kick k (csrc/drive.c gr_drive_wait)."""
    from helpers.sde_reference import Stream

    return -math.log(Stream(driving.seed, k, 1).uniform()) / (0.5 * driving.rate * n)


def kick(driving, v, m, k):
    """Kick k on velocities v (changed in place), as csrc/drive.c does it: the pair, then
    the momenta +-dp (white noise) or the pair's relative velocity drawn anew (thermostat)."""
    from helpers.sde_reference import Stream

    n, d = v.shape
    st = Stream(driving.seed, k, 0)
    i = int(st.uniform() * n)
    j = int(st.uniform() * (n - 1))
    j += j >= i
    mi, mj = float(m[i]), float(m[j])
    big, mu = mi + mj, mi * mj / (mi + mj)
    if hasattr(driving, "strength"):
        amp = 2.0 * mu * math.sqrt(driving.strength / driving.rate)
        for a in range(d):
            dp = amp * st.normal()
            v[i, a] += dp / mi
            v[j, a] -= dp / mj
    else:
        sd = math.sqrt(driving.temperature / mu)
        for a in range(d):
            c = (mi * v[i, a] + mj * v[j, a]) / big
            g = sd * st.normal()
            v[i, a] = c + (mj / big) * g
            v[j, a] = c - (mi / big) * g
    return i, j


def run(x, v, r, m, lo, hi, periodic, xi, t_stop, sample_times, wall_e=1.0, driving=None):
    """Positions (unwrapped) and velocities at sample_times."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v = [], []
    samples = list(sample_times)
    kicks, t_kick = 0, math.inf
    if driving is not None:
        t_kick = kick_wait(driving, len(x), 0)
    while True:
        pt = pair_times(x, v, r, L, periodic)
        i, j = np.unravel_index(np.argmin(pt), pt.shape)
        t_pair = pt[i, j]
        t_wall, wall = np.inf, None
        if not periodic:
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(v > 0, (hi - r[:, None] - x) / v, np.inf)
                down = np.where(v < 0, (lo + r[:, None] - x) / v, np.inf)
            w = np.minimum(up, down)
            k = np.unravel_index(np.argmin(w), w.shape)
            t_wall, wall = max(w[k], 0.0), k
        is_kick = t_kick - t < min(t_pair, t_wall)
        dt = min(t_pair, t_wall, t_kick - t)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            out_x.append(x + v * (ts - t) + image * L)
            out_v.append(v.copy())
        if t + dt > t_stop:
            break
        x += v * dt
        t = t_kick if is_kick else t + dt  # (kick times as the engine sums them)
        if periodic:
            wrap = np.floor((x - lo) / L)
            x -= wrap * L
            image += wrap
        if is_kick:
            kick(driving, v, m, kicks)
            kicks += 1
            t_kick = t + kick_wait(driving, len(x), kicks)
        elif t_pair <= t_wall:
            dr = x[j] - x[i]
            if periodic:
                dr -= L * np.round(dr / L)
            dv = v[j] - v[i]
            eps = _eps(xi, -np.dot(dv, dr) / np.sqrt(np.dot(dr, dr)))
            f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
            v[i] += f * m[j] * dr
            v[j] -= f * m[i] * dr
        else:
            p, a = wall
            e_w = _eps(wall_e, abs(v[p, a]))
            v[p, a] = -v[p, a]
            v[p] *= e_w
    return np.array(out_x), np.array(out_v)
