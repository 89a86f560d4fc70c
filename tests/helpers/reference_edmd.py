"""A slow, obvious event-driven MD in pure NumPy: the reference the C engine is tested
against.  Every step computes every pair's collision time over all 3^d periodic images
(or every wall time), moves all particles to the earliest event and applies the thesis'
collision rule (2.10-2.11) or wall rule (2.22).  O(N^2) per event: tests only.

A restitution may be a number or a law (anything callable on a normal impact speed, as
granular.restitution's laws are, evaluated with NumPy): eps(|dv . n|) for a pair, e_w(|v_a|)
for a wall."""

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


def run_scene(scene, t_stop, sample_times, tensors=None):
    """``run`` for a granular.Scene: its state, box, restitution and wall restitution
    (``run_sheared`` for a sheared one)."""
    if getattr(scene, "shear_rate", 0.0) != 0.0:
        return run_sheared(
            np.array(scene.positions),
            np.array(scene.velocities),
            scene.radii,
            scene.masses,
            scene.lower,
            scene.upper,
            scene.restitution,
            t_stop,
            sample_times,
            scene.shear_rate,
            scene.shear_offset,
            tensors=tensors,
        )[:2]
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
        tensors=tensors,
    )


def _eps(restitution, speed):
    return float(restitution(speed)) if callable(restitution) else restitution


