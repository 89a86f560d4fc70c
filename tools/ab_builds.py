"""Two builds of granular's C core timed in one process, on the same state, windows alternating.

On this shared machine two processes timed in turn still differ by the load between them
(whole runs: ±10-20 % a pair); two engines in one process, run in turn for short windows,
see the same load. This loads the `_core` extension of two builds side by side (under the
same module name, from their own files), builds one engine from each with the same
equilibrated scene, and runs them in windows of a fixed number of events, A B B A A B ...,
timing each window by the CPU time of this thread (the engines run on it). It prints the
median, quartiles and range of the per-pair ratio A / B, and whether both engines did the
same events (their event counts after all windows).

A build is a folder holding an importable `granular` with its compiled `_core`, e.g.

    pip wheel --no-deps -w /tmp/w_before /path/to/checkout_before
    unzip -q /tmp/w_before/*.whl -d /tmp/before

    python tools/ab_builds.py /tmp/after /tmp/before --eta 0.45 --n 10648

The scene comes from the `granular` this script imports (the working tree's): a random gas
equilibrated for five collisions per particle. Developer tool (it reaches into `_core`);
results in docs/performance.md.
"""

import argparse
import glob
import importlib.machinery
import importlib.util
import math
import time

import numpy as np

from granular import Scene, Simulation


def load_core(folder):
    """The `_core` extension module of the build in folder."""
    paths = glob.glob(f"{folder}/granular/_core*.so")
    if len(paths) != 1:
        raise SystemExit(f"{folder}: expected one granular/_core*.so, found {paths}")
    loader = importlib.machinery.ExtensionFileLoader("_core", paths[0])
    spec = importlib.util.spec_from_file_location("_core", paths[0], loader=loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("a", help="folder of build A")
    p.add_argument("b", help="folder of build B")
    p.add_argument("--n", type=int, default=10648)
    p.add_argument("--eta", type=float, default=0.45, help="packing fraction (3D)")
    p.add_argument("--shell", type=float, default=None, help="default: 0.25 at eta >= 0.4")
    p.add_argument("--window", type=int, default=300_000, help="events a window")
    p.add_argument("--pairs", type=int, default=40)
    args = p.parse_args()
    core_a, core_b = load_core(args.a), load_core(args.b)
    if core_a.__file__ == core_b.__file__:
        raise SystemExit("A and B are the same file")
    shell = args.shell if args.shell is not None else (0.25 if args.eta >= 0.4 else 0.0)
    radius = (args.eta / (args.n * 4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    sim = Simulation(Scene.random(args.n, radius, dim=3, seed=1))
    sim.run(stop_when={"collisions_per_particle": 5.0}, store=())
    scene = sim.scene

    def build(core):
        return core.EDMD(**scene._engine_keywords(), big_ratio=core.BIG_RATIO, shell=shell)

    engines = build(core_a), build(core_b)
    nothing = np.empty(0)
    # A build from before the binding took keywords only takes advance's 14 arguments by
    # position (its keyword list named kinetic_energy twice).
    by_position = [not hasattr(core, "LAW_TABLE") for core in (core_a, core_b)]

    def window(which):
        engine, t0 = engines[which], time.thread_time()
        if by_position[which]:
            engine.advance(math.inf, math.inf, -1.0, args.window, nothing, 0, *[None] * 8)
        else:
            engine.advance(
                t_stop=math.inf,
                collisions_per_particle=math.inf,
                stop_kinetic_energy=-1.0,
                max_events=args.window,
                sample_times=nothing,
                next=0,
            )
        return time.thread_time() - t0

    for which in (0, 1):  # caches and first predictions
        window(which)
    ratios = []
    for k in range(args.pairs):
        order = (0, 1) if k % 2 == 0 else (1, 0)
        seconds = {}
        for which in order:
            seconds[which] = window(which)
        ratios.append(seconds[0] / seconds[1])
    r = np.array(ratios)
    q1, q3 = np.percentile(r, [25, 75])
    # the event counts; float sums can differ in their last bits between builds (the energy
    # total is re-summed from the velocities now and then since the kinetic-energy stop fix)
    counts = [{k: v for k, v in e.counters().items() if isinstance(v, int)} for e in engines]
    same = counts[0] == counts[1]
    print(
        f"N = {args.n}, packing {args.eta}, shell {shell}: A / B, thread CPU time per window of "
        f"{args.window} events, {args.pairs} pairs: median {np.median(r):.3f} (quartiles "
        f"{q1:.3f}-{q3:.3f}, range {r.min():.3f}-{r.max():.3f}); same events: {same}"
    )


if __name__ == "__main__":
    main()
