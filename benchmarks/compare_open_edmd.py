"""granular against Smallenburg's EDMD, side by side on one machine.

The fastest open event-driven code we know is F. Smallenburg's (github.com/FSmallenburg/EDMD,
"Efficient event-driven simulations of hard spheres", Eur. Phys. J. E 45, 22 (2022)):
`Cell/` keeps cell lists, `Single/` neighbour lists.  Its numbers depend on the machine as
much as ours, so the only fair comparison is both codes on the same machine at the same
time.  This script does that: for each workload it runs a prepared copy of the other code,
and granular with the same N (read from the other code's init.sph) on the same number of
pair collisions, and repeats, interleaved, the order alternating from round to round; every
round is printed with both sides' wall and CPU seconds and the load average, then the median
and range per workload and code, and of the ratio granular / other round by round.

The other code is not shipped here; prepare one directory per workload:
  1. clone the repository; copy `Cell/` (dilute workloads) or `Single/` (packing 0.45),
     with `Grow/mt19937ar.c` beside the source, into a directory per workload;
  2. in the source set `maxtime` (the third number of each workload in WORKLOADS below:
     2-3 M pair collisions), in `Single/` `usethermostat = 0` (it is on as published; we
     compare NVE runs), and in `Cell/` `MAXCEL` to at least the cells per side it asks for
     (published as 75, which at N = 1e5 and 1e6 makes cells wider than it wants and says
     "Consider increasing MAXCEL"; 250 does for 1e6);
  3. build with its Makefile (as published: -Ofast -march=native; granular is built with
     portable -O3);
  4. give it an `init.sph`: from its `Grow/` program with `N` and `targetpackfrac` set, or,
     where that fails (it crashed at N = 1e6 here), a simple cubic lattice of M**3 spheres
     written by `--write-init` (a dilute lattice melts within the first collisions).
Then, for example:

    python benchmarks/compare_open_edmd.py --other 3d-1e5-0.065=/tmp/sm/cell_1e5 \\
        --other 3d-1e4-0.45=/tmp/sm/single_1e4 --repeats 2

(`--tiny` runs granular's side, the lattice writer and the report reader, on a stand-in for
the other code, at a tiny size: what CI checks.)

The other code's throughput is the pair collisions between its first and last reports
("Simtime: t, Collisions: c"; its output is made line-buffered) over the wall time between
them, its CPU time over the same span read from /proc: its setup (8 s at N = 1e6) and final
snapshot are not timed.  granular then runs the same number of pair collisions in one
window after building and equilibrating the gas, which is not timed either
(bench.edmd_workload with one window; wall and CPU time of that window).

`--process-cpu` times the whole processes instead, as a harness outside the project did:
the other code's whole run (CPU time at its exit, its set-up and final snapshot included)
against granular in a fresh interpreter started from the other code's own init.sph, run for
the same number of pair collisions, its Python start-up (the interpreter, NumPy, granular,
reading the file, the scene's checks) included, which weighs on short runs (measured in
docs/performance.md).  The windows give the engines' cost per collision, the whole
processes that of a job of this length.  Give this mode an equilibrated init.sph (the other
code's snapshot_end.sph from an earlier run): both codes then start from the same
uncorrelated state, exact N, not from a lattice that first has to melt.

`--huge-pages` gives both codes the same memory treatment.  granular asks the kernel for
2 MiB pages for its large arrays (madvise, csrc/hugemem.h); the other code's malloc does not
unless glibc is told to (`GLIBC_TUNABLES=glibc.malloc.hugetlb=1`, glibc >= 2.35), which at
N = 1e6 is worth ~12 % to it.  `both` (the default) sets that tunable for the other code;
`neither` turns transparent huge pages off for this process and every process it starts
(prctl PR_SET_THP_DISABLE, inherited), so neither code gets them; `as-built` leaves each code
as published.  Report both treatments: they bracket what memory alone is worth.
"""

import argparse
import ctypes
import math
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

from granular.cli.bench import edmd_workload

# name -> (N, packing fraction, the other code's maxtime: 2-3 M pair collisions)
WORKLOADS = {
    "3d-1e3-0.065": (1_000, 0.065, 4000),
    "3d-1e4-0.065": (10_000, 0.065, 400),
    "3d-1e5-0.065": (100_000, 0.065, 40),
    "3d-1e6-0.065": (1_000_000, 0.065, 6),
    "3d-1e4-0.45": (10_000, 0.45, 20),
}


