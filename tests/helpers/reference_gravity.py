"""The slow, obvious reference (reference_edmd.py) with uniform gravity g: parabolic flight
x + v t + g t^2 / 2, v + g t, every particle moved together to the earliest event.

Pair times are those of reference_edmd (all particles share one clock here, and g
cancels in the relative motion).  Wall times are found by brute force, by a method of
its own unlike the engine's closed forms (csrc/flight.h): the real roots of each
quadratic x(t) - stop = 0 from numpy.roots (eigenvalues of its companion matrix), of
which the earliest at which the particle moves towards that wall counts.  A crossing at
the apex (a particle thrown up falls back onto the floor) is then found as any other.
O(N^2) per event: tests only."""

import numpy as np

from helpers.reference_edmd import _eps, pair_times


def wall_time(x, v, g, stop, outward):
    """The earliest t >= 0 at which x + v t + g t^2 / 2 reaches ``stop`` moving outward
    (``outward`` +1: upwards, towards an upper wall; -1: downwards), +inf if never."""
    if g == 0.0:
        if v * outward <= 0.0:
            return np.inf
        return max((stop - x) / v, 0.0)
    # a particle at or past the wall moving outward hits it now (rounding)
    if (x - stop) * outward >= 0.0 and v * outward > 0.0:
        return 0.0
    roots = np.roots([0.5 * g, v, x - stop])
    best = np.inf
    for t in roots:
        if abs(t.imag) > 1e-9 * max(1.0, abs(t.real)):
            continue
        t = t.real
        if t >= -1e-12 and (v + g * t) * outward > 0.0:
            best = min(best, max(t, 0.0))
    return best


def run_scene(scene, t_stop, sample_times, tensors=None):
    """Positions (unwrapped) and velocities of a granular.Scene with gravity at
    sample_times (as reference_edmd.run_scene).  A dict ``tensors`` gets the stress
    tensor's parts at the sample times (as reference_edmd.run's): "collisional", the sum
    over pair collisions of dr_a dp_b, and "kinetic_time", the integral over time of
    sum m v_a v_b, by Simpson's rule over each flight between events (exact: v is linear
    in time in flight, so m v_a v_b is a quadratic), not by the engine's closed form."""
    x = np.array(scene.positions, dtype=float)
    v = np.array(scene.velocities, dtype=float)
    r, m, lo, hi = scene.radii, scene.masses, scene.lower, scene.upper
    g = np.zeros(scene.dim) if scene.gravity is None else np.array(scene.gravity)
    periodic = scene.boundary == "periodic"
    xi, wall_e = scene.restitution, scene.wall_restitution
    n, d = x.shape
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v = [], []
    samples = list(sample_times)
    coll, kin_time = np.zeros((d, d)), np.zeros((d, d))
    coll_out, kin_out = [], []

    def kin_integral(span):
        def tensor(tau):
            w = v + g * tau
            return np.einsum("i,ia,ib->ab", m, w, w)

        return span / 6.0 * (tensor(0.0) + 4.0 * tensor(0.5 * span) + tensor(span))

    while True:
        pt = pair_times(x, v, r, L, periodic)
        i, j = np.unravel_index(np.argmin(pt), pt.shape)
        t_pair = pt[i, j]
        t_wall, wall = np.inf, None
        if not periodic:
            for p in range(n):
                for a in range(d):
                    for stop, out in ((hi[a] - r[p], 1), (lo[a] + r[p], -1)):
                        tw = wall_time(x[p, a], v[p, a], g[a], stop, out)
                        if tw < t_wall:
                            t_wall, wall = tw, (p, a)
        dt = min(t_pair, t_wall)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            tau = ts - t
            out_x.append(x + v * tau + 0.5 * g * tau**2 + image * L)
            out_v.append(v + g * tau)
            coll_out.append(coll.copy())
            kin_out.append(kin_time + kin_integral(tau))
        if t + dt > t_stop:
            break
        kin_time = kin_time + kin_integral(dt)
        x += v * dt + 0.5 * g * dt**2
        v += g * dt
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
            coll += np.outer(dr, -f * m[i] * m[j] * dr)
        else:
            p, a = wall
            e_w = _eps(wall_e, abs(v[p, a]))
            v[p, a] = -v[p, a]
            v[p] *= e_w
            # on the wall exactly, as the engine puts it (else rounding may leave it a hair
            # past, and the next root search starts outside)
            x[p, a] = hi[a] - r[p] if v[p, a] < 0 else lo[a] + r[p]
    if tensors is not None:
        tensors["collisional"] = np.array(coll_out)
        tensors["kinetic_time"] = np.array(kin_out)
    return np.array(out_x), np.array(out_v)
