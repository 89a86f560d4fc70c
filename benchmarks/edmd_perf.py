"""Throughput of the EDMD core on the workloads of the performance target.

Pair collisions per second, one thread, periodic monodisperse hard spheres (and one
disk case), equilibrated first.  Each workload starts from a simple cubic (square)
lattice with Gaussian velocities, runs `--equilibrate` collisions per particle, then
times `--repeats` consecutive windows of `--events` events and reports the best window
(the machine is noisy; the best window is the least disturbed one).

    PYTHONPATH=. python benchmarks/edmd_perf.py            # every workload
    PYTHONPATH=. python benchmarks/edmd_perf.py --only 3d-1e5-0.065 --repeats 5
"""
import argparse
import time

import numpy as np

from granular import _core

WORKLOADS = [
    # name, dim, N, packing fraction
    ("3d-1e3-0.065", 3, 1_000, 0.065),
    ("3d-1e4-0.065", 3, 10_000, 0.065),
    ("3d-1e5-0.065", 3, 100_000, 0.065),
    ("3d-1e6-0.065", 3, 1_000_000, 0.065),
    ("3d-1e4-0.45", 3, 10_000, 0.45),
    ("2d-1e4-0.3", 2, 10_000, 0.3),
]


def lattice(n, d):
    k = int(np.ceil(n ** (1 / d)))
    g = (np.arange(k) + 0.5) / k
    return np.stack(np.meshgrid(*[g] * d, indexing="ij"), -1).reshape(-1, d)[:n].copy()


def radius_for(n, d, eta):
    if d == 3:
        return (eta / (n * 4 / 3 * np.pi)) ** (1 / 3)
    return (eta / (n * np.pi)) ** 0.5


def run(name, d, n, eta, cell_factor, equilibrate, events, repeats, seed):
    rng = np.random.default_rng(seed)
    pos = lattice(n, d)
    vel = rng.normal(size=(n, d))
    vel -= vel.mean(0)
    r = radius_for(n, d, eta)
    sim = _core.EDMD(pos, vel, np.full(n, r), np.ones(n), np.zeros(d), np.ones(d), True,
                     1.0, 1.0, 0.0, cell_factor)
    times = np.array([0.0, 1e300])
    bufs = (np.zeros(2), np.zeros(2 * d), np.zeros(2, np.int64), np.zeros(2, np.int64),
            np.zeros(2), np.zeros(2))
    t0 = time.perf_counter()
    sim.advance(np.inf, equilibrate, -1.0, 1 << 62, times, 2, None, None, *bufs)
    t_eq = time.perf_counter() - t0
    e_start = sim.counters()["kinetic_energy"]
    best = None
    for _ in range(repeats):
        c0 = sim.counters()
        t0 = time.perf_counter()
        sim.advance(np.inf, np.inf, -1.0, events, times, 2, None, None, *bufs)
        dt = time.perf_counter() - t0
        c1 = sim.counters()
        pairs = c1["pair_collisions"] - c0["pair_collisions"]
        ev = c1["events"] - c0["events"]
        row = dict(rate=pairs / dt, ev_per_pair=ev / pairs, ns_per_event=1e9 * dt / ev,
                   cross=(c1["cell_crossings"] - c0["cell_crossings"]) / pairs,
                   stale=(c1["stale_events"] - c0["stale_events"]) / pairs)
        if best is None or row["rate"] > best["rate"]:
            best = row
    best["drift"] = sim.counters()["kinetic_energy"] / e_start - 1.0
    best["t_eq"] = t_eq
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", help="workload names (default: all)")
    ap.add_argument("--cell-factor", type=float, default=1.0)
    ap.add_argument("--equilibrate", type=float, default=20.0, help="collisions per particle")
    ap.add_argument("--events", type=int, default=2_000_000, help="events per timed window")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    print(f"{'workload':14s} {'Mpair/s':>8s} {'ev/pair':>8s} {'ns/ev':>7s} {'cross/pair':>10s} "
          f"{'stale/pair':>10s} {'E drift':>9s} {'equil s':>8s}", flush=True)
    for name, d, n, eta in WORKLOADS:
        if args.only and name not in args.only:
            continue
        b = run(name, d, n, eta, args.cell_factor, args.equilibrate, args.events, args.repeats,
                args.seed)
        print(f"{name:14s} {b['rate'] / 1e6:8.3f} {b['ev_per_pair']:8.2f} {b['ns_per_event']:7.1f} "
              f"{b['cross']:10.2f} {b['stale']:10.3f} {b['drift']:9.1e} {b['t_eq']:8.1f}",
              flush=True)


if __name__ == "__main__":
    main()