def write_init(path, m, eta):
    """A simple cubic lattice of m**3 spheres of diameter 1 at packing fraction eta, in the
    other code's init.sph format (N; box lengths; one 'a x y z radius' line each)."""
    if not 0.0 < eta < math.pi / 6.0:
        raise ValueError(f"a simple cubic lattice holds packing fractions below pi/6, not {eta}")
    n = m**3
    box = (n * math.pi / 6.0 / eta) ** (1.0 / 3.0)
    a = box / m
    with open(path, "w") as f:
        f.write(f"{n}\n{box:.12f} {box:.12f} {box:.12f}\n")
        for i in range(m):
            for j in range(m):
                x, y = (i + 0.5) * a, (j + 0.5) * a
                f.writelines(f"a {x:.12f} {y:.12f} {(k + 0.5) * a:.12f} 0.5\n" for k in range(m))


def other_n(directory):
    """The other code's N: the first line of its init.sph, so that granular runs the same
    number of spheres (a lattice of M**3 is not always the workload's round N)."""
    with open(os.path.join(directory, "init.sph")) as f:
        return int(f.readline())


def _cpu_seconds(pid):
    """User + system CPU seconds of a running process so far (/proc, clock ticks)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


HUGE_PAGES = ("both", "neither", "as-built")
# the other code's environment: its malloc's huge pages asked for under --huge-pages both
OTHER_ENV = dict(os.environ)


def treat_memory(mode):
    """Give both codes the memory treatment `mode` (one of HUGE_PAGES), before either runs."""
    if mode == "both":
        OTHER_ENV["GLIBC_TUNABLES"] = ":".join(
            t for t in (os.environ.get("GLIBC_TUNABLES"), "glibc.malloc.hugetlb=1") if t
        )
    elif mode == "neither":
        # PR_SET_THP_DISABLE (41): no transparent huge pages for this process and its
        # children, whatever they madvise; PR_GET_THP_DISABLE (42) reads it back
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(41, 1, 0, 0, 0) != 0 or libc.prctl(42, 0, 0, 0, 0) != 1:
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_THP_DISABLE) failed")


def run_other(directory, eta, whole=False):
    """Run ./md in directory, line-buffered; (pair collisions, wall seconds, CPU seconds)
    between its first and its last report ("Simtime: t, Collisions: c, ..."), so that
    neither its setup (8 s at N = 1e6) nor its final snapshot is timed, as granular's setup
    is not; with `whole`, of the whole process instead (its CPU time at exit), the pair
    collisions being those of its last report."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        ["stdbuf", "-oL", "./md"], cwd=directory, stdout=subprocess.PIPE, text=True, env=OTHER_ENV
    )
    reports, packing = [], None
    for line in proc.stdout:
        now = time.perf_counter()
        if m := re.match(r"Packing fraction\s*:\s*([0-9.]+)", line):
            packing = float(m.group(1))
        elif m := re.match(r"Simtime:\s*[0-9.e+-]+,\s*Collisions:\s*(\d+)", line):
            reports.append((now, _cpu_seconds(proc.pid), int(m.group(1))))
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{directory}: ./md exited with status {proc.returncode}")
    if packing is None or abs(packing - eta) > 1e-3:
        raise RuntimeError(f"{directory}: packing fraction {packing}, not the workload's {eta}")
    if len(reports) < 2:
        raise RuntimeError(f"{directory}: fewer than two 'Simtime: ..., Collisions: ...' lines")
    (t0, cpu0, c0), (t1, cpu1, c1) = reports[0], reports[-1]
    if whole:
        return c1, wall, usage.ru_utime + usage.ru_stime
    return c1 - c0, t1 - t0, cpu1 - cpu0


# granular's side of --process-cpu, run in a fresh interpreter: argv = init.sph, pair
# collisions; prints the pair collisions it ran.  The radii are scaled by 1 - 2e-6: the
# other code writes 12 digits, and two spheres in contact then overlap by ~3e-8 of the box,
# which granular's scene check refuses.
GRANULAR_PROCESS = """
import sys
import numpy as np
from granular import Scene, Simulation
with open(sys.argv[1]) as f:
    n = int(f.readline())
    box = float(f.readline().split()[0])
    rows = [f.readline().split() for _ in range(n)]
xyz = np.mod(np.array([[float(v) for v in r[1:4]] for r in rows]) / box, 1.0)
radii = np.array([float(r[4]) for r in rows]) / box * (1.0 - 2e-6)
v = np.random.default_rng(0).normal(size=xyz.shape)
scene = Scene(positions=xyz, radii=radii, velocities=v - v.mean(axis=0), box=1.0)
sim = Simulation(scene)
sim.run(stop_when={"collisions_per_particle": 2.0 * int(sys.argv[2]) / n}, store=())
print(sim.stats["pair_collisions"])
"""


