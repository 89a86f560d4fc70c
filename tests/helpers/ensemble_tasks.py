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


def y_missing_from_run_1(seed):
    """Run r returns x = r and, except run 1, y = r: the mean of y is over 3 runs of 4."""
    index = seed.spawn_key[-1]
    out = {"x": np.float64(index)}
    if index != 1:
        out["y"] = np.float64(index)
    return out


def z_shorter_in_run_1(seed):
    """z has 3 entries, but 2 in run 1 (as a run stopped early would sample)."""
    index = seed.spawn_key[-1]
    return {"x": np.float64(index), "z": np.zeros(2 if index == 1 else 3)}


def always_collapses(seed):
    raise granular.InelasticCollapseError(
        f"collapse in run {seed.spawn_key[-1]}", particles=(1, 2), time=0.5
    )


def scene_without_run_options(seed):
    """A model returning a Scene: with no t_stop given, every EDMD run refuses to start."""
    return granular.Scene.random(20, 0.02, dim=2, seed=seed)


def slow_draws(seed, delay=0.02):
    """Arrays drawn from the run's seed, after a pause that varies from run to run (so
    that a process killed at a random moment is caught in a run, between runs or mid-write)."""
    import time

    rng = np.random.default_rng(seed)
    time.sleep(delay * rng.random())
    return {"times": np.arange(4.0), "msd": rng.random(4), "energy": np.float64(rng.random())}
