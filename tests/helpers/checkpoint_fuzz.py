"""Corrupted engine states fed to the C restore (EDMD.restore_state), past the file's
checksums: python checkpoint_fuzz.py COUNT.  Each case must end in ValueError (refused) or,
when it passes the checks, in a bounded run that returns or raises a GranularError.  Prints
one JSON line of counts; a crash kills the process (the test sees its return code), and the
case being tried is printed before each attempt so that a crash names it."""

import json
import sys

import numpy as np

from granular import GranularError, Scene, Simulation


def scenes():
    yield Scene.random(40, 0.03, dim=2, restitution=0.5, contact_duration=1e-4, seed=1), {}
    yield (
        Scene.random(40, 0.06, dim=3, boundary="walls", wall_restitution=0.9, seed=2),
        {},
    )
    yield Scene.random(60, 0.1, dim=3, seed=3), {"shell": 0.25}  # neighbour lists
    pos = np.array([[0.5, 0.5], [0.1, 0.1], [0.9, 0.1], [0.1, 0.9], [0.9, 0.9], [0.2, 0.5]])
    radii = np.array([0.15, 0.02, 0.02, 0.02, 0.02, 0.02])  # one big particle
    vel = np.random.default_rng(4).normal(size=pos.shape)
    yield Scene(pos, vel, radii, box=1.0, boundary="walls"), {}


SPECIAL_INTS = [-(2**31), -(2**31) + 1, -100, -9, -8, -7, -3, -2, -1, 0, 1, 2, 63, 64, 2**31 - 1]
SPECIAL_DOUBLES = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1e308, -1e308, 5e-324, 1.0]


def corrupt(state, rng, n):
    data = bytearray(state)
    kind = int(rng.integers(0, 6))
    if kind == 0:  # truncated
        return bytes(data[: int(rng.integers(0, len(data)))]), "truncate"
    if kind == 1:  # bytes appended
        return bytes(data) + bytes(int(rng.integers(1, 16))), "append"
    if kind == 2:  # random bytes flipped
        for _ in range(int(rng.integers(1, 6))):
            data[int(rng.integers(0, len(data)))] ^= int(rng.integers(1, 256))
        return bytes(data), "flip"
    if kind in (3, 4):  # an aligned int32 overwritten with an index near a range's ends
        values = [*SPECIAL_INTS, n - 1, n, n + 1, -n, int(rng.integers(-(2**31), 2**31))]
        k = 4 * int(rng.integers(0, len(data) // 4))
        v = int(values[int(rng.integers(0, len(values)))])
        data[k : k + 4] = np.int32(v).tobytes()
        return bytes(data), f"int32 {v} at {k}"
    k = 8 * int(rng.integers(0, len(data) // 8))  # a double overwritten
    v = SPECIAL_DOUBLES[int(rng.integers(0, len(SPECIAL_DOUBLES)))]
    data[k : k + 8] = np.float64(v).tobytes()
    return bytes(data), f"double {v} at {k}"


def main(count):
    rng = np.random.default_rng(20261126)
    cases = []
    for scene, knobs in scenes():
        sim = Simulation(scene, **knobs)
        sim.run(stop_when={"events": 300})
        cases.append((scene, knobs, sim._engine.save_state()))
    counts = {"refused": 0, "accepted": 0, "ran": 0, "run_errors": 0}
    for k in range(count):
        scene, knobs, state = cases[k % len(cases)]
        bad, what = corrupt(state, rng, scene.n)
        print(f"case {k}: {what}", file=sys.stderr, flush=True)
        sim = Simulation(scene, **knobs)
        try:
            sim._engine.restore_state(bad)
        except ValueError:
            counts["refused"] += 1
            continue
        counts["accepted"] += 1
        try:
            sim.run(stop_when={"events": 2000}, store=())
            counts["ran"] += 1
        except (GranularError, ValueError, RuntimeError, MemoryError):
            counts["run_errors"] += 1
    print(json.dumps(counts))


if __name__ == "__main__":
    main(int(sys.argv[1]))
