"""Ensembles: K independent realizations of a run, on all local cores by default, on a
Dask cluster when one machine is outgrown, with the mean and central-limit error of
every quantity (thesis 2.120-2.122).

Every run r gets its own random stream ``SeedSequence(seed).spawn(K)[r]``, so the same
seed gives the same results whichever backend and however many workers ran them.
"""
from __future__ import annotations

import os
import sys
import traceback

import numpy as np

from .scene import Scene
from .simulation import Simulation

EDMD_QUANTITIES = ("msd", "msd_per_dimension", "temperature", "kinetic_energy",
                   "collisions_per_particle", "pair_collisions", "pressure", "positions",
                   "velocities")


class RunFailure:
    """A run that raised: its index, its seed (``SeedSequence`` entropy and spawn key,
    enough to rerun it alone) and the error."""

    def __init__(self, index, seed, error, traceback_text):
        self.index = index
        self.seed = seed
        self.error = error
        self.traceback = traceback_text

    def __repr__(self):
        return f"RunFailure(run {self.index}, seed={self.seed}, error={self.error!r})"


class EnsembleResult:
    """Per-run results and their ensemble statistics.

    Attributes
    ----------
    runs : list of dict
        One dict of arrays per successful run, in run order (empty if ``keep_runs=False``).
    mean, error : dict
        Per quantity: the mean over successful runs and its standard error
        ``std(ddof=1) / sqrt(K)`` (central limit theorem, thesis 2.120-2.122); NaN error
        for K = 1.
    count : int
        Number of successful runs.
    failures : list of RunFailure
    times : ndarray or None
        The sample times, when the runs share them.
    """

    def __init__(self, runs, mean, error, count, failures, times):
        self.runs = runs
        self.mean = mean
        self.error = error
        self.count = count
        self.failures = failures
        self.times = times

    def __repr__(self):
        q = ", ".join(sorted(self.mean))
        return f"EnsembleResult({self.count} runs, {len(self.failures)} failed; {q})"


class _Accumulator:
    """Running mean and variance per quantity (Welford), so runs can be reduced as they
    arrive without keeping them."""

    def __init__(self):
        self.count = 0
        self.mean = {}
        self.m2 = {}
        self.ragged = set()

    def add(self, result):
        self.count += 1
        for k, v in result.items():
            v = np.asarray(v, dtype=np.float64)
            if k in self.ragged:
                continue
            if k not in self.mean:
                self.mean[k] = v.copy()
                self.m2[k] = np.zeros_like(v)
                continue
            if self.mean[k].shape != v.shape:  # runs that stopped at different samples
                self.ragged.add(k)
                del self.mean[k], self.m2[k]
                continue
            with np.errstate(invalid="ignore"):  # inf parameters (tau0 = inf) stay inf
                delta = v - self.mean[k]
                self.mean[k] += delta / self.count
                self.m2[k] += delta * (v - self.mean[k])

    def result(self):
        error = {}
        for k, m2 in self.m2.items():
            error[k] = (np.sqrt(m2 / (self.count - 1) / self.count) if self.count > 1
                        else np.full_like(m2, np.nan))
        return self.mean, error


def _shuffle_velocities(scene, rng):
    """The thesis' way (3.8) to make independent runs from one equilibrated scene: give the
    velocity vectors to the particles in a random order."""
    if not np.all(scene.masses == scene.masses[0]):
        raise ValueError("shuffling velocities among particles of different masses would "
                         "change the energy; pass a function seed -> Scene instead")
    return scene.replace(velocities=scene.velocities[rng.permutation(scene.n)])


def _edmd_quantities(scene, run_kwargs, quantities):
    """Run EDMD on one scene and collect the requested quantities."""
    store = tuple(s for s in ("positions", "velocities")
                  if s in quantities or (s == "positions" and any(q.startswith("msd") for q in quantities)))
    traj = Simulation(scene).run(store=store, **run_kwargs)
    out = {"times": traj.times}
    for q in quantities:
        if q == "msd":
            out[q] = traj.msd()
        elif q == "msd_per_dimension":
            out[q] = traj.msd(per_dimension=True)
        elif q == "pressure":
            out[q] = np.float64(traj.pressure())
        else:
            out[q] = getattr(traj, q)
    return out


def _arrays_of(result):
    """The NumPy arrays and numbers among a result's attributes (or dict entries)."""
    items = result.items() if isinstance(result, dict) else vars(result).items()
    return {k: np.asarray(v) for k, v in items
            if isinstance(v, (np.ndarray, float, np.floating, np.integer))}


class _Task:
    """One realization for a seed: a Scene (velocities shuffled), or whatever the model
    function returns for the seed -- a Scene is then run by EDMD, anything else is
    collected as it is (e.g. a Langevin result)."""

    def __init__(self, model, run_kwargs, quantities):
        self.model, self.run_kwargs, self.quantities = model, run_kwargs, quantities

    def __call__(self, seed):
        if isinstance(self.model, Scene):
            made = _shuffle_velocities(self.model, np.random.default_rng(seed))
        else:
            made = self.model(seed=seed)
        if isinstance(made, Scene):
            return _edmd_quantities(made, self.run_kwargs, self.quantities)
        if self.run_kwargs:
            raise TypeError(f"run options {sorted(self.run_kwargs)} apply to EDMD scenes only; "
                            "put the model's own options into the function (functools.partial)")
        return _arrays_of(made)


