"""Picklable functions for the ensemble tests (workers import them by module name)."""
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