def run_granular_process(directory, pairs):
    """granular as a whole process (--process-cpu): a fresh interpreter starts from the
    other code's init.sph in directory and runs `pairs` pair collisions; (pair collisions,
    wall seconds, CPU seconds) of the whole process, start-up included."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, "-c", GRANULAR_PROCESS, os.path.join(directory, "init.sph"), str(pairs)],
        stdout=subprocess.PIPE,
        text=True,
    )
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        raise RuntimeError(f"granular from {directory}/init.sph exited with status {code}")
    return int(out.split()[-1]), wall, usage.ru_utime + usage.ru_stime


# What the other code prints, for --tiny: its packing fraction, then a report a step.
STAND_IN = """#!/bin/sh
echo "Packing fraction : 0.0650"
for c in 1000 2000 3000 4000; do
    i=0; while [ $i -lt 20000 ]; do i=$((i + 1)); done
    echo "Simtime: $c.0, Collisions: $c, Press: 1.0"
done
"""


# pair collisions the other code ran per workload, for granular's next run of it
PAIRS = {}


def run_granular(name, n, pairs, directory=None):
    """granular's side: one timed window after building and equilibrating the gas, or with
    `directory` (--process-cpu) a whole process from the other code's init.sph there."""
    if directory is not None:
        return run_granular_process(directory, pairs)
    _, eta, _ = WORKLOADS[name]
    r = edmd_workload(name, 3, n, eta, 2.0 * pairs / n, windows=1)
    return r["pair_collisions"], r["seconds"], r["cpu_seconds"]


def main():
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument(
        "--other",
        action="append",
        default=[],
        metavar="WORKLOAD=DIR",
        help="a prepared run directory of the other code; workloads: " + ", ".join(WORKLOADS),
    )
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--plot", metavar="FILE", help="also chart the figures into FILE (PNG)")
    p.add_argument(
        "--process-cpu",
        action="store_true",
        help="time whole processes, start-up included, granular from the other code's "
        "init.sph (as an outside harness did); default: both codes' timed windows",
    )
    p.add_argument(
        "--huge-pages",
        choices=HUGE_PAGES,
        default="both",
        help="2 MiB pages for both codes (the other's malloc told to ask), for neither "
        "(transparent huge pages off for every process), or each as built (default: both)",
    )
    p.add_argument(
        "--write-init",
        nargs=3,
        metavar=("M", "ETA", "FILE"),
        help="write an M**3 simple cubic lattice at packing fraction ETA and exit",
    )
    p.add_argument(
        "--tiny",
        action="store_true",
        help="granular's side and --write-init at a tiny size, no other code (CI)",
    )
    args = p.parse_args()
    treat_memory(args.huge_pages)
    if args.tiny:
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "init.sph")
            write_init(path, 4, 0.065)
            with open(path) as f:
                if len(f.readlines()) != 2 + 4**3:
                    raise RuntimeError(f"{path}: not the N + 2 lines of an init.sph")
            # the other code's report format, from a stand-in that burns a little CPU
            md = os.path.join(folder, "md")
            with open(md, "w") as f:
                f.write(STAND_IN)
            os.chmod(md, 0o755)
            pairs, seconds, cpu = run_other(folder, 0.065)
            if pairs != 3000 or not 0.0 <= cpu <= 2.0 * seconds + 0.05 or other_n(folder) != 64:
                raise RuntimeError(f"stand-in read as {pairs} pairs, {seconds} s, {cpu} CPU s")
            print(f"{'stand-in':14s} {'other':12s} {pairs:16d} {seconds:8.2f} {cpu:8.2f}")
            # --process-cpu's two sides: the stand-in's whole run, granular from its init.sph
            pairs, seconds, cpu = run_other(folder, 0.065, whole=True)
            if pairs != 4000 or not 0.0 <= cpu <= 2.0 * seconds + 0.05:
                raise RuntimeError(f"stand-in's whole run read as {pairs} pairs, {seconds} s")
            pairs, seconds, cpu = run_granular(None, 64, 200, directory=folder)
            # (no bound from wall time: importing NumPy starts a BLAS thread a core)
            if pairs < 200 or not cpu > 0.0:
                raise RuntimeError(f"granular's process read as {pairs} pairs, {cpu} CPU s")
            print(f"{'tiny process':14s} {'granular':12s} {pairs:16d} {seconds:8.2f} {cpu:8.2f}")
        r = edmd_workload("3d-tiny-0.065", 3, 500, 0.065, 2.0, windows=1)
        print(f"{r['name']:14s} {'granular':12s} {r['pair_collisions']:16d} {r['seconds']:8.2f}")
        return
    if args.write_init:
        m, eta, path = args.write_init
        try:
            write_init(path, int(m), float(eta))
        except ValueError as e:
            p.error(str(e))
        return
    if any("=" not in item for item in args.other):
        p.error("--other wants WORKLOAD=DIR")
    others = dict(item.split("=", 1) for item in args.other)
    if not others:
        p.error("give at least one --other (granular alone: python -m granular bench)")
    if len(others) < len(args.other):
        p.error("a workload given twice in --other")
    unknown = set(others) - set(WORKLOADS)
    if unknown:
        p.error(f"unknown workloads {sorted(unknown)}; known: {', '.join(WORKLOADS)}")
    names = [name for name in WORKLOADS if name in others]
    sizes = {name: other_n(others[name]) for name in names}
    rows = []  # (workload, code, pair collisions per second)
    ratios = {name: [] for name in names}  # granular / other per round: (wall, CPU)

    def report(round_, name, code, pairs, seconds, cpu):
        rows.append((name, code, pairs / seconds))
        print(
            f"{round_:5d} {name:14s} {sizes[name]:8d} {code:12s} {pairs:16d} {seconds:8.2f} "
            f"{cpu:8.2f} {pairs / seconds / 1e6:7.3f} {os.getloadavg()[0]:6.2f}",
            flush=True,
        )

    print(f"huge pages: {args.huge_pages}")
    if args.process_cpu:
        print("whole processes timed, start-up included; granular from the other's init.sph")
    print(
        f"{'round':>5s} {'workload':14s} {'N':>8s} {'code':12s} {'pair collisions':>16s} "
        f"{'wall s':>8s} {'CPU s':>8s} {'M/s':>7s} {'load':>6s}"
    )
    for round_ in range(args.repeats):
        for name in names:
            # the order alternates from round to round, so a machine whose load drifts
            # during a round favours neither code; granular runs the other's N and pair
            # count (in odd rounds the count of its previous run: granular goes first)
            eta = WORKLOADS[name][1]
            whole = others[name] if args.process_cpu else None
            if round_ % 2 == 0:
                other = run_other(others[name], eta, whole=args.process_cpu)
                mine = run_granular(name, sizes[name], other[0], directory=whole)
                order = (("Smallenburg", other), ("granular", mine))
            else:
                mine = run_granular(name, sizes[name], PAIRS.get(name) or 2_000_000, whole)
                other = run_other(others[name], eta, whole=args.process_cpu)
                order = (("granular", mine), ("Smallenburg", other))
            for code, (pairs, seconds, cpu) in order:
                report(round_, name, code, pairs, seconds, cpu)
            PAIRS[name] = other[0]
            # rates per wall second and per CPU second, granular's over the other's
            ratios[name].append(
                (
                    (mine[0] / mine[1]) / (other[0] / other[1]),
                    (mine[0] / mine[2]) / (other[0] / other[2]),
                )
            )
    print("\nmedian (smallest-largest) over the rounds, M pair collisions/s (wall):")
    for name in names:
        line = []
        for code in ("granular", "Smallenburg"):
            r = sorted(rate for w, c, rate in rows if w == name and c == code)
            line.append(f"{code} {np.median(r) / 1e6:.3f} ({r[0] / 1e6:.3f}-{r[-1] / 1e6:.3f})")
        print(f"{name:14s} " + ", ".join(line))
    print("\ngranular / Smallenburg, round by round: median (smallest-largest)")
    for name in names:
        wall, cpu = np.array(ratios[name]).T
        print(
            f"{name:14s} wall {np.median(wall):.2f} ({wall.min():.2f}-{wall.max():.2f}), "
            f"CPU {np.median(cpu):.2f} ({cpu.min():.2f}-{cpu.max():.2f})"
        )
    if args.plot:
        plot(rows, args.plot)


