"""Langevin engine benchmarks: particle-steps per second and peak memory, with a plain
vectorised NumPy Euler-Maruyama measured in the same run for the ratio.

Peak memory is tracemalloc's peak over the run: it sees NumPy's arrays and the scratch
the binding allocates through Python's allocator -- not the C core's per-call block sums
and per-thread rings (malloc, a few kB to MB, freed at the end of each call).

Each record has the keys every bench record has (name, engine, dim, n, seconds, and the
EDMD ones -- packing_fraction, boundary, restitution, pair_collisions,
pair_collisions_per_second -- set to None: independent particles in free space have none
of them) plus the Langevin ones: ``threads`` (1, or every core this process may use),
the median rate over the rounds and its range, and the 1-minute load average at the end
(the machine's other work, which a rate on "every core" shares them with)."""

from __future__ import annotations

import functools
import os
import time
import tracemalloc
from typing import Any

import numpy as np

from .. import langevin

G0, D0 = 9.26, 0.072  # the thesis' standard gas
_NOT_EDMD = dict.fromkeys(
    ("packing_fraction", "boundary", "restitution", "pair_collisions", "pair_collisions_per_second")
)


def numpy_em(n, steps, dt, dim=3, seed=0):
    """The thesis' way: all particles advanced together, one NumPy call per operation."""
    rng = np.random.default_rng(seed)
    x = np.zeros((n, dim))
    v = rng.normal(scale=np.sqrt(G0 * D0), size=(n, dim))
    b = np.sqrt(2 * D0) * G0 * np.sqrt(dt)
    for _ in range(steps):
        x += v * dt
        v += -G0 * dt * v + b * rng.standard_normal((n, dim))
    return x


def log_lags(count, t_max, dt):
    """`count` distinct lags (in time), whole steps of dt, log-spaced from dt to t_max:
    log-spaced steps rounded, each raised to at least one step past the one before (where
    rounding would merge them, at the short end; geomspace is convex, so the raised lags
    still end at t_max)."""
    largest = round(t_max / dt)
    if not 1 <= count <= largest:
        raise ValueError(f"{count} distinct lags need 1 <= count <= t_max / dt = {largest}")
    rounded = np.rint(np.geomspace(1, largest, count))
    k = np.arange(count)
    return (np.maximum.accumulate(rounded - k) + k) * dt


def _measure(fn):
    """fn's result, its wall-clock seconds, its peak traced memory in MiB and its CPU
    seconds (every thread of the process: on a loaded machine the wall time grows, the
    CPU time much less)."""
    tracemalloc.start()
    c0 = time.process_time()
    t0 = time.perf_counter()
    result = fn()
    seconds = time.perf_counter() - t0
    cpu = time.process_time() - c0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return result, seconds, peak / 2**20, cpu


def _record(name, r, peak, numpy_rate, threads, rates, cpu_rates, estimator=None):
    """One row: the median rate over the rounds (``rates``, wall clock) and its range, and
    the median rate per CPU-second (``cpu_rates``: all threads' CPU time)."""
    steps = round(r.t_stop / r.dt)
    rate = float(np.median(rates))
    return dict(
        name=name,
        engine="langevin",
        dim=r.dim,
        n=r.n,
        **_NOT_EDMD,
        model=r.model,
        scheme=r.scheme,
        dt=r.dt,
        steps=steps,
        tamsd_lags=len(r.tamsd_lags),
        tamsd_estimator=estimator,
        threads=threads,
        seconds=r.n * steps / rate,
        particle_steps_per_second=rate,
        particle_steps_per_second_range=[min(rates), max(rates)],
        particle_steps_per_cpu_second=float(np.median(cpu_rates)),
        rounds=len(rates),
        peak_memory_mb=peak,
        numpy_particle_steps_per_second=numpy_rate,
        load_average=os.getloadavg()[0],
    )


def _size(n):
    return f"n{n:.0e}".replace("+0", "").replace("+", "")


def _rounds(configs, rounds):
    """Each config's (last result, peak MiB, wall rates, CPU rates over the rounds): the
    configs run in turn, forwards in even rounds and backwards in odd ones, so that a
    machine whose load drifts during the bench favours none of them."""
    got: dict[Any, list[Any]] = {k: [None, 0.0, [], []] for k in configs}
    for i in range(rounds):
        for k in list(configs)[:: 1 if i % 2 == 0 else -1]:
            fn, work = configs[k]
            r, seconds, peak, cpu = _measure(fn)
            got[k][0], got[k][1] = r, max(got[k][1], peak)
            got[k][2].append(work / seconds)
            got[k][3].append(work / max(cpu, 1e-9))
    return got


def workloads(quick=False, rounds=1):
    """The Langevin rows: for each (scheme, N) one row on one thread and one on every
    core (``threads``), with the NumPy Euler-Maruyama at the same N measured in the same
    rounds; then the TAMSD case.  ``rounds`` > 1 interleaves the runs and reports
    medians and ranges."""
    out = []
    cores = langevin._threads(None)
    counts = sorted({1, cores})
    cases = [(1_000, 200_000), (100_000, 2_000)] if not quick else [(1_000, 2_000), (10_000, 200)]
    for n, steps in cases:
        dt = 0.01
        np_steps = max(10, steps // 20)
        configs: dict[str | tuple[str | None, int], tuple[functools.partial[Any], int]] = {
            "numpy": (functools.partial(numpy_em, n, np_steps, dt), n * np_steps)
        }
        for scheme in ("em", "exact"):
            for t in counts:
                configs[scheme, t] = (
                    functools.partial(
                        langevin.run,
                        n,
                        gamma0=G0,
                        D0=D0,
                        dt=dt,
                        t_stop=steps * dt,
                        scheme=scheme,
                        seed=1,
                        threads=t,
                    ),
                    n * steps,
                )
        got = _rounds(configs, rounds)
        numpy_rate = float(np.median(got.pop("numpy")[2]))  # wall clock: one thread
        for (scheme, t), (r, peak, rates, cpu_rates) in got.items():
            out.append(
                _record(
                    f"langevin-3d-{scheme}-{_size(n)}-threads{t}",
                    r,
                    peak,
                    numpy_rate,
                    t,
                    rates,
                    cpu_rates,
                )
            )
    # the memory case: N = 1000, t = 1000, dt = 0.01, MSD and 30 TAMSD lags, each
    # TAMSD estimator beside the same run without lags (the "plain" rate it is a share of)
    n, t_stop = (1_000, 1000.0) if not quick else (200, 20.0)
    lags = log_lags(30, t_stop / 2, 0.01)
    configs = {}
    for estimator in (None, "strided", "all"):
        for t in counts:
            configs[estimator, t] = (
                functools.partial(
                    langevin.run,
                    n,
                    gamma0=G0,
                    D0=D0,
                    tau0=0.972,
                    dt=0.01,
                    t_stop=t_stop,
                    scheme="em",
                    tamsd_lags=None if estimator is None else lags,
                    tamsd_estimator=estimator or "strided",
                    seed=1,
                    threads=t,
                ),
                n * round(t_stop / 0.01),
            )
    for (estimator, t), (r, peak, rates, cpu_rates) in _rounds(configs, rounds).items():
        tag = f"{len(lags)}lags-{estimator}" if estimator else "nolags"
        out.append(
            _record(
                f"udsbm-3d-em-{_size(n)}-t{t_stop:g}-{tag}-threads{t}",
                r,
                peak,
                float("nan"),
                t,
                rates,
                cpu_rates,
                estimator,
            )
        )
    return out
