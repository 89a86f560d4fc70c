"""Where Scene.random puts particles and how it draws their velocities: random sequential
addition (dilute), a triangular / face-centred cubic lattice (dense, melted afterwards by
Scene.random), and fixed-speed or Maxwell-Boltzmann velocities."""

from __future__ import annotations

import itertools
import math

import numpy as np

from . import _core


def draw_velocities(rng, n, dim, masses, speed, temperature, remove_drift):
    if temperature is not None:
        if not (temperature >= 0 and math.isfinite(temperature)):
            raise ValueError(f"temperature must be finite and >= 0, got {temperature}")
        v = rng.normal(size=(n, dim)) * np.sqrt(temperature / masses)[:, None]
    else:
        speed = math.sqrt(2.0) if speed is None else float(speed)
        if not (speed >= 0 and math.isfinite(speed)):
            raise ValueError(f"speed must be finite and >= 0, got {speed}")
        g = rng.normal(size=(n, dim))
        norm = np.linalg.norm(g, axis=1)
        norm[norm == 0] = 1.0
        v = speed * g / norm[:, None]
    if remove_drift and n > 1:
        v -= (masses[:, None] * v).sum(axis=0) / masses.sum()
    return v


def place_rsa(rng, radii, lo, hi, periodic, patience=100, max_rounds=5000, fixed=None):
    """Random sequential addition in batches, with k-d trees for the neighbour search.
    Returns None if it does not finish (too dense): when ``patience`` rounds in a row
    place nobody, or after ``max_rounds`` rounds.  (A fixed number of rounds gave up on
    mixtures whose last few big particles need many tries in a small box.)

    A few particles much larger than the rest (a tracer) would make every neighbour
    query as wide as they are; they are checked against everyone directly instead, and
    the trees reach only as far as two of the others can touch.

    ``fixed = (positions (k, d), radii (k,))``: particles already in place (e.g. a tracer
    put in the middle), which the new ones must not overlap; they are checked directly,
    as big ones are, and are not among the rows returned."""
    from scipy.spatial import cKDTree

    n, dim = len(radii), len(lo)
    L = hi - lo
    is_big = _core.big_particles(radii, L, _core.BIG_RATIO, 1.0)
    r_small = float(radii[~is_big].max())
    order = np.argsort(-radii, kind="stable")  # big ones first: they are the hard ones
    placed = np.empty((0, dim))
    placed_r = np.empty(0)
    placed_big = np.empty(0, dtype=bool)
    if fixed is not None:
        placed = np.array(fixed[0], dtype=np.float64).reshape(-1, dim)
        placed_r = np.array(fixed[1], dtype=np.float64).reshape(-1)
        placed_big = np.ones(len(placed_r), dtype=bool)
    n_fixed = len(placed_r)
    box = L if periodic else None
    shift = lambda x: np.mod(x - lo, L) if periodic else x  # noqa: E731
    todo = order
    idle = 0
    for _ in range(max_rounds):
        if len(todo) == 0 or idle >= patience:
            break
        r = radii[todo]
        inset = np.zeros((len(todo), 1)) if periodic else r[:, None]
        cand = lo + inset + rng.random((len(todo), dim)) * (L - 2 * inset)
        ok = np.ones(len(todo), dtype=bool)
        # against the particles placed before: the big ones directly, the rest by tree
        small = ~placed_big
        for b in np.flatnonzero(~small):
            ok &= distance(placed[b], cand, L, periodic) >= placed_r[b] + r
        if small.any():
            ps, pr = placed[small], placed_r[small]
            tree = cKDTree(shift(ps), boxsize=box)
            for k, nbrs in enumerate(tree.query_ball_point(shift(cand), r + r_small)):
                if nbrs and ok[k]:
                    ok[k] = np.all(distance(cand[k], ps[nbrs], L, periodic) >= r[k] + pr[nbrs])
        # among the candidates themselves: the earlier one of a clashing pair wins
        cand_big = is_big[todo]
        for a in np.flatnonzero(cand_big):
            if ok[a]:
                clash = distance(cand[a], cand, L, periodic) < r[a] + r
                clash[: a + 1] = False
                ok &= ~clash
        tree = cKDTree(shift(cand), boxsize=box)
        for a, b in sorted(tree.query_pairs(2 * r_small)):
            if ok[a] and ok[b] and not (cand_big[a] or cand_big[b]):
                if distance(cand[a], cand[b][None], L, periodic)[0] < r[a] + r[b]:
                    ok[b] = False
        placed = np.concatenate([placed, cand[ok]])
        placed_r = np.concatenate([placed_r, r[ok]])
        placed_big = np.concatenate([placed_big, cand_big[ok]])
        todo = todo[~ok]
        idle = 0 if ok.any() else idle + 1
    if len(todo):
        return None
    out = np.empty((n, dim))
    # Rows were placed round by round, not in `order`: hand the rows of each radius to the
    # particles of that radius, in `order` (stable sorts on -radius on both sides).  Which
    # of the equal particles gets which row does not matter (velocities are drawn apart);
    # for equal radii this is the order in which they were placed.
    placed, placed_r = placed[n_fixed:], placed_r[n_fixed:]
    out[order] = placed[np.argsort(-placed_r, kind="stable")]
    return out