def plot(rows, path):
    """Pair collisions per second against N, every round a point, a line through the means
    of the dilute workloads; the dense one (packing 0.45) as open markers."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4.0), layout="constrained")
    for code, colour in (("granular", "C0"), ("Smallenburg", "C1")):
        label = "granular" if code == "granular" else "Smallenburg's EDMD"
        for dense in (False, True):
            mine = [
                (WORKLOADS[name][0], rate)
                for name, c, rate in rows
                if c == code and (WORKLOADS[name][1] > 0.1) == dense
            ]
            if not mine:
                continue
            n, rate = np.array(mine).T
            ax.plot(
                n,
                rate / 1e6,
                "s" if dense else "o",
                color=colour,
                mfc="none" if dense else colour,
                label=f"{label}, packing 0.45" if dense else f"{label}, packing 0.065",
            )
            if not dense:
                ns = np.unique(n)
                ax.plot(ns, [rate[n == v].mean() / 1e6 for v in ns], "-", color=colour)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(
        matplotlib.ticker.FuncFormatter(
            lambda v, _: f"{v:g}" if round(v / 10 ** math.floor(math.log10(v))) in (2, 3, 5) else ""
        )
    )
    ax.set_xlabel("particles N (3D, periodic, monodisperse)")
    ax.set_ylabel("pair collisions per second (millions)")
    ax.set_title("one thread, same machine, interleaved runs")
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
