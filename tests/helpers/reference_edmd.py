"""A slow, obvious event-driven MD in pure NumPy: the reference the C engine is tested
against.  Every step computes every pair's collision time over all 3^d periodic images
(or every wall time), moves all particles to the earliest event and applies the thesis'
collision rule (2.10-2.11) or wall rule (2.22).  O(N^2) per event: tests only.

A restitution may be a number or a law (anything callable on a normal impact speed, as
granular.restitution's laws are, evaluated with NumPy): eps(|dv . n|) for a pair, e_w(|v_a|)
for a wall.

A scene's random driving (granular.driving) is its kicks as events, from the engine's
random numbers (csrc/drive.h): the same pairs, times and velocity changes.

Rough particles (``spin`` given: (N,) in 2D, (N, 3) in 3D): the impulse P at the contact
point is found the obvious way, from rigid-body mechanics alone -- the contact point's
relative velocity g(P) after an impulse P (dv = +-P / m, dw = (contact - centre) x (+-P) /
I) is affine in P; P solves g(P) = -xi g_n - beta g_t (Huthmann & Zippelius 1997), and
under Walton's Coulomb rule its tangential part is cut to mu |P_n| where it exceeds that.
Walls are smooth.

A vibrating wall (``vib``, a granular.VibratingWall) is found by brute force
(helpers/vibwall_reference.py: a fine grid of times up to the next other event, the first
sign change of the gap bisected) and reflects in its own frame: v_a' = U - e_w (v_a - U), the
other components scaled by e_w, e_w of the speed relative to the wall.

Gravity (``gravity``, a vector g, between fixed walls): every particle falls on the parabola
x + v t + g t^2 / 2, so a pair's relative motion stays a straight line (the pair times are
the same) and a wall is met at the earliest root of the quadratic where the particle moves
into it.  Not with a vibrating wall or a random driving."""

import itertools
import math

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


def run_scene(scene, t_stop, sample_times, tensors=None):
    """``run`` for a granular.Scene: its state, box, restitution and wall restitution
    (``run_sheared`` for a sheared one); for rough particles (tangential_restitution > -1)
    positions, velocities and spins."""
    rough = getattr(scene, "tangential_restitution", -1.0) != -1.0
    if getattr(scene, "shear_rate", 0.0) != 0.0:
        out = run_sheared(
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
            spin=np.array(scene.angular_velocities) if rough else None,
            beta=scene.tangential_restitution,
            q=scene.inertia_factor,
            mu=scene.friction,
        )
        return out[:2] + out[4:]
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
        driving=scene.driving,
        spin=np.array(scene.angular_velocities) if rough else None,
        beta=scene.tangential_restitution,
        q=scene.inertia_factor,
        mu=scene.friction,
        vib=scene.vibrating_wall,
        gravity=scene.gravity,
    )