def run(x, v, r, m, lo, hi, periodic, xi, t_stop, sample_times, wall_e=1.0, tensors=None):
    """Positions (unwrapped) and velocities at sample_times.  A dict ``tensors`` gets the
    stress tensor's parts at the sample times: "collisional" (sum over pair collisions of
    dr_a dp_b, dr = x_j - x_i, dp j's momentum change) and "kinetic_time" (the integral of
    sum m v_a v_b over time, summed step by step)."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v = [], []
    samples = list(sample_times)
    d = x.shape[1]
    coll, kin_time = np.zeros((d, d)), np.zeros((d, d))
    coll_out, kin_out = [], []
    while True:
        kin = np.einsum("i,ia,ib->ab", m, v, v)
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
        dt = min(t_pair, t_wall)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            out_x.append(x + v * (ts - t) + image * L)
            out_v.append(v.copy())
            coll_out.append(coll.copy())
            kin_out.append(kin_time + kin * (ts - t))
        if t + dt > t_stop:
            break
        x += v * dt
        t += dt
        kin_time = kin_time + kin * dt
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
    if tensors is not None:
        tensors["collisional"] = np.array(coll_out)
        tensors["kinetic_time"] = np.array(kin_out)
    return np.array(out_x), np.array(out_v)


# -- Lees-Edwards (sliding-brick) images ------------------------------------------------


def sheared_pair_times(x, v, r, L, u, delta, kx_max=2):
    """Every pair's next contact time over all images of a sheared periodic box: along y
    the images ky = -1, 0, 1, displaced along x by ky * delta and moving with ky * u; along
    x the images kx = -kx_max .. kx_max (the displacement can put the nearest one beyond
    the first), along z -1, 0, 1.  Returns (times, image index) with images listed as
    ``sheared_images``."""
    n, d = x.shape
    images = sheared_images(d, kx_max)
    best = np.full((n, n), np.inf)
    which = np.zeros((n, n), dtype=int)
    sig = r[:, None] + r[None, :]
    for k, (kx, ky, kz) in enumerate(images):
        shift = np.zeros(d)
        shift[0] = kx * L[0] + ky * delta
        shift[1] = ky * L[1]
        if d == 3:
            shift[2] = kz * L[2]
        dr = x[None, :, :] + shift - x[:, None, :]
        dv = v[None, :, :] - v[:, None, :]
        dv[..., 0] += ky * u
        b = (dr * dv).sum(-1)
        a = (dv * dv).sum(-1)
        c = (dr * dr).sum(-1) - sig**2
        disc = b * b - a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            t = (-b - np.sqrt(disc)) / a
        ok = (b < 0) & (disc > 0) & (t >= -1e-12)
        t = np.where(ok, np.maximum(t, 0.0), np.inf)
        which = np.where(t < best, k, which)
        best = np.minimum(best, t)
    np.fill_diagonal(best, np.inf)
    return best, images


def sheared_images(d, kx_max=2):
    """The (kx, ky, kz) images ``sheared_pair_times`` tries."""
    zs = (-1, 0, 1) if d == 3 else (0,)
    return [(kx, ky, kz) for kx in range(-kx_max, kx_max + 1) for ky in (-1, 0, 1) for kz in zs]


def run_sheared(
    x, v, r, m, lo, hi, xi, t_stop, sample_times, shear_rate, shear_offset=0.0, tensors=None
):
    """``run`` in a periodic box with Lees-Edwards images across the y faces (flow along x):
    the image across the upper face is displaced along x by delta(t) = (shear_offset +
    u t) mod L_x and moves with u = shear_rate * L_y.  A particle leaving through the upper
    (lower) face re-enters at the lower (upper) one with x -(+) delta and v_x -(+) u.

    The unwrapped positions are integrated on their own, from each particle's velocity in
    the unfolded lattice (its box velocity plus img_y u along x), not from the engine's
    formula.  Each step is at most the time the fastest relative motion needs to cross
    half the narrowest side, so every image that can touch within it is among those
    tried.  Returns (positions, velocities, kinetic energies, boundary work) at
    sample_times; the work is summed from the momentum carried across the faces (a
    crossing's m (v + v') / 2, a collision's impulse through an image) times the velocity
    jump u, and the energy from the velocities.

    A dict ``tensors`` gets the stress tensor's parts at the sample times, as ``run``'s but
    with the peculiar velocities V = v - shear_rate (y - y_c) e_x: "kinetic_time" integrates
    sum m V_a V_b step by step by Simpson's rule (exact: V is linear in time within a step),
    "collisional" sums dr_a dp_b with dr through the image that touched."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    n, d = x.shape
    y_c = 0.5 * (lo[1] + hi[1])
    coll, kin_time = np.zeros((d, d)), np.zeros((d, d))
    coll_out, kin_out = [], []

    def peculiar_tensor(xs):
        vp = v.copy()
        vp[:, 0] -= shear_rate * (xs[:, 1] - y_c)
        return np.einsum("i,ia,ib->ab", m, vp, vp)

    def kin_integral(span):
        mid, end = x + v * (0.5 * span), x + v * span
        return span / 6.0 * (peculiar_tensor(x) + 4 * peculiar_tensor(mid) + peculiar_tensor(end))

    L = hi - lo
    u = shear_rate * L[1]
    unwrapped = x.copy()
    img_y = np.zeros(n)
    t, work = 0.0, 0.0
    out_x, out_v, out_k, out_w = [], [], [], []
    samples = list(sample_times)

    def delta_at(time):
        return (shear_offset + u * time) % L[0]

    while True:
        pt, images = sheared_pair_times(x, v, r, L, u, delta_at(t))
        i, j = np.unravel_index(np.argmin(pt), pt.shape)
        t_pair = pt[i, j]
        cap = 0.5 * L.min() / (abs(u) + 2.0 * np.abs(v).max() + 1e-300)
        # the next y-face crossing: an event, so that a particle is always represented by
        # its image inside the box (as the engine does), its velocity in that frame
        with np.errstate(divide="ignore", invalid="ignore"):
            t_face = np.where(
                v[:, 1] > 0,
                (hi[1] - x[:, 1]) / v[:, 1],
                np.where(v[:, 1] < 0, (lo[1] - x[:, 1]) / v[:, 1], np.inf),
            )
        face = int(np.argmin(t_face))
        t_face = max(t_face[face], 0.0)
        dt = min(t_pair, cap, t_face)
        lab = v.copy()
        lab[:, 0] += img_y * u
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            out_x.append(unwrapped + lab * (ts - t))
            out_v.append(v.copy())
            out_k.append(0.5 * (m[:, None] * v * v).sum())
            out_w.append(work)
            coll_out.append(coll.copy())
            kin_out.append(kin_time + kin_integral(ts - t))
        if t + dt > t_stop:
            break
        if tensors is not None:
            kin_time = kin_time + kin_integral(dt)
        x += v * dt
        unwrapped += lab * dt
        t += dt
        # through a y face: y, then x and v_x, then x back into the box
        ky = np.floor((x[:, 1] - lo[1]) / L[1])
        if dt == t_face and dt < t_pair:
            ky[face] = 1.0 if v[face, 1] > 0 else -1.0
        for p in np.flatnonzero(ky):
            v_before = v[p, 0]
            x[p, 1] -= ky[p] * L[1]
            x[p, 0] -= ky[p] * delta_at(t)
            v[p, 0] -= ky[p] * u
            img_y[p] += ky[p]
            work -= ky[p] * u * m[p] * 0.5 * (v_before + v[p, 0])
        x[:, 0] -= np.floor((x[:, 0] - lo[0]) / L[0]) * L[0]
        if d == 3:
            x[:, 2] -= np.floor((x[:, 2] - lo[2]) / L[2]) * L[2]
        if t_pair > dt:
            continue
        # the image of j that touches i now
        best_k, best_d = 0, np.inf
        for k, (kx, kyy, kz) in enumerate(images):
            shift = np.array(
                [kx * L[0] + kyy * delta_at(t), kyy * L[1], kz * L[2] if d == 3 else 0]
            )
            dist = np.linalg.norm(x[j] + shift[:d] - x[i])
            if dist < best_d:
                best_k, best_d, dr = k, dist, x[j] + shift[:d] - x[i]
        kyy = images[best_k][1]
        vj = v[j].copy()
        vj[0] += kyy * u
        dv = vj - v[i]
        eps = _eps(xi, -np.dot(dv, dr) / np.sqrt(np.dot(dr, dr)))
        f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
        v[i] += f * m[j] * dr
        v[j] -= f * m[i] * dr
        # i's x momentum change came across the face from j's image
        work += kyy * u * m[i] * f * m[j] * dr[0]
        coll += np.outer(dr, -f * m[i] * m[j] * dr)
    if tensors is not None:
        tensors["collisional"] = np.array(coll_out)
        tensors["kinetic_time"] = np.array(kin_out)
    return np.array(out_x), np.array(out_v), np.array(out_k), np.array(out_w)
