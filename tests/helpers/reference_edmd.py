"""A slow, obvious event-driven MD in pure NumPy: the reference the C engine is tested
against.  Every step computes every pair's collision time over all 3^d periodic images
(or every wall time), moves all particles to the earliest event and applies the thesis'
collision rule (2.10-2.11) or wall rule (2.22).  O(N^2) per event: tests only.

A restitution may be a number or a law (anything callable on a normal impact speed, as
granular.restitution's laws are, evaluated with NumPy): eps(|dv . n|) for a pair, e_w(|v_a|)
for a wall.

Rough particles (``spin`` given: (N,) in 2D, (N, 3) in 3D): the impulse P at the contact
point is found the obvious way, from rigid-body mechanics alone -- the contact point's
relative velocity g(P) after an impulse P (dv = +-P / m, dw = (contact - centre) x (+-P) /
I) is affine in P; P solves g(P) = -xi g_n - beta g_t (Huthmann & Zippelius 1997), and
under Walton's Coulomb rule its tangential part is cut to mu |P_n| where it exceeds that.
Walls are smooth."""

import itertools

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


def rough_impulse(dr, vi, vj, wi, wj, ri, rj, mi, mj, q, xi, beta, mu):
    """The impulse on j (-P on i) of a rough collision, 3-vectors (a 2D pair embedded with
    its spins along z), dr = x_j - x_i at contact."""
    n = dr / np.sqrt(np.dot(dr, dr))
    inertia_i, inertia_j = q * mi * ri**2, q * mj * rj**2

    def g(P):  # j's surface velocity at the contact point less i's, after an impulse P
        vi2, vj2 = vi - P / mi, vj + P / mj
        wi2 = wi + np.cross(ri * n, -P) / inertia_i
        wj2 = wj + np.cross(-rj * n, P) / inertia_j
        return (vj2 + np.cross(wj2, -rj * n)) - (vi2 + np.cross(wi2, ri * n))

    g0 = g(np.zeros(3))
    a = np.column_stack([g(e) - g0 for e in np.eye(3)])
    gn = np.dot(g0, n) * n
    want = -xi * gn - beta * (g0 - gn)
    P = np.linalg.solve(a, want - g0)
    pn = np.dot(P, n) * n
    pt = P - pn
    limit = mu * np.sqrt(np.dot(pn, pn))
    size = np.sqrt(np.dot(pt, pt))
    if size > limit:  # Coulomb: sliding
        P = pn + pt * (limit / size)
    return P


def rough_collide(dr, vi, vj, wi, wj, ri, rj, mi, mj, q, xi, beta, mu, dim):
    """Velocities and spins after a rough collision (``rough_impulse``): (vi, vj, wi, wj),
    spins as the engine keeps them (2D: scalars, 3D: 3-vectors)."""

    def vec(u):
        return np.append(np.asarray(u, float), 0.0) if dim == 2 else np.asarray(u, float)

    def spin(w):
        return np.array([0.0, 0.0, float(w)]) if dim == 2 else np.asarray(w, float)

    dr3, vi3, vj3, wi3, wj3 = vec(dr), vec(vi), vec(vj), spin(wi), spin(wj)
    P = rough_impulse(dr3, vi3, vj3, wi3, wj3, ri, rj, mi, mj, q, xi, beta, mu)
    n = dr3 / np.sqrt(np.dot(dr3, dr3))
    wi3 = wi3 + np.cross(ri * n, -P) / (q * mi * ri**2)
    wj3 = wj3 + np.cross(-rj * n, P) / (q * mj * rj**2)
    vi3, vj3 = vi3 - P / mi, vj3 + P / mj
    if dim == 2:
        return vi3[:2], vj3[:2], wi3[2], wj3[2]
    return vi3, vj3, wi3, wj3


def run_scene(scene, t_stop, sample_times):
    """``run`` for a granular.Scene: its state, box, restitution and wall restitution; for
    rough particles (tangential_restitution > -1) positions, velocities and spins."""
    rough = scene.tangential_restitution != -1.0
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
        spin=np.array(scene.angular_velocities) if rough else None,
        beta=scene.tangential_restitution,
        q=scene.inertia_factor,
        mu=scene.friction,
    )


def _eps(restitution, speed):
    return float(restitution(speed)) if callable(restitution) else restitution


def run(
    x,
    v,
    r,
    m,
    lo,
    hi,
    periodic,
    xi,
    t_stop,
    sample_times,
    wall_e=1.0,
    spin=None,
    beta=-1.0,
    q=0.4,
    mu=np.inf,
):
    """Positions (unwrapped) and velocities at sample_times; with ``spin``, the spins too."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    w = None if spin is None else spin.astype(float).copy()
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v, out_w = [], [], []
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
            wt = np.minimum(up, down)
            k = np.unravel_index(np.argmin(wt), wt.shape)
            t_wall, wall = max(wt[k], 0.0), k
        dt = min(t_pair, t_wall)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            out_x.append(x + v * (ts - t) + image * L)
            out_v.append(v.copy())
            if w is not None:
                out_w.append(w.copy())
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
            if w is not None:
                v[i], v[j], w[i], w[j] = rough_collide(
                    dr, v[i], v[j], w[i], w[j], r[i], r[j], m[i], m[j], q, eps, beta, mu, x.shape[1]
                )
                continue
            f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
            v[i] += f * m[j] * dr
            v[j] -= f * m[i] * dr
        else:
            p, a = wall
            e_w = _eps(wall_e, abs(v[p, a]))
            v[p, a] = -v[p, a]
            v[p] *= e_w
    if w is not None:
        return np.array(out_x), np.array(out_v), np.array(out_w)
    return np.array(out_x), np.array(out_v)
