"""A slow, obvious event-driven MD in pure NumPy: the reference the C engine is tested
against.  Every step computes every pair's collision time over all 3^d periodic images
(or every wall time), moves all particles to the earliest event and applies the thesis'
collision rule (2.10-2.11) or wall rule (2.22).  O(N^2) per event: tests only.

A restitution may be a number or a law (anything callable on a normal impact speed, as
granular.restitution's laws are, evaluated with NumPy): eps(|dv . n|) for a pair, e_w(|v_a|)
for a wall.

A vibrating wall (``vib``, a granular.VibratingWall) is found by brute force
(helpers/vibwall_reference.py: a fine grid of times up to the next other event, the first
sign change of the gap bisected) and reflects in its own frame: v_a' = U - e_w (v_a - U), the
other components scaled by e_w, e_w of the speed relative to the wall."""

import itertools

import numpy as np

from . import vibwall_reference


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
        vib=scene.vibrating_wall,
    )


def _eps(restitution, speed):
    return float(restitution(speed)) if callable(restitution) else restitution


def run(x, v, r, m, lo, hi, periodic, xi, t_stop, sample_times, wall_e=1.0, vib=None):
    """Positions (unwrapped) and velocities at sample_times."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v = [], []
    samples = list(sample_times)
    while True:
        pt = pair_times(x, v, r, L, periodic)
        i, j = np.unravel_index(np.argmin(pt), pt.shape)
        t_pair = pt[i, j]
        t_wall, wall = np.inf, None
        if not periodic:
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(v > 0, (hi - r[:, None] - x) / v, np.inf)
                down = np.where(v < 0, (lo + r[:, None] - x) / v, np.inf)
            if vib is not None:  # its face is no fixed wall
                (up if vib.side == "upper" else down)[:, vib.axis] = np.inf
            w = np.minimum(up, down)
            k = np.unravel_index(np.argmin(w), w.shape)
            t_wall, wall = max(w[k], 0.0), k
        t_vib, moving = np.inf, None
        if vib is not None:
            a = vib.axis
            for p in range(len(x)):
                horizon = min(t_pair, t_wall, t_stop - t, t_vib)
                th = vibwall_reference.first_hit(
                    vib, lo[a], hi[a], t, x[p, a], v[p, a], r[p], horizon
                )
                if th < t_vib:
                    t_vib, moving = th, p
            if t_vib < min(t_pair, t_wall):
                t_wall, wall = t_vib, (moving, a)
            else:
                moving = None
        dt = min(t_pair, t_wall)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            out_x.append(x + v * (ts - t) + image * L)
            out_v.append(v.copy())
        if t + dt > t_stop:
            break
        x += v * dt
        t += dt
        if periodic:
            wrap = np.floor((x - lo) / L)
            x -= wrap * L
            image += wrap
        if t_pair <= t_wall:
            dr = x[j] - x[i]
            if periodic:
                dr -= L * np.round(dr / L)
            dv = v[j] - v[i]
            eps = _eps(xi, -np.dot(dv, dr) / np.sqrt(np.dot(dr, dr)))
            f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
            v[i] += f * m[j] * dr
            v[j] -= f * m[i] * dr
        elif moving is not None:
            p, a = wall
            U = vibwall_reference.velocity(vib, t)
            e_w = _eps(wall_e, abs(v[p, a] - U))
            v[p, a] = -(v[p, a] - U)
            v[p] *= e_w
            v[p, a] += U
            X = vibwall_reference.position(vib, t, lo[a], hi[a])
            x[p, a] = X - r[p] if vib.side == "upper" else X + r[p]
        else:
            p, a = wall
            e_w = _eps(wall_e, abs(v[p, a]))
            v[p, a] = -v[p, a]
            v[p] *= e_w
    return np.array(out_x), np.array(out_v)
