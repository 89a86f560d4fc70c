"""Instructions and simulated cache misses per EDMD event, repeatably (for cachegrind).

Wall time on a shared machine moves by 2x; cachegrind's counts do not.  `prep` equilibrates
each workload once (natively, fixed seed) and saves the state; `run` rebuilds a Simulation
from it and does a fixed number of events.  Run `run` under cachegrind twice, with E1 and
E2 events: the difference of the counts over E2 - E1 is the cost per event in the
equilibrated gas, without Python start-up, building and the first predictions.

    python benchmarks/edmd_cachegrind.py prep DIR
    valgrind --tool=cachegrind --cache-sim=yes --LL=8388608,16,64 \\
        python benchmarks/edmd_cachegrind.py run DIR 3d-1e5-0.065 200000

`benchmarks/edmd_cachegrind.sh` does both runs and prints the per-event figures;
`--tiny` runs both steps at N = 500 in a temporary folder (that it works, not a measurement).
"""

import sys
import tempfile

import numpy as np

from granular import Scene, Simulation

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from edmd_perf import WORKLOADS, lattice, radius_for


def prep(folder, tiny=False):
    for name, d, n, eta in WORKLOADS:
        if n > 100_000:
            continue
        n = 500 if tiny else n
        rng = np.random.default_rng(1)
        vel = rng.normal(size=(n, d))
        vel -= vel.mean(0)
        sim = Simulation(Scene(lattice(n, d), vel, radius_for(n, d, eta)))
        sim.run(stop_when={"collisions_per_particle": 0.5 if tiny else 5.0}, store=())
        sc = sim.scene
        np.savez(f"{folder}/{name}.npz", pos=sc.positions, vel=sc.velocities, r=sc.radii)


def run(folder, name, events):
    z = np.load(f"{folder}/{name}.npz")
    sim = Simulation(Scene(z["pos"], z["vel"], z["r"]))
    if events:
        sim.run(stop_when={"events": events}, store=())
    s = sim.stats
    print(name, s["events"], s["pair_collisions"], s["kinetic_energy"], s["shell"])


if __name__ == "__main__":
    if sys.argv[1] == "--tiny":
        with tempfile.TemporaryDirectory() as tmp:
            prep(tmp, tiny=True)
            for name, *_ in WORKLOADS[:1]:
                run(tmp, name, 1000)
    elif sys.argv[1] == "prep":
        prep(sys.argv[2])
    else:
        run(sys.argv[2], sys.argv[3], int(sys.argv[4]))
