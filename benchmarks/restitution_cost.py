"""What a restitution law costs per pair collision, against a constant restitution.

One elastic-like gas (N = 2000 spheres at packing 0.23, periodic, T = 1) run through three
kernels: the constant-restitution loop (restitution=1), the law loop with a table that is
1 everywhere (the same events, bit for bit, plus the table lookup), and the viscoelastic
law with a damping so small that eps = 1 - 1e-9 (the same kind of events, plus the normal
speed, one pow and the series).  The three run in turn, round after round (A B C A B C...,
so that a drift of the machine's speed hits all three alike); reported are CPU seconds per
pair collision, median and range over the rounds, and the ratios to the constant loop
taken round by round.  Only granular's public API, as a user's script would.

    python benchmarks/restitution_cost.py                 # 7 rounds of 2e6 events
    python benchmarks/restitution_cost.py --plot cost.png # and a figure
    python benchmarks/restitution_cost.py --tiny          # seconds (CI)
"""

import argparse
import time

import numpy as np

from granular import Scene, Simulation, TabulatedRestitution, Viscoelastic

KERNELS = {
    "constant xi = 1": 1.0,
    "table law (eps = 1)": TabulatedRestitution([0.0], [1.0]),
    "viscoelastic law": Viscoelastic(1e-9, 1.0),
}


def per_collision(scene, events):
    """CPU seconds per pair collision over `events` events after a short warm-up."""
    sim = Simulation(scene)
    sim.run(stop_when={"collisions_per_particle": 2.0}, store=())
    pairs = sim.stats["pair_collisions"]
    t0 = time.process_time()
    sim.run(stop_when={"events": events}, store=())
    seconds = time.process_time() - t0
    return seconds / (sim.stats["pair_collisions"] - pairs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--events", type=int, default=2_000_000)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--plot", help="write a figure to this PNG")
    ap.add_argument("--tiny", action="store_true", help="a few seconds (CI)")
    a = ap.parse_args()
    if a.tiny:
        a.events, a.rounds, a.n = 20_000, 1, 300
    radius = 0.03 * (2000 / a.n) ** (1 / 3)
    base = Scene.random(a.n, radius, dim=3, temperature=1.0, seed=5)
    cost = {name: [] for name in KERNELS}
    for _ in range(a.rounds):
        for name, law in KERNELS.items():
            cost[name].append(per_collision(base.replace(restitution=law), a.events))
    ref = np.array(cost["constant xi = 1"])
    print(f"N = {a.n}, {a.events} events per run, {a.rounds} rounds; CPU us per pair collision")
    for name, c in cost.items():
        c = np.array(c) * 1e6
        r = np.array(cost[name]) / ref
        print(
            f"{name:22s} median {np.median(c):.3f} (range {c.min():.3f}-{c.max():.3f}); "
            f"ratio to constant median {np.median(r):.3f} (range {r.min():.3f}-{r.max():.3f})"
        )
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3))
        for k, c in enumerate(cost.values()):
            c = np.array(c) * 1e6
            ax.plot(np.full(c.size, k), c, "o", color="0.6", ms=4)
            ax.plot([k - 0.25, k + 0.25], [np.median(c)] * 2, "k-", lw=2)
        ax.set_xticks(range(len(cost)), list(cost))
        ax.set_xlim(-0.6, len(cost) - 0.4)
        ax.set_ylim(0, None)
        ax.set_ylabel("CPU µs per pair collision")
        ax.set_title(f"N = {a.n} spheres, packing 0.23: rounds (grey), median (bar)", fontsize=10)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
