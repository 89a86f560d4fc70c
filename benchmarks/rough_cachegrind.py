"""Rough particles against smooth ones in each combination, instructions per pair collision
(run under cachegrind by rough_cachegrind.sh): a periodic box, a sheared one, a vibrating
floor, gravity between walls, and a vibrated bed under gravity.  The gas: 3D, N = 10^3,
packing 0.065, equilibrated once (prep; between walls its velocities on the lattice); the
rough one the same with beta = 1, xi = 1 and thermal spins, so that both keep their
temperature (or heat alike) as the smooth one does.

    python rough_cachegrind.py prep DIR
    python rough_cachegrind.py run DIR CASE rough|smooth EVENTS

`--tiny` runs prep and every case, rough and smooth, for a few hundred events in a temporary
folder (that it works, not a measurement).
"""

import sys

import numpy as np

from granular import Scene, Simulation, VibratingWall

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from edmd_perf import lattice, radius_for

N, ETA = 1000, 0.065


CASES = ("periodic", "sheared", "vibrating wall", "gravity", "vibrated bed")


def prep(folder, tiny=False):
    rng = np.random.default_rng(1)
    vel = rng.normal(size=(N, 3))
    vel -= vel.mean(0)
    sim = Simulation(Scene(lattice(N, 3), vel, radius_for(N, 3, ETA)))
    sim.run(stop_when={"collisions_per_particle": 0.5 if tiny else 5.0}, store=())
    sc = sim.scene
    np.savez(f"{folder}/rough-base.npz", pos=sc.positions, vel=sc.velocities, r=sc.radii)


def scene(folder, case, rough):
    z = np.load(f"{folder}/rough-base.npz")
    pos, vel, r = z["pos"], z["vel"], float(z["r"][0])
    if case == "periodic":  # the rough loop alone
        s = Scene(pos, vel, r)
    elif case == "sheared":
        s = Scene(pos, vel, r, shear_rate=0.5)
    else:
        # walls: the lattice (the floor's sweep and a radius clear), the equilibrated
        # velocities; the first E1 events of the count let it melt
        a = 0.5 * r
        pos = 2 * r + a + lattice(N, 3) * (1.0 - 4 * r - 2 * a)
        s = Scene(pos, vel, r, boundary="walls")
        if case in ("gravity", "vibrated bed"):  # scale height T / (m g) about the box
            s = s.replace(gravity=[0.0, 0.0, -1.0])
        if case in ("vibrating wall", "vibrated bed"):
            s = s.replace(vibrating_wall=VibratingWall(2, "lower", a, 20.0))
    if rough:
        rng = np.random.default_rng(2)
        inertia = 0.4 * r * r
        w = rng.normal(size=(N, 3)) / np.sqrt(inertia)
        s = s.replace(angular_velocities=w, tangential_restitution=1.0)
    return s


def run(folder, case, kind, events):
    sim = Simulation(scene(folder, case, kind == "rough"))
    if events:
        sim.run(stop_when={"events": events}, store=())
    print("pairs", sim.stats["pair_collisions"], "events", sim.stats["events"], case, kind)


if __name__ == "__main__":
    if sys.argv[1] == "--tiny":
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            prep(tmp, tiny=True)
            for case in CASES:
                for kind in ("smooth", "rough"):
                    run(tmp, case, kind, 300)
    elif sys.argv[1] == "prep":
        prep(sys.argv[2])
    else:
        run(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
