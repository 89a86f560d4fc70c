"""Langevin engine benchmarks: particle-steps per second and peak memory, with a plain
vectorised NumPy Euler-Maruyama measured in the same run for the ratio.

Peak memory is tracemalloc's peak over the run: it sees NumPy's arrays and the C core's
scratch (allocated through Python's allocator), i.e. everything the run allocates.

Each record has the keys every bench record has (name, engine, dim, n, seconds, and the
EDMD ones -- packing_fraction, boundary, restitution, pair_collisions,
pair_collisions_per_second -- set to None: independent particles in free space have none
of them) plus the Langevin ones."""

from __future__ import annotations

import functools
import time
import tracemalloc

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
    """fn's result, its wall-clock seconds and its peak traced memory in MiB."""
    tracemalloc.start()
    t0 = time.perf_counter()
    result = fn()
    seconds = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return result, seconds, peak / 2**20


def _record(name, r, seconds, peak, numpy_rate):
    steps = round(r.t_stop / r.dt)
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
        seconds=seconds,
        particle_steps_per_second=r.n * steps / seconds,
        peak_memory_mb=peak,
        numpy_particle_steps_per_second=numpy_rate,
    )


def _size(n):
    return f"n{n:.0e}".replace("+0", "").replace("+", "")


def workloads(quick=False):
    out = []
    cases = [(1_000, 200_000), (100_000, 2_000)] if not quick else [(1_000, 2_000), (10_000, 200)]
    for n, steps in cases:
        dt = 0.01
        np_steps = max(10, steps // 20)
        _, np_seconds, _ = _measure(functools.partial(numpy_em, n, np_steps, dt))
        for scheme in ("em", "exact"):
            r, seconds, peak = _measure(
                functools.partial(
                    langevin.run,
                    n,
                    gamma0=G0,
                    D0=D0,
                    dt=dt,
                    t_stop=steps * dt,
                    scheme=scheme,
                    seed=1,
                )
            )
            out.append(
                _record(
                    f"langevin-3d-{scheme}-{_size(n)}", r, seconds, peak, n * np_steps / np_seconds
                )
            )
    # the memory case: N = 1000, t = 1000, dt = 0.01, MSD and 30 TAMSD lags
    n, t_stop = (1_000, 1000.0) if not quick else (200, 20.0)
    lags = log_lags(30, t_stop / 2, 0.01)
    r, seconds, peak = _measure(
        lambda: langevin.run(
            n,
            gamma0=G0,
            D0=D0,
            tau0=0.972,
            dt=0.01,
            t_stop=t_stop,
            scheme="em",
            tamsd_lags=lags,
            seed=1,
        )
    )
    out.append(
        _record(
            f"udsbm-3d-em-{_size(n)}-t{t_stop:g}-{len(r.tamsd_lags)}lags",
            r,
            seconds,
            peak,
            float("nan"),
        )
    )
    return out
