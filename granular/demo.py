"""The main job: a granular gas (xi = 0.8) and a molecular gas in the thesis' standard
periodic box, run by event-driven MD and compared with theory."""
from __future__ import annotations

import os

import numpy as np

from .scene import Scene
from .simulation import Simulation


def main(out="granular-demo", quick=False):
    n, radius = (1000, 0.025) if not quick else (300, 0.025 * (1000 / 300) ** (1 / 3))
    t_stop = 20.0 if not quick else 5.0
    times = np.concatenate([[0.0], np.logspace(-2, np.log10(t_stop), 40)])
    os.makedirs(out, exist_ok=True)
    print(f"granular demo: N = {n}, r = {radius:.4g}, periodic unit box, t = 0 .. {t_stop}")
    rows = []
    for label, xi in (("molecular", 1.0), ("granular", 0.8)):
        scene = Scene.random(n, radius, restitution=xi, seed=2020)
        sim = Simulation(scene)
        traj = sim.run(t_stop=t_stop, sample_times=times)
        msd = traj.msd()
        rows.append((label, xi, scene.packing_fraction, traj.temperature[0], traj.temperature[-1],
                     msd[-1], sim.stats["pair_collisions"]))
    print(f"{'gas':<10} {'xi':>4} {'eta':>7} {'T(0)':>8} {'T(end)':>10} {'MSD(end)':>10} {'collisions':>11}")
    for r in rows:
        print(f"{r[0]:<10} {r[1]:>4} {r[2]:>7.4f} {r[3]:>8.4f} {r[4]:>10.4g} {r[5]:>10.4g} {r[6]:>11}")
    return rows
