"""Picklable functions for the ensemble tests (workers import them by module name)."""

import threading
import weakref

import numpy as np

import granular


def gaussian(seed):
    """50 independent standard normal numbers: the ensemble error of each is 1/sqrt(K)."""
    return {"x": np.random.default_rng(seed).normal(size=50)}


def fails_for_run_2(seed):
    if seed.spawn_key[-1] == 2:
        raise granular.InelasticCollapseError("collapse in run 2", particles=(1, 2), time=0.5)
    return {"x": np.random.default_rng(seed).normal(size=3)}


def small_gas(seed):
    return granular.Scene.random(200, 0.03, restitution=0.8, seed=seed)


# How many results of `tracked_result` are alive in this process, and the most seen at once:
# with the threads backend this shows how many finished runs the ensemble keeps around.
live_results = 0
peak_live_results = 0
_lock = threading.RLock()  # re-entrant: a result may be freed while this thread holds it


def reset_tracking():
    global peak_live_results
    with _lock:
        peak_live_results = 0


def _freed():
    global live_results
    with _lock:
        live_results -= 1


def tracked_result(seed):
    global live_results, peak_live_results
    x = np.random.default_rng(seed).normal(size=10_000)
    weakref.finalize(x, _freed)
    with _lock:
        live_results += 1
        peak_live_results = max(peak_live_results, live_results)
    return {"x": x}
