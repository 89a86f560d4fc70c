"""Gravity's cost against the plain loop: pair collisions per CPU second of one 3D gas
between walls with and without gravity (same N, same packing), in alternating windows of
one process so that both see the same machine load.

    python benchmarks/gravity_throughput.py [N] [packing] [windows]
    python benchmarks/gravity_throughput.py --tiny     (N = 300: that it runs)

g is chosen so that the scale height T / (m g) is the box's height: the gas is stratified
by a factor e from floor to ceiling, its mean packing the one asked for.  Prints the
ratio of the rates (gravity / plain) per window and their median.
"""

import math
import sys
import time

import numpy as np

from granular import Scene, Simulation


def main(n=10_000, eta=0.1, windows=7, events=400_000):
    radius = (eta / (n * 4 / 3 * math.pi)) ** (1 / 3)
    base = Scene.random(n, radius, dim=3, boundary="walls", seed=1)
    g = base.temperature / (base.masses[0] * 1.0)  # scale height = the box's height 1
    sims = {
        "plain": Simulation(base),
        "gravity": Simulation(base.replace(gravity=(0.0, 0.0, -g))),
    }
    for sim in sims.values():  # equilibrate both (gravity: the column settles)
        sim.run(stop_when={"collisions_per_particle": 20}, store=())
    ratios = []
    for _ in range(windows):
        rate = {}
        for name, sim in sims.items():
            pairs = sim.stats["pair_collisions"]
            t0 = time.process_time()
            sim.run(stop_when={"events": events}, store=())
            rate[name] = (sim.stats["pair_collisions"] - pairs) / (time.process_time() - t0)
        ratios.append(rate["gravity"] / rate["plain"])
        plain, grav = rate["plain"], rate["gravity"]
        print(f"plain {plain:.3g}/s  gravity {grav:.3g}/s  ratio {ratios[-1]:.3f}")
    print(f"median ratio {np.median(ratios):.3f} (min {min(ratios):.3f}, max {max(ratios):.3f})")


if __name__ == "__main__":
    if sys.argv[1:] == ["--tiny"]:  # that it runs, not a measurement
        main(300, 0.1, 1, 2000)
    else:
        args = [float(a) for a in sys.argv[1:]]
        main(int(args[0]) if args else 10_000, *(args[1:2] or [0.1]), *[int(a) for a in args[2:3]])
