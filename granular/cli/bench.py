"""Throughput benchmarks: pair collisions per second of the event-driven engine (and the
Langevin engine's workloads when it is present).  Figures are printed and written as
JSON, never asserted: speed is measured here, not in the tests."""

from __future__ import annotations

import math
import os
import platform
import time
from types import ModuleType

from .. import Scene, Simulation
from .output import write_json


def _radius_for(n, eta, dim, box=1.0):
    if dim == 3:
        return (eta * box**3 / (n * 4.0 / 3.0 * math.pi)) ** (1.0 / 3.0)
    return math.sqrt(eta * box**2 / (n * math.pi))


# (name, dim, n, packing fraction, collisions per particle timed)
EDMD_WORKLOADS = [
    ("edmd-3d-eta0.065-n1e3", 3, 1_000, 0.065, 2000.0),
    ("edmd-3d-eta0.065-n1e4", 3, 10_000, 0.065, 200.0),
    ("edmd-3d-eta0.065-n1e5", 3, 100_000, 0.065, 40.0),
    ("edmd-3d-eta0.45-n1e4", 3, 10_000, 0.45, 200.0),
    ("edmd-2d-eta0.16-n1e4", 2, 10_000, 0.16, 200.0),
]
LARGE_WORKLOADS = [("edmd-3d-eta0.065-n1e6", 3, 1_000_000, 0.065, 10.0)]


def edmd_workload(
    name,
    dim,
    n,
    eta,
    collisions,
    *,
    boundary="periodic",
    restitution=1.0,
    equilibrate=10.0,
    windows=3,
    seed=0,
):
    """Time one EDMD workload: an equilibrated molecular gas, then `collisions` more
    collisions per particle in `windows` consecutive windows.  The median window is
    reported (its wall and CPU seconds), with the slowest and fastest windows' rates and
    the load average at the start, so a figure can be set beside another code's typical
    one (never our best window beside its typical)."""
    scene = Scene.random(n, _radius_for(n, eta, dim), dim=dim, boundary=boundary, seed=seed)
    sim = Simulation(scene.replace(restitution=restitution))
    target = equilibrate
    sim.run(stop_when={"collisions_per_particle": target}, store=())
    load = os.getloadavg()[0]
    measured = []  # (rate, pairs, events, wall seconds, CPU seconds) per window
    for _ in range(windows):
        before = sim.stats
        target += collisions / windows
        # CPU time of this thread, where the engine runs: the process's would add NumPy's
        # BLAS threads, which spin for a while after a call without slowing the engine
        # (measured in docs/performance.md)
        t0, c0 = time.perf_counter(), time.thread_time()
        sim.run(stop_when={"collisions_per_particle": target}, store=())
        seconds, cpu = time.perf_counter() - t0, time.thread_time() - c0
        after = sim.stats
        pairs = after["pair_collisions"] - before["pair_collisions"]
        events = after["events"] - before["events"]
        measured.append((pairs / seconds, pairs, events, seconds, cpu))
    measured.sort()
    rate, pairs, events, seconds, cpu = measured[(len(measured) - 1) // 2]  # the median
    return dict(
        name=name,
        engine="edmd",
        dim=dim,
        n=n,
        packing_fraction=round(scene.packing_fraction, 6),
        boundary=boundary,
        restitution=restitution,
        pair_collisions=pairs,
        events=events,
        seconds=seconds,
        cpu_seconds=cpu,
        pair_collisions_per_second=rate,
        pair_collisions_per_second_range=[measured[0][0], measured[-1][0]],
        load_average=load,
        ns_per_event=1e9 * seconds / events,
        windows=windows,
        cells=list(after["cells"][:dim]),
        shell=after["shell"],
    )


def run(quick=False, large=False, langevin=True, out=print, rounds=None):
    """Run the workloads; `quick` shrinks them to seconds (for tests); `rounds` of the
    Langevin runs, interleaved (default 3, 1 when quick)."""
    results = []
    workloads = EDMD_WORKLOADS + (LARGE_WORKLOADS if large else [])
    for name, dim, n, eta, coll in workloads:
        if quick:
            n, coll = min(n, 2000), 5.0
        r = edmd_workload(name, dim, n, eta, coll)
        results.append(r)
        lo, hi = r["pair_collisions_per_second_range"]
        out(
            f"{r['name']:<28} N={r['n']:>8}  {r['pair_collisions_per_second'] / 1e6:6.3f} M pair "
            f"collisions/s, median of {r['windows']} windows "
            f"({lo / 1e6:.3f}-{hi / 1e6:.3f}; {r['ns_per_event']:.0f} ns/event, "
            f"{r['events'] / r['pair_collisions']:.2f} "
            f"events/collision{', neighbour lists' if r['shell'] > 0 else ''})"
        )
    if langevin:
        bench_langevin: ModuleType | None
        try:
            from . import bench_langevin
        except ImportError:
            bench_langevin = None
        if bench_langevin is not None:
            if rounds is None:
                rounds = 1 if quick else 3
            for r in bench_langevin.workloads(quick=quick, rounds=rounds):
                results.append(r)
                out(
                    f"{r['name']:<28} N={r['n']:>8}  {r['particle_steps_per_second'] / 1e6:8.1f} M "
                    f"particle-steps/s on {r['threads']} thread(s), median of {r['rounds']} "
                    f"({r['particle_steps_per_second_range'][0] / 1e6:.1f}-"
                    f"{r['particle_steps_per_second_range'][1] / 1e6:.1f}; "
                    f"{r['particle_steps_per_cpu_second'] / 1e6:.1f} M per CPU-s)  (NumPy: "
                    f"{r['numpy_particle_steps_per_second'] / 1e6:.1f} M/s; peak "
                    f"{r['peak_memory_mb']:.1f} MB; load {r['load_average']:.1f})"
                )
    return results


def main(json_path=None, quick=False, large=False, rounds=None):
    results = run(quick=quick, large=large, rounds=rounds)
    if json_path:
        meta = dict(
            python=platform.python_version(),
            machine=platform.machine(),
            processor=platform.processor(),
        )
        for r in results:
            r.setdefault("host", meta)
        write_json(json_path, results)
    return results
