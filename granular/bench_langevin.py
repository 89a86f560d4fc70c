"""Langevin engine benchmarks: particle-steps per second and peak memory, with a plain
vectorised NumPy Euler-Maruyama measured in the same run for the ratio.

Peak memory is tracemalloc's peak over the run: it sees NumPy's arrays and the C core's
scratch (allocated through Python's allocator), i.e. everything the run allocates."""
from __future__ import annotations

import time
import tracemalloc

import numpy as np

from . import langevin

G0, D0 = 9.26, 0.072  # the thesis' standard gas


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


def _measure(fn):
    tracemalloc.start()
    t0 = time.perf_counter()
    fn()
    seconds = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return seconds, peak / 2**20


def workloads(quick=False):
    out = []
    cases = [(1_000, 200_000), (100_000, 2_000)] if not quick else [(1_000, 2_000), (10_000, 200)]
    for n, steps in cases:
        dt = 0.01
        np_steps = max(10, steps // 20)
        np_seconds, _ = _measure(lambda: numpy_em(n, np_steps, dt))
        for scheme in ("em", "exact"):
            seconds, peak = _measure(lambda: langevin.run(n, gamma0=G0, D0=D0, dt=dt, t_stop=steps * dt,
                                                          scheme=scheme, seed=1))
            out.append(dict(name=f"langevin-3d-{scheme}-n{n:.0e}".replace("+0", ""), engine="langevin",
                            dim=3, n=n, scheme=scheme, dt=dt, steps=steps, seconds=seconds,
                            particle_steps_per_second=n * steps / seconds, peak_memory_mb=peak,
                            numpy_particle_steps_per_second=n * np_steps / np_seconds))
    # the memory case: N = 1000, t = 1000, dt = 0.01, MSD and 30 TAMSD lags
    n, t_stop = (1_000, 1000.0) if not quick else (200, 20.0)
    lags = np.unique(np.round(np.logspace(-2, np.log10(t_stop / 2), 30), 2))
    seconds, peak = _measure(lambda: langevin.run(n, gamma0=G0, D0=D0, tau0=0.972, dt=0.01, t_stop=t_stop,
                                                  scheme="em", tamsd_lags=lags, seed=1))
    steps = int(round(t_stop / 0.01))
    out.append(dict(name="udsbm-3d-em-n1e3-t1000-30lags", engine="langevin", dim=3, n=n, scheme="em",
                    dt=0.01, steps=steps, seconds=seconds, particle_steps_per_second=n * steps / seconds,
                    peak_memory_mb=peak, numpy_particle_steps_per_second=float("nan")))
    return out