def _fall_times(x, v, g, stop, side):
    """Per particle and axis, the earliest tau >= 0 at which x + v tau + g tau^2 / 2 reaches
    ``stop`` moving into it (side +1: upwards, -1: downwards); inf if never.  A particle on
    the stop moving out of it (just reflected) meets it again at the other root only."""
    a, b, c = 0.5 * g[None, :], v, x - stop
    out = np.full(x.shape, np.inf)
    for idx in np.ndindex(x.shape):
        ai, bi, ci = float(a[0, idx[1]]), float(b[idx]), float(c[idx])
        if ai == 0.0:
            roots = [-ci / bi] if bi != 0.0 else []
        else:
            disc = bi * bi - 4.0 * ai * ci
            if disc < 0.0:
                continue
            q = -0.5 * (bi + math.copysign(math.sqrt(disc), bi))
            roots = [q / ai, ci / q] if q != 0.0 else [0.0]
        for tau in sorted(roots):
            # moving into the stop at tau, and not a root behind us (rounding: 1e-12)
            if side * (bi + 2.0 * ai * tau) > 0.0 and tau >= -1e-12:
                out[idx] = max(tau, 0.0)
                break
    return out


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
    tensors=None,
    driving=None,
    spin=None,
    beta=-1.0,
    q=0.4,
    mu=np.inf,
    vib=None,
    gravity=None,
):
    """Positions (unwrapped) and velocities at sample_times.  A dict ``tensors`` gets the
    stress tensor's parts at the sample times: "collisional" (sum over pair collisions of
    dr_a dp_b, dr = x_j - x_i, dp j's momentum change) and "kinetic_time" (the integral of
    sum m v_a v_b over time, summed step by step).  ``driving`` (a granular.WhiteNoise or
    PairThermostat): its kicks, drawn as csrc/drive.c draws them.  With ``spin``, the spins
    too (a third array returned).  ``vib``: a vibrating wall; ``gravity``: g (module
    docstring)."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    g = None if gravity is None else np.asarray(gravity, float)
    if g is not None and (vib is not None or driving is not None or periodic):
        raise NotImplementedError("gravity: between fixed walls only")
    w = None if spin is None else spin.astype(float).copy()
    L = hi - lo
    image = np.zeros_like(x)
    t = 0.0
    out_x, out_v, out_w = [], [], []
    samples = list(sample_times)
    d = x.shape[1]
    coll, kin_time = np.zeros((d, d)), np.zeros((d, d))
    coll_out, kin_out = [], []
    kicks, t_kick = 0, math.inf
    if driving is not None:
        t_kick = kick_wait(driving, len(x), 0)
    while True:
        kin = np.einsum("i,ia,ib->ab", m, v, v)
        pt = pair_times(x, v, r, L, periodic)
        i, j = np.unravel_index(np.argmin(pt), pt.shape)
        t_pair = pt[i, j]
        t_wall, wall = np.inf, None
        if g is not None:
            up = _fall_times(x, v, g, hi - r[:, None], +1)
            down = _fall_times(x, v, g, lo + r[:, None], -1)
            wt = np.minimum(up, down)
            k = np.unravel_index(np.argmin(wt), wt.shape)
            t_wall, wall = wt[k], k
        elif not periodic:
            with np.errstate(divide="ignore", invalid="ignore"):
                up = np.where(v > 0, (hi - r[:, None] - x) / v, np.inf)
                down = np.where(v < 0, (lo + r[:, None] - x) / v, np.inf)
            if vib is not None:  # its face is no fixed wall
                (up if vib.side == "upper" else down)[:, vib.axis] = np.inf
            wt = np.minimum(up, down)
            k = np.unravel_index(np.argmin(wt), wt.shape)
            t_wall, wall = max(wt[k], 0.0), k
        t_vib, moving = np.inf, None
        if vib is not None:
            a = vib.axis
            for p in range(len(x)):
                horizon = min(t_pair, t_wall, t_stop - t, t_vib, t_kick - t)
                th = vibwall_reference.first_hit(
                    vib, lo[a], hi[a], t, x[p, a], v[p, a], r[p], horizon
                )
                if th < t_vib:
                    t_vib, moving = th, p
            if t_vib < min(t_pair, t_wall):
                t_wall, wall = t_vib, (moving, a)
            else:
                moving = None
        is_kick = t_kick - t < min(t_pair, t_wall)
        dt = min(t_pair, t_wall, t_kick - t)
        while samples and samples[0] <= min(t + dt, t_stop):
            ts = samples.pop(0)
            if g is not None:
                out_x.append(x + v * (ts - t) + 0.5 * g * (ts - t) ** 2)
                out_v.append(v + g * (ts - t))
            else:
                out_x.append(x + v * (ts - t) + image * L)
                out_v.append(v.copy())
            if w is not None:
                out_w.append(w.copy())
            coll_out.append(coll.copy())
            kin_out.append(kin_time + kin * (ts - t))
        if t + dt > t_stop:
            break
        if g is not None:
            x += v * dt + 0.5 * g * dt * dt
            v += g * dt
        else:
            x += v * dt
        kin_time = kin_time + kin * dt
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
            if w is not None:
                vj_before = v[j].copy()
                v[i], v[j], w[i], w[j] = rough_collide(
                    dr, v[i], v[j], w[i], w[j], r[i], r[j], m[i], m[j], q, eps, beta, mu, d
                )
                coll += np.outer(dr, m[j] * (v[j] - vj_before))
                continue
            f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
            v[i] += f * m[j] * dr
            v[j] -= f * m[i] * dr
            coll += np.outer(dr, -f * m[i] * m[j] * dr)
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
            if g is not None:  # on the wall exactly (the engine places it there too)
                x[p, a] = hi[a] - r[p] if v[p, a] > 0 else lo[a] + r[p]
            v[p, a] = -v[p, a]
            v[p] *= e_w
    if tensors is not None:
        tensors["collisional"] = np.array(coll_out)
        tensors["kinetic_time"] = np.array(kin_out)
    if w is not None:
        return np.array(out_x), np.array(out_v), np.array(out_w)
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
    x,
    v,
    r,
    m,
    lo,
    hi,
    xi,
    t_stop,
    sample_times,
    shear_rate,
    shear_offset=0.0,
    tensors=None,
    spin=None,
    beta=-1.0,
    q=0.4,
    mu=np.inf,
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
    "collisional" sums dr_a dp_b with dr through the image that touched.

    With ``spin`` (rough particles, ``run``'s), the pair through an image collides by
    ``rough_collide`` with the image's velocity (v_x + ky u) and the particle's own spin
    (the images slide, they do not turn); the spins at sample_times are a fifth array
    returned."""
    x, v = x.astype(float).copy(), v.astype(float).copy()
    w = None if spin is None else spin.astype(float).copy()
    out_s = []
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
            if w is not None:
                out_s.append(w.copy())
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
        if w is not None:  # rough: the rule on the image's velocity, the spins as they are
            vi_before = v[i].copy()
            v[i], vj_after, w[i], w[j] = rough_collide(
                dr, v[i], vj, w[i], w[j], r[i], r[j], m[i], m[j], q, eps, beta, mu, d
            )
            v[j] = vj_after
            v[j][0] -= kyy * u
            dp_i = m[i] * (v[i] - vi_before)
            work += kyy * u * dp_i[0]
            coll += np.outer(dr, -dp_i)
            continue
        f = (1 + eps) * np.dot(dv, dr) / (np.dot(dr, dr) * (m[i] + m[j]))
        v[i] += f * m[j] * dr
        v[j] -= f * m[i] * dr
        # i's x momentum change came across the face from j's image
        work += kyy * u * m[i] * f * m[j] * dr[0]
        coll += np.outer(dr, -f * m[i] * m[j] * dr)
    if tensors is not None:
        tensors["collisional"] = np.array(coll_out)
        tensors["kinetic_time"] = np.array(kin_out)
    out = np.array(out_x), np.array(out_v), np.array(out_k), np.array(out_w)
    return out if w is None else (*out, np.array(out_s))
