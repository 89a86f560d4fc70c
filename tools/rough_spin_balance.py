"""Why rough spheres' T_rot / T_tr falls 1-3 % below the Maxwellian theory in 3D (and not in
2D): the velocity-spin correlation of the cooling state, measured and weighed.

Runs the reproduction's rough-sphere cooling state (reproduce_rough: N = 250, eta = 0.065,
xi = 0.9, q = 2/5) for each beta and prints, over the runs' snapshots between 60 and 140
collisions per particle:

- the measured T_rot / T_tr and the theory's (theory.rough_temperature_ratio, which takes
  velocities and spins as independent Gaussians);
- <cos^2 angle(v, w)> - 1/3, zero for independent isotropic v and w; disks cannot have it
  (their spin is normal to their plane of motion);
- the fixed point of the molecular-chaos energy balance (reproduce_rough._walton_moves with
  no Coulomb limit: the constant-beta rule) evaluated three ways: on Gaussian velocities and
  spins (it must return the theory: a check of the Monte Carlo), on the snapshots' own
  particles paired at random, and on the same with the spins shuffled among particles (the
  same one-particle marginals, no correlation).

Usage: python tools/rough_spin_balance.py [runs]   (200 runs: ~2 minutes per beta)
"""

from __future__ import annotations

import math
import sys

import numpy as np

from granular import Simulation, theory
from granular.cli.reproduce_rough import RADIUS, XI, Q, _scene, _walton_moves


def snapshots(beta, runs):
    """Velocities and spins over the runs' snapshots, each scaled to T_tr = 1 (ratios kept)."""
    V, W = [], []
    for seed in range(runs):
        sim = Simulation(_scene(1000 + seed, tangential_restitution=beta, restitution=XI))
        for c in (60.0, 80.0, 100.0, 120.0, 140.0):
            sim.run(stop_when={"collisions_per_particle": c}, store=())
            v = sim.scene.velocities - sim.scene.velocities.mean(axis=0)
            scale = 1.0 / math.sqrt(np.mean(v * v))  # T_tr = 1 at m = 1
            V.append(v * scale)
            W.append(sim.scene.angular_velocities * RADIUS * scale)  # radius-1 units
    return np.concatenate(V), np.concatenate(W)


def fixed_point(V, W, beta, rng, pairs=2_000_000):
    """T_rot / T_tr where the molecular-chaos rates keep the ratio constant (bisection)."""
    i, j = rng.integers(0, len(V), pairs), rng.integers(0, len(V), pairs)
    n = rng.standard_normal((pairs, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    dv, w = V[i] - V[j], W[i] + W[j]
    b = np.einsum("ka,ka->k", dv, n)
    keep = b < 0  # approaching, rate ~ |b|
    n, dv, w, weight = n[keep], dv[keep], w[keep], -b[keep]
    r0 = Q * np.mean(W * W) / np.mean(V * V)

    def drift(r):
        d_tr, d_rot = _walton_moves(n, dv, w * math.sqrt(r / r0), weight, Q, XI, beta, math.inf)
        return d_rot / 3.0 - r * d_tr / 3.0

    lo, hi = 0.01, 5.0
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if drift(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def main(runs):
    rng = np.random.default_rng(2026)
    for beta in (0.0, 0.5, -0.5):
        V, W = snapshots(beta, runs)
        ratio = Q * np.mean(W * W) / np.mean(V * V)
        per = np.einsum("ka,ka->k", V, W) ** 2 / (
            np.einsum("ka,ka->k", V, V) * np.einsum("ka,ka->k", W, W)
        )
        per_run = per.reshape(runs, -1).mean(axis=1) - 1.0 / 3.0
        gauss = fixed_point(rng.standard_normal(V.shape), rng.standard_normal(W.shape), beta, rng)
        joint = fixed_point(V, W, beta, rng)
        shuffled = fixed_point(V, W[rng.permutation(len(W))], beta, rng)
        th = theory.rough_temperature_ratio(restitution=XI, tangential_restitution=beta)
        print(
            f"beta = {beta:+.1f}: T_rot/T_tr measured {ratio:.4f}, theory {th:.4f}; "
            f"<cos^2(v,w)> - 1/3 = {per_run.mean():+.4f} +- "
            f"{per_run.std(ddof=1) / math.sqrt(runs):.4f}; molecular-chaos fixed point: "
            f"Gaussian {gauss:.4f}, snapshots {joint:.4f}, spins shuffled {shuffled:.4f}"
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200)
