"""Golden outputs: fixed-seed runs must give the same bits as when the file was written.

Hashes (SHA-256 of the float64 bytes) of positions, velocities, MSDs and the integer
counters of one run per engine mode: 3D periodic inelastic (cells), 2D walls, dense 3D
with neighbour lists, a mixture with a large tracer kept out of the grid, the TC model,
and the Langevin engine with each model and scheme.  A refactoring must leave every hash
alone.  A change that is meant to change a result (a new event order, a fixed bug)
rewrites the file in its own commit, saying why:

    GRANULAR_UPDATE_GOLDEN=1 python -m pytest tests/test_golden.py

The build uses portable flags only (setup.py: no -march=native, no -ffast-math), so the
bits do not depend on the x86-64 machine.
"""

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

import granular
from granular import langevin

GOLDEN = Path(__file__).with_name("golden.json")


def _digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str(a.dtype).encode() + str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _edmd(scene, t_stop, n_samples=6, **sim_kwargs):
    sim = granular.Simulation(scene, **sim_kwargs)
    times = np.linspace(0.0, t_stop, n_samples)
    traj = sim.run(t_stop, sample_times=times)
    # the physical counts only: how the engine names its bookkeeping may change
    counters = {
        k: int(sim.stats[k])
        for k in ("events", "pair_collisions", "wall_collisions", "tc_elastic_collisions")
    }
    return {
        "state": _digest(traj.positions, traj.velocities),
        "energy": _digest(traj.kinetic_energy, traj.momentum),
        "msd": _digest(traj.msd()),
        "counters": counters,
    }


def _mixture_with_tracer():
    base = granular.Scene.random(400, 0.01, dim=2, restitution=0.9, seed=4)
    pos = base.positions.copy()
    radii = base.radii.copy()
    masses = base.masses.copy()
    # one wide, heavy tracer in the middle: free the space it needs first
    centre = np.full(2, 0.5)
    keep = np.linalg.norm(pos - centre, axis=1) > 0.08 + 0.011
    pos, radii, masses = pos[keep], radii[keep], masses[keep]
    vel = base.velocities[keep]
    pos = np.vstack([pos, centre])
    vel = np.vstack([vel, [0.0, 0.0]])
    radii = np.append(radii, 0.08)
    masses = np.append(masses, 20.0)
    return granular.Scene(pos, vel, radii, masses, restitution=0.9)


CASES = {
    "3d-periodic-inelastic-cells": lambda: _edmd(
        granular.Scene.random(500, 0.03, restitution=0.8, seed=1), 2.0
    ),
    "2d-walls-inelastic": lambda: _edmd(
        granular.Scene.random(
            300, 0.01, dim=2, boundary="walls", restitution=0.9, wall_restitution=0.95, seed=2
        ),
        2.0,
    ),
    "3d-dense-lists": lambda: _edmd(
        granular.Scene.random(500, 0.0608, seed=3), 0.3
    ),  # packing 0.47: lists
    "2d-mixture-big-tracer": lambda: _edmd(_mixture_with_tracer(), 1.0),
    "3d-tc-model": lambda: _edmd(
        granular.Scene.random(300, 0.04, restitution=0.3, contact_duration=1e-2, seed=5), 2.0
    ),  # 254 of 1787 collisions elastic under the TC model
}

for _model, _tau0 in (("langevin", np.inf), ("udsbm", 0.972)):
    for _scheme in ("em", "exact"):

        def _case(model=_model, tau0=_tau0, scheme=_scheme):
            r = langevin.run(
                50,
                gamma0=9.26,
                D0=0.072,
                tau0=tau0,
                model=model,
                dt=0.01,
                t_stop=5.0,
                scheme=scheme,
                dim=3,
                tamsd_lags=[0.1, 0.5, 2.0],
                store_positions=True,
                seed=6,
            )
            return {
                "msd": _digest(r.times, r.msd(), r.msd(per_dimension=True), r.v2),
                "tamsd": _digest(r.tamsd_per_particle),
                "positions": _digest(r.positions),
            }

        CASES[f"langevin-{_model}-{_scheme}"] = _case


def _recorded():
    return json.loads(GOLDEN.read_text()) if GOLDEN.exists() else {}


# the granular cases' boxes sit just above the shear-instability size (L/L_c ~ 1.01): the
# warning is right, and beside the point of a test of bits
@pytest.mark.filterwarnings("ignore::granular.ClusteringWarning")
@pytest.mark.parametrize("name", sorted(CASES))
def test_fixed_seed_runs_give_the_recorded_bits(name):
    got = CASES[name]()
    if os.environ.get("GRANULAR_UPDATE_GOLDEN"):
        data = _recorded()
        data[name] = got
        GOLDEN.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
        return
    recorded = _recorded()
    assert name in recorded, (
        f"no golden record for {name!r}; write it with "
        "GRANULAR_UPDATE_GOLDEN=1 python -m pytest tests/test_golden.py"
    )
    assert got == recorded[name]


def test_dense_case_really_uses_lists():
    """The golden file covers the neighbour-list engine only if that case runs with lists."""
    scene = granular.Scene.random(500, 0.0608, seed=3)
    sim = granular.Simulation(scene)
    sim.run(0.01)
    assert sim.stats["shell"] > 0, scene.packing_fraction