def _call_task(task, index, seed):
    """Run one realization in a worker; return ('ok', result) or ('error', failure info)
    so that one failing run never loses the others."""
    try:
        return index, "ok", task(seed)
    except Exception as exc:  # reported with its seed, the other runs go on
        return index, "error", (repr(exc), exc.__class__.__name__, traceback.format_exc())


def _auto_progress():
    return sys.stderr.isatty() or "ipykernel" in sys.modules


def _executor(backend, workers):
    import concurrent.futures as cf
    import multiprocessing as mp

    if backend == "threads":
        return cf.ThreadPoolExecutor(max_workers=workers)
    ctx = mp.get_context("forkserver" if sys.platform.startswith("linux") else "spawn")
    return cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx)


def _results(task, seeds, backend, workers):
    """Yield (index, status, payload) as runs finish, from the chosen backend."""
    if backend == "serial":
        for i, s in enumerate(seeds):
            yield _call_task(task, i, s)
        return
    if hasattr(backend, "submit") and hasattr(backend, "gather"):  # a dask.distributed Client
        from distributed import as_completed

        futures = [backend.submit(_call_task, task, i, s, pure=False) for i, s in enumerate(seeds)]
        for fut in as_completed(futures):
            yield fut.result()
            fut.release()
        return
    if backend not in ("processes", "threads"):
        raise ValueError(f"backend must be 'serial', 'processes', 'threads' or a dask Client, got {backend!r}")
    import concurrent.futures as cf

    with _executor(backend, workers) as pool:
        futures = [pool.submit(_call_task, task, i, s) for i, s in enumerate(seeds)]
        for fut in cf.as_completed(futures):
            yield fut.result()


def ensemble(model, runs, *, seed=None, backend="processes", workers=None, progress=None,
             keep_runs=True, quantities=("msd", "temperature"), **run_kwargs):
    """Run ``runs`` independent realizations and return their results with ensemble means
    and standard errors.

    Parameters
    ----------
    model : Scene, or a function of ``seed``
        - a ``Scene``: each run shuffles its velocity vectors among the particles (the
          thesis' method, section 3.8) and runs EDMD with ``run_kwargs`` (``t_stop``,
          ``sample_times``, ``stop_when`` as in ``Simulation.run``);
        - a function ``f(seed=SeedSequence)`` returning a ``Scene`` (e.g.
          ``functools.partial(Scene.random, 1000, 0.025, restitution=0.8)``): a new scene
          per run, then EDMD as above;
        - a function ``f(seed=SeedSequence)`` returning anything else (e.g.
          ``functools.partial(granular.langevin.run, ...)``): its NumPy arrays and numbers
          are the quantities (``run_kwargs`` must then be empty).
        Functions must be picklable (module level, or partials of such) for the process
        and Dask backends.
    runs : int
    seed : int, SeedSequence or None
        Run r uses ``SeedSequence(seed).spawn(runs)[r]``.
    backend : "processes" (default: all local cores), "serial", "threads", or a
        ``dask.distributed.Client`` (a real cluster, or a ``LocalCluster``)
    workers : int, optional
        Local worker count (default: all cores).
    progress : bool, optional
        tqdm bar over runs; by default on in a terminal or a notebook, off otherwise.
    keep_runs : bool
        Keep every run's arrays (default), or only reduce them to means as they arrive.
    quantities : for EDMD, which of ``EDMD_QUANTITIES`` to collect.

    Failed runs (e.g. inelastic collapse) are listed in ``.failures`` with their seeds and
    do not lose the others.
    """
    runs = int(runs)
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    seeds = root.spawn(runs)
    if not (isinstance(model, Scene) or callable(model)):
        raise TypeError(f"model must be a Scene or a function of seed, got {type(model).__name__}")
    bad = set(quantities) - set(EDMD_QUANTITIES)
    if bad:
        raise ValueError(f"unknown quantities {sorted(bad)}; choose from {EDMD_QUANTITIES}")
    task = _Task(model, run_kwargs, tuple(quantities))
    if workers is None:
        workers = os.cpu_count() or 1

    acc = _Accumulator()
    kept = {} if keep_runs else None
    failures = []
    bar = None
    if progress if progress is not None else _auto_progress():
        from tqdm.auto import tqdm

        bar = tqdm(total=runs, unit="run")
    try:
        pending = {}
        next_index = 0
        # reduce in run order, whatever order runs finish in, so that means are
        # bit-identical across backends
        for index, status, payload in _results(task, seeds, backend, workers):
            pending[index] = (status, payload)
            while next_index in pending:
                st, pl = pending.pop(next_index)
                if st == "ok":
                    acc.add(pl)
                    if kept is not None:
                        kept[next_index] = pl
                else:
                    s = seeds[next_index]
                    failures.append(RunFailure(next_index, {"entropy": s.entropy, "spawn_key": s.spawn_key},
                                               pl[0], pl[2]))
                next_index += 1
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    mean, error = acc.result()
    times = mean.pop("times", None)
    error.pop("times", None)
    runs_list = [kept[i] for i in sorted(kept)] if kept is not None else []
    return EnsembleResult(runs_list, mean, error, acc.count, failures, times)