def distance(x, ys, L, periodic):
    d = ys - x
    if periodic:
        d -= L * np.round(d / L)
    return np.sqrt((d * d).sum(axis=1))


def lattice_order(positions, G):
    """Q = N <|rho_G|^2> over reciprocal-lattice vectors G, rho_G = mean_j exp(i G.r_j):
    exactly N on the lattice's sites, the structure factor S(G) (a few at most) times a
    unit-mean random factor in a fluid.  Summed in blocks of particles: the phases of a
    million particles at once would take ~300 MB."""
    rho = np.zeros(len(G), dtype=complex)
    for start in range(0, len(positions), 1 << 16):
        rho += np.exp(1j * positions[start : start + (1 << 16)] @ G.T).sum(axis=0)
    rho /= len(positions)
    return len(positions) * float(np.mean(np.abs(rho) ** 2))


def place_lattice(rng, radii, lo, hi, periodic):
    """n sites drawn at random from the densest simple lattice that fits: face-centred
    cubic in 3D (packing up to 0.74 when full), triangular in 2D (up to 0.91).  Returns
    the positions and reciprocal-lattice vectors G (rows) for ``lattice_order``: the
    stars {111}, {200}, {220} of the cubic cell in 3D, the first star in 2D."""
    n, dim = len(radii), len(lo)
    L = hi - lo
    sigma = 2 * float(radii.max()) * (1 + 1e-9)
    inner = L if periodic else L - sigma  # walls: keep the particles inside
    if dim == 3:
        k = max(1, math.ceil((n / 4) ** (1.0 / 3.0)))
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
        grid = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3)
        cell = inner / k
        sites = ((grid[:, None, :] + basis[None, :, :]).reshape(-1, 3) + 0.25) * cell
        nearest = cell.min() / math.sqrt(2)
        hkl = [
            g
            for g in itertools.product(range(-2, 3), repeat=3)
            if sum(x * x for x in g) in (3, 4, 8)
            and len({x % 2 for x in g}) == 1
            and g > tuple(-x for x in g)
        ]
        G = 2 * math.pi * np.array(hkl, dtype=float) / cell
    else:
        # rows of kx sites, every other row shifted by half a spacing; ky even so the
        # shift is periodic; pick kx for the largest nearest-neighbour distance
        best = None
        for kx in range(1, n + 1):
            ky = math.ceil(n / kx)
            ky += ky % 2 if ky > 1 else 0
            ax, ay = inner[0] / kx, inner[1] / ky
            # same row: ax; next row: (ax/2, ay); two rows on: 2 ay straight up
            near = min(ax, math.hypot(ax / 2, ay), 2 * ay) if ky > 1 else ax
            if best is None or near > best[0]:
                best = (near, kx, ky, ax, ay)
            if ax < sigma:
                break
        assert best is not None  # n >= 1: the loop ran at least once
        nearest, kx, ky, ax, ay = best
        i, j = np.meshgrid(np.arange(kx), np.arange(ky), indexing="ij")
        sites = np.stack([(i + 0.25 + 0.5 * (j % 2)) * ax, (j + 0.25) * ay], -1).reshape(-1, 2)
        # basis a1 = (ax, 0), a2 = (ax/2, ay); reciprocal b1, b2 and b1 + b2
        b1, b2 = 2 * math.pi * np.array([1 / ax, -0.5 / ay]), 2 * math.pi * np.array([0.0, 1 / ay])
        G = np.array([b1, b2, b1 + b2])
    if nearest < sigma:
        raise ValueError(
            f"{n} particles of radius {radii.max():g} do not fit in this box even on a "
            f"{'face-centred cubic' if dim == 3 else 'triangular'} lattice"
            + (
                " spaced for the largest of them (random sequential addition jammed first)"
                if radii.min() < radii.max()
                else ""
            )
        )
    pick = rng.choice(len(sites), size=n, replace=False)
    return lo + (0.0 if periodic else sigma / 2) + sites[pick], G
