"""Ensembles: K independent realizations of a run, on all local cores by default, on a
Dask cluster when one machine is outgrown, with the mean and central-limit error of
every quantity (thesis 2.120-2.122).

Every run r gets its own random stream ``SeedSequence(seed).spawn(K)[r]`` (run r of point p
of a sweep over P models: ``SeedSequence(seed).spawn(P)[p].spawn(K)[r]``), and runs are
reduced in run order, so the same seed gives bit-identical results whichever backend and
however many workers ran them.
"""

from __future__ import annotations

import ast
import contextlib
import dataclasses
import math
import os
import pickle
import sys
import threading
import traceback
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from types import FrameType
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._results import _lag_indices, ergodicity_breaking, readonly
from .errors import ProcessBackendError
from .scene import Scene
from .simulation import _STOP_KEYS, Simulation

EDMD_QUANTITIES = (
    "msd",
    "msd_per_dimension",
    "temperature",
    "kinetic_energy",
    "collisions_per_particle",
    "pair_collisions",
    "pressure",
    "positions",
    "velocities",
)
# the options an EDMD run takes from ensemble's keywords (Simulation.run's; ensemble sets
# store= from quantities= and shows its own progress)
RUN_OPTIONS = ("t_stop", "sample_times", "stop_when")


@dataclass(frozen=True)
class RunFailure:
    """A run that raised.

    Attributes
    ----------
    index : int
        The run's index in its point (``SeedSequence(seed).spawn(runs)[index]``).
    seed : dict
        ``{"entropy": ..., "spawn_key": ...}`` of the run's ``SeedSequence``, enough to
        rerun it alone: ``np.random.SeedSequence(**failure.seed)``.
    error : str
        ``repr`` of the exception.
    traceback : str
        The formatted traceback, from the worker that ran it.
    error_type : str
        The exception's class name (e.g. ``"InelasticCollapseError"``).
    """

    index: int
    seed: dict[str, Any]
    error: str
    traceback: str
    error_type: str = ""

    def __repr__(self) -> str:
        return f"RunFailure(run {self.index}, seed={self.seed}, error={self.error!r})"


_GUARD_ADVICE = (
    "Worker processes start by importing the main script, so its top-level code, this "
    "ensemble call included, runs again in each of them. Put the script's work under a "
    "main guard (the functions the runs call stay at top level, where workers find them):\n\n"
    '    if __name__ == "__main__":\n'
    "        result = granular.ensemble(...)\n\n"
    'or pass backend="serial" or backend="threads".'
)


@dataclass(frozen=True, eq=False, repr=False)
class EnsembleResult:
    """Per-run results and their ensemble statistics: read-only (a frozen dataclass whose
    arrays are read-only views), as every result is (see docs/analysis.md, "Results").

    The quantities every result offers under the same names and units, as a
    ``Trajectory`` and a ``LangevinResult`` do, here the ensemble means: ``times``,
    ``temperature`` (an energy, k_B = 1), ``msd(per_dimension=False, particles=None)``,
    ``tamsd(lags=None, *, lag_samples=None, particles=None, per_particle=False)``,
    ``tamsd_lags`` and ``ergodicity_breaking(lags=None, *, lag_samples=None,
    particles=None)``.  Their standard errors are in ``error`` (``error["msd"]``,
    ``error["temperature"]``, ``error["tamsd"]``, ...).

    Attributes
    ----------
    runs : list of dict
        One dict of arrays per successful run, in run order (empty if ``keep_runs=False``).
    mean, error : dict
        Per quantity: the mean over the K successful runs that returned it and its
        standard error ``std(ddof=1) / sqrt(K)`` (central limit theorem, thesis
        2.120-2.122); NaN error for K = 1.  An entry equal in every run (inf included,
        e.g. a Langevin run's ``tau0``) keeps that value, with error 0.
    count : int
        Number of successful runs.
    failures : list of RunFailure
    times : ndarray or None
        The sample times, when the runs share them.
    counts : dict
        Per quantity of ``mean``: how many runs it is the mean of (``count`` unless some
        runs did not return it).
    left_out : dict
        Quantities the runs returned that have no mean, each with the reason: their
        shape differs between runs (e.g. runs stopped by ``stop_when`` at different
        samples) or they are not numbers.  ``ensemble`` warns about them; each run's
        values stay in ``runs``.
    temperature : (T,) ndarray
        The mean temperature, an energy (EDMD runs collect ``"temperature"``; Langevin
        runs always give it).
    tamsd_lags : (L,) ndarray
        The lags of ``tamsd()`` by default.
    """

    runs: list[dict[str, NDArray[Any]]]
    mean: dict[str, NDArray[np.float64]]
    error: dict[str, NDArray[np.float64]]
    count: int
    failures: list[RunFailure]
    times: NDArray[np.float64] | None
    counts: dict[str, int] = field(default_factory=dict)
    left_out: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # read-only views: a caller writing into an array the result hands out gets a
        # ValueError instead of changing the means (or a run) unseen
        object.__setattr__(self, "times", readonly(self.times))
        for values in (self.mean, self.error, *self.runs):
            for k, v in values.items():
                values[k] = readonly(v)

    def _quantity(self, name: str, hint: str) -> NDArray[np.float64]:
        if name in self.mean:
            return self.mean[name]
        if name in self.left_out:
            raise ValueError(
                f"this ensemble has no mean {name!r}: {self.left_out[name]} "
                f"(each run's is in runs[r][{name!r}])"
            )
        if self.count == 0 and self.failures:
            raise ValueError(
                f"this ensemble collected no {name!r}: all {len(self.failures)} runs failed "
                f"(see .failures; the first: {self.failures[0].error})"
            )
        raise ValueError(
            f"this ensemble collected no {name!r} ({hint}); it has {sorted(self.mean)}"
        )

    def _runs_with(self, name: str, why: str, hint: str) -> list[dict[str, NDArray[Any]]]:
        """The runs, each of which must hold ``name``: what a choice of particles (or a
        TAMSD of EDMD runs) is computed from."""
        if not self.runs:
            raise ValueError(
                f"{why} needs each run's {name}, and this ensemble kept no runs "
                "(ensemble(..., keep_runs=True), the default, keeps them)"
            )
        missing = [r for r, run in enumerate(self.runs) if name not in run]
        if missing:
            raise ValueError(
                f"{why} needs each run's {name!r}, which run {missing[0]} does not hold ({hint})"
            )
        return self.runs

    @property
    def temperature(self) -> NDArray[np.float64]:
        """(T,) the mean temperature of the runs at the sample times, an energy (k_B = 1)
        as on every result; its standard error is ``error["temperature"]``."""
        return self._quantity(
            "temperature", 'ensemble(quantities=(..., "temperature")) for EDMD runs'
        )

    def msd(
        self, per_dimension: bool = False, particles: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """The ensemble mean of the runs' MSDs at the sample times: (T,) summed over
        dimensions, or (T, d) with ``per_dimension=True`` (for EDMD, collect
        ``"msd_per_dimension"`` among ``quantities``).  Its standard error is
        ``error["msd"]`` (``error["msd_per_dimension"]``).  The same call as
        ``Trajectory.msd`` and ``LangevinResult.msd``.

        Parameters
        ----------
        per_dimension : bool
            Return (T, d), one column per axis, instead of the sum over axes.
        particles : array_like of int or bool, optional
            The mean over the runs of the MSD of these particles only (indices, or a
            boolean mask over each run's N), e.g. a tracer: computed from each run's
            positions, which the runs must keep (EDMD: ``quantities=(..., "positions")``;
            Langevin: ``store_positions=True``), as ``msd(particles=...)`` of each run
            would.  No standard error is kept for it.
        """
        if particles is not None:
            from .analysis import _select

            runs = self._runs_with(
                "positions",
                "msd(particles=...)",
                'EDMD: quantities=(..., "positions"); Langevin: store_positions=True',
            )
            out = []
            for run in runs:
                x = _select(np.asarray(run["positions"]), particles)
                # a Langevin run (the one with "v2") starts every particle at the origin at
                # t = 0, which need not be a sample; an EDMD run's MSD is from its first sample
                d = x if "v2" in run else x - x[0]
                out.append(np.einsum("tna,tna->ta", d, d) / x.shape[1])
            per = np.mean(out, axis=0)
            return per if per_dimension else per.sum(axis=1)
        if per_dimension:
            return self._quantity(
                "msd_per_dimension", 'ensemble(quantities=(..., "msd_per_dimension"))'
            )
        return self._quantity("msd", 'ensemble(quantities=(..., "msd"))')

    @property
    def tamsd_lags(self) -> NDArray[np.float64]:
        """(L,) the lags ``tamsd()`` takes by default: those the runs accumulated (Langevin
        runs with ``tamsd_lags``), or for EDMD runs that kept their positions every sample
        time after the first, less the first (as ``Trajectory.tamsd_lags``)."""
        if "tamsd_lags" in self.mean or "tamsd_lags" in self.left_out:
            return self._quantity("tamsd_lags", "")
        if self.times is not None and self.runs and "positions" in self.runs[0]:
            return readonly(self.times[1:] - self.times[0])
        return self._quantity(
            "tamsd_lags",
            "a TAMSD comes from Langevin runs with tamsd_lags, or EDMD runs with "
            'quantities=(..., "positions")',
        )

    def _tamsd_rows(
        self, lags: ArrayLike | None, lag_samples: ArrayLike | None, particles: ArrayLike | None
    ) -> list[NDArray[np.float64]]:
        """Each run's (N, L) TAMSD of the chosen particles: the rows a Langevin run kept,
        or ``analysis.tamsd`` of an EDMD run's positions."""
        from . import analysis

        if "tamsd_lags" in self.mean or (self.runs and "tamsd_per_particle" in self.runs[0]):
            runs = self._runs_with(
                "tamsd_per_particle",
                "tamsd(particles=...) or tamsd(per_particle=True)",
                "the rows of a Langevin run with tamsd_lags",
            )
            rows = []
            for run in runs:
                pick = _lag_indices(run["tamsd_lags"], float(run["dt"]), lags, lag_samples)
                per = np.asarray(run["tamsd_per_particle"])[:, pick]
                rows.append(per if particles is None else analysis._select(per[None], particles)[0])
            return rows
        runs = self._runs_with(
            "positions",
            "a TAMSD of EDMD runs",
            'collect quantities=(..., "positions"); Langevin runs need tamsd_lags',
        )
        if lags is not None and lag_samples is not None:
            raise TypeError("give at most one of lags (in time) and lag_samples (in samples)")
        if lags is None and lag_samples is None:
            lags = self.tamsd_lags
        return [
            analysis.tamsd(
                run["positions"],
                lags,
                times=run["times"],
                lag_samples=lag_samples,
                particles=particles,
                per_particle=True,
            )
            for run in runs
        ]

    def tamsd(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
        per_particle: bool = False,
    ) -> NDArray[np.float64]:
        """The ensemble mean of the runs' time-averaged MSDs, (L,); the same call,
        defaults and errors as ``Trajectory.tamsd`` and ``LangevinResult.tamsd``: by
        default at every lag the runs have (``tamsd_lags``), or at those of them chosen by
        ``lags`` (in time) or ``lag_samples`` (in steps or samples).  Its standard error
        is ``error["tamsd"]`` (Langevin runs).

        Langevin runs give the TAMSD they accumulated; EDMD runs give it from their
        positions (``quantities=(..., "positions")``, ``analysis.tamsd`` of each run).

        Parameters
        ----------
        lags, lag_samples : array_like, optional
            The lags to return, in time or in steps (samples for EDMD), at most one.
        particles : array_like of int or bool, optional
            The mean over the runs of these particles' TAMSD only (indices, or a boolean
            mask over each run's N): from each run's kept rows, which needs the runs
            (``keep_runs=True``, the default).
        per_particle : bool
            Return (K N, L): one row per chosen particle of every run, the runs in order
            (each Langevin run's ``tamsd_per_particle``), instead of the mean.
        """
        if particles is None and not per_particle and "tamsd" in self.mean:
            dt = float(self._quantity("dt", "the runs' step"))
            return self.mean["tamsd"][_lag_indices(self.tamsd_lags, dt, lags, lag_samples)]
        rows = self._tamsd_rows(lags, lag_samples, particles)
        if per_particle:
            return np.concatenate(rows)
        return np.mean([r.mean(axis=0) for r in rows], axis=0)

    def ergodicity_breaking(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """The measured ergodicity-breaking parameter at the lags of ``tamsd()`` (by
        default ``tamsd_lags``), over the particles of every run together:
        ``analysis.ergodicity_breaking`` of ``tamsd(..., per_particle=True)``.  The same
        call as on the other results.

        Parameters
        ----------
        lags, lag_samples, particles : as in ``tamsd``.
        """
        return ergodicity_breaking(self, lags, lag_samples, particles)

    def __repr__(self) -> str:
        q = ", ".join(
            k if self.counts.get(k, self.count) == self.count else f"{k} ({self.counts[k]} runs)"
            for k in sorted(self.mean)
        )
        return f"EnsembleResult({self.count} runs, {len(self.failures)} failed; {q})"


def _difference(v, mean):
    """``v - mean``, but 0 where they are equal: an entry that is the same in every run,
    inf included (tau0 = inf of a Langevin run), keeps its value and gets error 0, where
    inf - inf would make both NaN."""
    return np.where(v == mean, 0.0, v - mean)


class _Accumulator:
    """Running mean and variance per quantity (Welford), so runs can be reduced as they
    arrive without keeping them.  Each quantity is the mean of the runs that returned it
    (``counts``); one whose shape differs between runs, or that is not numbers, has no
    mean and is named in ``left_out`` with the reason."""

    def __init__(self):
        self.count = 0
        self.counts = {}
        self.mean = {}
        self.m2 = {}
        self.first = {}  # quantity -> (run, shape) of the first run that returned it
        self.left_out = {}

    def _leave_out(self, k, reason):
        self.left_out[k] = reason
        for d in (self.mean, self.m2, self.counts):
            d.pop(k, None)

    def add(self, result, run=None):
        """Add one run's quantities; ``run`` (its index) names it in ``left_out``."""
        self.count += 1
        run = self.count - 1 if run is None else run
        for k, v in result.items():
            if k in self.left_out:
                continue
            try:
                v = np.asarray(v, dtype=np.float64)
            except (TypeError, ValueError) as exc:
                self._leave_out(k, f"run {run}'s is not numbers ({exc})")
                continue
            if k not in self.mean:
                self.first[k] = (run, v.shape)
                self.counts[k] = 1
                self.mean[k] = v.copy()
                self.m2[k] = np.zeros_like(v)
                continue
            if self.mean[k].shape != v.shape:
                first_run, first_shape = self.first[k]
                self._leave_out(
                    k,
                    f"its shape differs between runs ({first_shape} in run {first_run}, "
                    f"{v.shape} in run {run})",
                )
                continue
            self.counts[k] += 1
            # runs with inf in some entries and finite numbers in others: mean inf, error NaN
            with np.errstate(invalid="ignore"):
                delta = _difference(v, self.mean[k])
                self.mean[k] += delta / self.counts[k]
                self.m2[k] += delta * _difference(v, self.mean[k])

    def result(self):
        error = {}
        for k, m2 in self.m2.items():
            n = self.counts[k]
            error[k] = np.sqrt(m2 / (n - 1) / n) if n > 1 else np.full_like(m2, np.nan)
        return self.mean, error


def _shuffle_velocities(scene, rng):
    """The thesis' way (3.8) to make independent runs from one equilibrated scene: give the
    velocity vectors to the particles in a random order (and a random driving a seed of
    the run's own)."""
    if not np.all(scene.masses == scene.masses[0]):
        raise ValueError(
            "shuffling velocities among particles of different masses would "
            "change the energy; pass a function seed -> Scene instead"
        )
    shuffled = scene.replace(velocities=scene.velocities[rng.permutation(scene.n)])
    if scene.driving is None:
        return shuffled
    # a random driving's kicks are its seed's: each run draws its own, or every run would
    # be kicked at the same times with the same numbers
    seed = int(rng.integers(0, 2**53))
    return shuffled.replace(driving=dataclasses.replace(scene.driving, seed=seed))


def _edmd_quantities(scene, run_kwargs, quantities):
    """Run EDMD on one scene and collect the requested quantities."""
    store = tuple(
        s
        for s in ("positions", "velocities")
        if s in quantities or (s == "positions" and any(q.startswith("msd") for q in quantities))
    )
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
    """The NumPy arrays and numbers of a result: its own ``arrays()`` (a
    ``LangevinResult``), else those among its attributes (or dict entries)."""
    if callable(getattr(result, "arrays", None)):
        return dict(result.arrays())
    items = result.items() if isinstance(result, dict) else vars(result).items()
    return {
        k: np.asarray(v)
        for k, v in items
        if isinstance(v, (np.ndarray, float, np.floating, np.integer))
    }


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
            raise TypeError(
                f"run options {sorted(self.run_kwargs)} apply to EDMD scenes only; "
                "put the model's own options into the function (functools.partial)"
            )
        return _arrays_of(made)


def _call_task(task, index, seed):
    """Run one realization in a worker; return ('ok', result) or ('error', failure info)
    so that one failing run never loses the others.  The failure info ends with the
    exception itself, without its traceback (which is formatted beside it), when it
    pickles: if every run fails alike, ``ensemble`` raises it."""
    try:
        return index, "ok", task(seed)
    # any error of the task (user code) is caught: reported with its seed, the other runs go on
    except Exception as exc:  # noqa: BLE001
        info = (repr(exc), exc.__class__.__name__, traceback.format_exc())
        exc.__traceback__ = None  # its frames may hold the failed run's arrays
        sent: Exception | None = exc
        try:  # the round trip: an exception may pickle and not unpickle (required args)
            pickle.loads(pickle.dumps(exc))
        except Exception:  # noqa: BLE001 (an exception that does not pickle stays behind)
            sent = None
        return index, "error", (*info, sent)


def _progress_bar(total, progress):
    """A tqdm bar over runs; by default shown in a terminal or a notebook only."""
    from tqdm.auto import tqdm

    if progress is None:
        progress = sys.stderr.isatty() or "ipykernel" in sys.modules
    return tqdm(total=total, unit="run", disable=not progress)


def _process_context():
    """The multiprocessing context of the process backend (forkserver on Linux, else spawn:
    either way, workers re-import the main script)."""
    import multiprocessing as mp

    return mp.get_context("forkserver" if sys.platform.startswith("linux") else "spawn")


def _exit_with_parent(lifeline):
    """In a worker process: exit as soon as the ensemble's process dies.

    ``lifeline`` is the read end of a pipe whose only write end the parent holds (forkserver
    and spawn workers inherit no other descriptors), so reading it waits until the parent
    closes it -- after its pool has shut down -- or dies, killed or not.  A worker that
    outlives its parent would otherwise wait for tasks forever, and keep the forkserver
    alive with it.  A daemon thread: it blocks without the GIL and ends with the worker."""

    def watch():
        try:
            lifeline.recv_bytes()
        except (EOFError, OSError):
            pass
        os._exit(1)

    threading.Thread(target=watch, name="granular-exit-with-parent", daemon=True).start()


@contextlib.contextmanager
def _executor(backend, workers):
    import concurrent.futures as cf

    if backend == "threads":
        with cf.ThreadPoolExecutor(max_workers=workers) as pool:
            yield pool
        return
    context = _process_context()
    lifeline, keep = context.Pipe(duplex=False)
    try:
        with cf.ProcessPoolExecutor(
            max_workers=workers,
            mp_context=context,
            initializer=_exit_with_parent,
            initargs=(lifeline,),
        ) as pool:
            yield pool
    finally:  # the workers have exited (shutdown waits for them): let go of the pipe
        keep.close()
        lifeline.close()


def _main_guard_lines(tree):
    """Line ranges of the blocks that run only when a script is run, not imported:
    ``if __name__ == "__main__":`` (either operand order) and the ``else`` of ``!=``."""

    def is_name(node):
        return isinstance(node, ast.Name) and node.id == "__name__"

    def is_main(node):
        return isinstance(node, ast.Constant) and node.value == "__main__"

    for node in ast.walk(tree):
        if not isinstance(node, ast.If):
            continue
        test = node.test
        if not (isinstance(test, ast.Compare) and len(test.ops) == 1):
            continue
        left, right = test.left, test.comparators[0]
        if not ((is_name(left) and is_main(right)) or (is_main(left) and is_name(right))):
            continue
        block = {ast.Eq: node.body, ast.NotEq: node.orelse}.get(type(test.ops[0]))
        if block:
            yield block[0].lineno, block[-1].end_lineno


def _unguarded_main_call(start_method):
    """(script, line) when this call comes from the main script's top level outside a main
    guard -- directly, or through functions that such a line calls -- and worker processes
    started by ``start_method`` re-run that script; None otherwise.

    Only ``spawn`` and ``forkserver`` workers re-run the main script, and only when it is a
    file: not in a notebook, an interactive session or ``python -c``, nor for a package's
    ``__main__`` (multiprocessing skips those), so no false alarm there."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    spec = getattr(main, "__spec__", None)
    if (
        start_method == "fork"
        or not isinstance(path, str)
        or (spec is not None and spec.name.rpartition(".")[2] == "__main__")
    ):
        return None
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and not (
        frame.f_globals is vars(main)
        and frame.f_code.co_name == "<module>"
        and os.path.abspath(frame.f_code.co_filename) == os.path.abspath(path)
    ):
        frame = frame.f_back
    if frame is None:
        return None  # not called from the script's top level (e.g. from another thread)
    try:
        with open(path, "rb") as f:
            tree = ast.parse(f.read(), path)
    except (OSError, SyntaxError, ValueError):
        return None  # cannot tell; a broken pool still gets the advice
    line = frame.f_lineno
    if any(first <= line <= last for first, last in _main_guard_lines(tree)):
        return None
    return path, line


def _windowed(calls, submit, wait_any, window):
    """Yield every call's (index, status, payload) as it finishes, submitting a call only
    while it is fewer than ``window`` places after the earliest unfinished one.

    So at most ``window`` calls are in flight, and the results that ``ensemble`` holds back
    until an earlier, slower run is reduced (it reduces in run order) number fewer than
    ``window`` too: memory stays bounded however many runs there are.  The price: a run far
    slower than the ``window - 1`` after it holds back further submissions until it ends.
    A finished future is dropped as soon as its result is taken, which on Dask also frees
    its result on the cluster.
    """
    running = {}  # future -> index of its call
    finished = set()  # indices that finished while an earlier call still ran
    first = submitted = 0  # every call before `first` has finished
    while first < len(calls):
        while submitted < min(first + window, len(calls)):
            running[submit(calls[submitted])] = submitted
            submitted += 1
        done = wait_any(list(running))
        while done:
            future = done.pop()
            finished.add(running.pop(future))
            result = future.result()
            del future
            yield result
        while first in finished:
            finished.remove(first)
            first += 1


def _pool_results(calls, backend, workers):
    import concurrent.futures as cf
    from concurrent.futures.process import BrokenProcessPool

    with _executor(backend, workers) as pool:
        try:
            yield from _windowed(
                calls,
                lambda call: pool.submit(_call_task, *call),
                lambda futures: cf.wait(futures, return_when=cf.FIRST_COMPLETED).done,
                window=2 * workers,
            )  # a run queued behind each running one: no worker waits
        except BrokenProcessPool as exc:
            raise ProcessBackendError(
                'A worker process of ensemble(backend="processes") died (BrokenProcessPool). '
                "The usual cause: the script calls ensemble outside an "
                '`if __name__ == "__main__":` block. ' + _GUARD_ADVICE + "\nIf the script "
                "has that guard, a run crashed its worker or ran out of memory: "
                'backend="serial" shows the run\'s own error.'
            ) from exc


def _dask_results(calls, client):
    from distributed import wait

    threads = max(1, sum(client.nthreads().values()))
    yield from _windowed(
        calls,
        lambda call: client.submit(_call_task, *call, pure=False),
        lambda futures: wait(futures, return_when="FIRST_COMPLETED").done,
        window=2 * threads,
    )  # as for local pools, per thread of the cluster as it is now


def _results(calls, backend, workers):
    """Yield (index, status, payload) as runs finish, from the chosen backend."""
    if backend == "serial":
        for call in calls:
            yield _call_task(*call)
    elif hasattr(backend, "submit") and hasattr(backend, "gather"):  # a dask.distributed Client
        yield from _dask_results(calls, backend)
    elif backend in ("processes", "threads"):
        yield from _pool_results(calls, backend, workers)
    else:
        raise ValueError(
            f"backend must be 'serial', 'processes', 'threads' or a dask Client, got {backend!r}"
        )


def _seeds(seed, runs, points=None):
    """Per point, its runs' SeedSequences: ``SeedSequence(seed).spawn(runs)`` for a single
    model (``points=None``), ``SeedSequence(seed).spawn(points)[p].spawn(runs)`` for point p
    of a sweep."""
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    if points is None:
        return [root.spawn(runs)]
    return [child.spawn(runs) for child in root.spawn(points)]


class _PointReducer:
    """One point's runs, fed in run order, reduced to an EnsembleResult."""

    def __init__(self, seeds, keep_runs):
        self.seeds = seeds
        self.acc = _Accumulator()
        self.kept: list[Any] | None = [] if keep_runs else None
        self.failures = []
        self.first_exception = None  # of the first failure, if it came back with it

    def add(self, run, status, payload):
        if status == "ok":
            self.acc.add(payload, run)
            if self.kept is not None:
                self.kept.append(payload)
        else:
            s = self.seeds[run]
            self.failures.append(
                RunFailure(
                    run,
                    {"entropy": s.entropy, "spawn_key": s.spawn_key},
                    payload[0],
                    payload[2],
                    payload[1],
                )
            )
            if len(self.failures) == 1 and len(payload) > 3:
                self.first_exception = payload[3]

    def result(self):
        mean, error = self.acc.result()
        counts = dict(self.acc.counts)
        times = mean.pop("times", None)
        error.pop("times", None)
        counts.pop("times", None)
        return EnsembleResult(
            self.kept if self.kept is not None else [],
            mean,
            error,
            self.acc.count,
            self.failures,
            times,
            counts,
            dict(self.acc.left_out),
        )


def _check_run_options(run_kwargs, models):
    """Refuse, before any run starts, EDMD run options with which every run would fail.

    ``Simulation.run`` checks them again in every run (it has the last word, and checks
    what needs the scene); this is the same check made once, so that a caller's mistake
    is an exception here rather than K failed runs."""
    unknown = sorted(set(run_kwargs) - set(RUN_OPTIONS))
    if unknown:
        raise TypeError(
            f"ensemble got unknown keyword arguments {unknown}: besides its own, it takes "
            f"{', '.join(RUN_OPTIONS)}, which each EDMD run passes to Simulation.run "
            "(what a run stores follows from quantities=)"
        )
    t_stop = run_kwargs.get("t_stop")
    t_end = math.inf
    if t_stop is not None:
        try:
            t_end = float(t_stop)
        except (TypeError, ValueError):
            raise TypeError(f"t_stop must be a number (a time), got {t_stop!r}") from None
        if not t_end >= 0:
            raise ValueError(f"t_stop must be a time >= 0 (runs start at t = 0), got {t_end:g}")
    stop_when = run_kwargs.get("stop_when")
    if stop_when is not None:
        if not isinstance(stop_when, dict):
            raise TypeError(
                f"stop_when must be a dict such as {{'collisions_per_particle': 10}}, "
                f"got {type(stop_when).__name__}"
            )
        bad = sorted(set(stop_when) - set(_STOP_KEYS))
        if bad:
            raise ValueError(f"unknown stop_when keys {bad}; use {list(_STOP_KEYS)}")
        for key, value in stop_when.items():
            if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
                raise TypeError(f"stop_when[{key!r}] must be a number, got {value!r}")
            if math.isnan(value):
                raise ValueError(f"stop_when[{key!r}] is NaN")
    if (run_kwargs or any(isinstance(m, Scene) for m in models)) and (
        t_end == math.inf and not stop_when
    ):
        raise ValueError(
            "EDMD runs need a finite t_stop or a stop_when criterion, e.g. "
            "ensemble(scene, runs, t_stop=10.0) (the options of Simulation.run)"
        )
    times = run_kwargs.get("sample_times")
    if times is None:
        return
    try:
        times = np.asarray(times, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"sample_times must be an array of times: {exc}") from None
    if times.ndim != 1:
        raise ValueError(f"sample_times must be one-dimensional, got shape {times.shape}")
    if not np.all(np.isfinite(times)):
        raise ValueError("sample_times must be finite")
    if len(times) and times[0] < 0:
        raise ValueError(f"sample_times start at {times[0]:g}, before t = 0 when runs start")
    steps = np.diff(times)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(
            f"sample_times must be strictly increasing: entry {i + 1} is {times[i + 1]:g} "
            f"after {times[i]:g} (np.sort them, or build them increasing)"
        )
    if len(times) and times[-1] > t_end + 1e-12 * max(1.0, abs(t_end)):  # as Simulation.run
        raise ValueError(f"sample_times reach {times[-1]:g}, past t_stop = {t_end:g}")


def _check_outcome(reducers, results):
    """Raise when every run of the call failed alike -- the caller's mistake, most likely,
    that no result can hide -- and warn about what a result cannot show: a point whose
    runs all failed, quantities left out of the means."""
    failed = [f for r in results for f in r.failures]
    if failed and not any(r.count for r in results):
        kinds = sorted({f.error_type for f in failed})
        first = failed[0]
        if len(kinds) == 1:
            exc = next((r.first_exception for r in reducers if r.first_exception is not None), None)
            note = (
                f"every one of this ensemble's {len(failed)} runs failed with {kinds[0]} "
                f"(the first, run {first.index}: {first.error}); run {first.index}'s "
                f"traceback:\n{first.traceback}"
            )
            if exc is not None:
                if hasattr(exc, "add_note"):
                    exc.add_note(note)
                raise exc
            raise RuntimeError(note)
        warnings.warn(
            f"every one of this ensemble's {len(failed)} runs failed ({', '.join(kinds)}); "
            "see .failures",
            RuntimeWarning,
            stacklevel=3,
        )
    for p, r in enumerate(results):
        where = f"point {p}: " if len(results) > 1 else ""
        if r.count == 0 and any(x.count for x in results):
            warnings.warn(
                f"{where}every one of its {len(r.failures)} runs failed "
                f"(the first: {r.failures[0].error}); see .failures",
                RuntimeWarning,
                stacklevel=3,
            )
        for name, reason in r.left_out.items():
            warnings.warn(
                f"{where}{name!r} has no ensemble mean: {reason}; each run's is in "
                f"runs[r][{name!r}]",
                RuntimeWarning,
                stacklevel=3,
            )


def _reduce_in_order(results, reducers, runs, bar, stored=None):
    """Feed each (index, status, payload) to its point's reducer in index order, whatever
    order the runs finish in, so that means are bit-identical across backends.  Results
    that arrive early wait in ``pending``, which the windowed submission keeps small.
    ``stored``: index -> (status, payload) of the runs a save_to directory already holds,
    read from disk only when their turn comes."""
    pending: dict[int, tuple[str, Any]] = {}
    next_index = 0

    def feed():
        nonlocal next_index
        while next_index in pending or (stored is not None and next_index in stored):
            item = pending.pop(next_index) if next_index in pending else stored[next_index]
            point, run = divmod(next_index, runs)
            reducers[point].add(run, *item)
            next_index += 1

    feed()
    for index, status, payload in results:
        pending[index] = (status, payload)
        feed()
        bar.update(1)


class _Stored:
    """The runs a RunStore holds, by call index, loaded when asked for."""

    def __init__(self, store, indices, runs, seeds):
        self.store, self.indices, self.runs, self.seeds = store, indices, runs, seeds

    def __contains__(self, index):
        return index in self.indices

    def __getitem__(self, index):
        point, run = divmod(index, self.runs)
        return self.store.load(point, run, self.seeds[point][run])


def _saving(results, store, runs, seeds):
    """Write each run to the store as it finishes, then pass it on."""
    for index, status, payload in results:
        point, run = divmod(index, runs)
        store.write(point, run, seeds[point][run], status, payload)
        yield index, status, payload


# one model: one result; a sweep (a list or tuple of models): a list of results
@overload
def ensemble(
    model: Scene | Callable[..., Any],
    runs: int,
    *,
    seed: int | np.random.SeedSequence | None = None,
    backend: Any = "processes",
    workers: int | None = None,
    progress: bool | None = None,
    keep_runs: bool = True,
    quantities: Sequence[str] = ("msd", "temperature"),
    save_to: str | os.PathLike | None = None,
    **run_kwargs: Any,
) -> EnsembleResult: ...


@overload
def ensemble(
    model: Sequence[Scene | Callable[..., Any]],
    runs: int,
    *,
    seed: int | np.random.SeedSequence | None = None,
    backend: Any = "processes",
    workers: int | None = None,
    progress: bool | None = None,
    keep_runs: bool = True,
    quantities: Sequence[str] = ("msd", "temperature"),
    save_to: str | os.PathLike | None = None,
    **run_kwargs: Any,
) -> list[EnsembleResult]: ...


def ensemble(
    model: Scene | Callable[..., Any] | Sequence[Scene | Callable[..., Any]],
    runs: int,
    *,
    seed: int | np.random.SeedSequence | None = None,
    backend: Any = "processes",
    workers: int | None = None,
    progress: bool | None = None,
    keep_runs: bool = True,
    quantities: Sequence[str] = ("msd", "temperature"),
    save_to: str | os.PathLike | None = None,
    **run_kwargs: Any,
) -> EnsembleResult | list[EnsembleResult]:
    """Run ``runs`` independent realizations of a model, or of every model of a sweep, and
    return their results with ensemble means and standard errors.

    Parameters
    ----------
    model : Scene, a function of ``seed``, or a list or tuple of these (a sweep)
        - a ``Scene``: each run shuffles its velocity vectors among the particles (the
          thesis' method, section 3.8) and runs EDMD with ``run_kwargs`` (``t_stop``,
          ``sample_times``, ``stop_when`` as in ``Simulation.run``);
        - a function ``f(seed=SeedSequence)`` returning a ``Scene`` (e.g.
          ``functools.partial(Scene.random, 1000, 0.025, restitution=0.8)``): a new scene
          per run, then EDMD as above;
        - a function ``f(seed=SeedSequence)`` returning anything else (e.g.
          ``functools.partial(granular.langevin.run, ..., threads=1)``, one thread per run
          since the workers already share the cores): its NumPy arrays and numbers are the
          quantities (``run_kwargs`` must then be empty);
        - a list or tuple of P such models, the points of a sweep: all P x ``runs`` runs
          are scheduled together, so the backend's workers stay busy across points.

        Functions must be picklable (module level, or partials of such) for the process
        and Dask backends.
    runs : int
        Realizations per model.
    seed : int, SeedSequence or None
        Run r uses ``SeedSequence(seed).spawn(runs)[r]``; in a sweep, run r of point p uses
        ``SeedSequence(seed).spawn(P)[p].spawn(runs)[r]``, so a point gives the same
        results as ``ensemble(model[p], runs, seed=SeedSequence(seed).spawn(P)[p])``.
    backend : "processes" (default: all local cores), "serial", "threads", or a
        ``dask.distributed.Client`` (a real cluster, or a ``LocalCluster``).  Worker
        processes import the calling script, so in a script call ``ensemble`` under
        ``if __name__ == "__main__":`` (as for any process pool; notebooks need nothing);
        without it ``ProcessBackendError`` says so before any run starts.
    workers : int, optional
        Local worker count (default: all cores).
    progress : bool, optional
        tqdm bar over all runs; by default on in a terminal or a notebook, off otherwise.
    keep_runs : bool
        Keep every run's arrays (default), or only reduce them to means as they arrive.
        Either way at most 2 runs per worker (local worker or Dask thread) are submitted
        ahead of the earliest unfinished run, so results waiting to be reduced in run
        order stay few.
    quantities : for EDMD, which of ``EDMD_QUANTITIES`` to collect.
    save_to : str or path, optional
        A directory where each run's result is written as it finishes, and from which a
        later call with the same arguments resumes: runs already there are read back,
        not repeated (``runs`` may grow between calls: ``runs=k`` then ``runs=n``
        computes the n - k new ones), and the result is bit for bit the one an
        uninterrupted call gives.  Needs a ``seed`` and a model that pickles (a Scene, a
        module-level function or a partial of one: it is recognised by its pickle, not
        by its code).  Files are written atomically; failed runs are stored too (delete
        a run's file to redo it).  A call holds the directory locked until it returns: a
        second call on it meanwhile is refused (the lock dies with its process, so a
        killed ensemble resumes).  A directory, or a run file, made by another model,
        other run options, quantities, seed or granular version is refused, and so is a
        damaged run file (``CheckpointError`` naming the file).
    **run_kwargs
        For EDMD runs: ``t_stop``, ``sample_times`` and ``stop_when`` as in
        ``Simulation.run`` (times from 0, the start of every run).  They are checked
        before any run starts.

    Returns
    -------
    EnsembleResult or list of EnsembleResult
        One result, or for a sweep a list of them, one per point in order.  Failed runs
        (e.g. inelastic collapse) are listed in their point's ``.failures`` with their seeds
        and do not lose the others.

    Raises
    ------
    TypeError, ValueError
        For arguments with which no run could succeed (e.g. ``sample_times`` not
        increasing, an EDMD run without ``t_stop`` or ``stop_when``), before any run.
    Exception
        When every run of the call failed with one exception type: that exception (of
        the first failed run), with a note saying so and giving the run's traceback (a
        ``RuntimeError`` with its message when the exception is not at hand: runs read
        back from ``save_to``, or an exception that does not pickle).
        (Failures of several types give a ``RuntimeWarning`` and the result.)
    CheckpointError
        For a ``save_to`` directory in use, of another ensemble, or damaged.

    Warns
    -----
    RuntimeWarning
        For a quantity whose shape differs between runs (it gets no mean: see
        ``EnsembleResult.left_out``), and for a point of a sweep whose runs all failed.
    """
    if isinstance(runs, bool) or not isinstance(runs, (int, np.integer)):
        raise TypeError(f"runs must be a whole number >= 1, got {runs!r}")
    runs = int(runs)
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1
    ):
        raise ValueError(f"workers must be a whole number >= 1, got {workers!r}")
    if isinstance(model, (list, tuple)):
        sweep, models = True, list(model)
    else:
        sweep, models = False, [model]
    if not models:
        raise ValueError("a sweep needs at least one model")
    for m in models:
        if not (isinstance(m, Scene) or callable(m)):
            raise TypeError(
                "model must be a Scene, a function of seed or a list of these, "
                f"got {type(m).__name__}"
            )
    if isinstance(quantities, str):
        raise TypeError(f"quantities must be a list of names, e.g. ({quantities!r},)")
    bad = set(quantities) - set(EDMD_QUANTITIES)
    if bad:
        raise ValueError(f"unknown quantities {sorted(bad)}; choose from {EDMD_QUANTITIES}")
    _check_run_options(run_kwargs, models)
    if isinstance(backend, str) and backend == "processes":
        where = _unguarded_main_call(_process_context().get_start_method())
        if where is not None:
            raise ProcessBackendError(
                f'ensemble(backend="processes") is called from {where[0]}, line {where[1]}, '
                'outside an `if __name__ == "__main__":` block. ' + _GUARD_ADVICE
            )
    if save_to is not None and seed is None:
        raise ValueError(
            "save_to needs a seed (an int or a SeedSequence): runs are resumed by their seeds"
        )
    root = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    store = None
    if save_to is not None:
        from .ensemble_store import RunStore, fingerprint

        # locked until this call returns: no other ensemble writes there meanwhile
        store = RunStore(save_to, fingerprint(models, sweep, root, run_kwargs, quantities))
    with store if store is not None else contextlib.nullcontext():
        reducers = _run_all(
            models,
            runs,
            root,
            sweep,
            run_kwargs,
            quantities,
            store,
            keep_runs,
            backend,
            workers,
            progress,
        )
    results = [r.result() for r in reducers]
    _check_outcome(reducers, results)
    return results if sweep else results[0]


def _run_all(
    models, runs, root, sweep, run_kwargs, quantities, store, keep_runs, backend, workers, progress
):
    """Every run of every point, from the store or the backend, fed to one reducer per
    point in run order."""
    seeds = _seeds(root, runs, len(models) if sweep else None)
    tasks = [_Task(m, run_kwargs, tuple(quantities)) for m in models]
    # call index p * runs + r: run r of point p, the order in which runs are reduced
    calls = [
        (task, p * runs + r, s) for p, task in enumerate(tasks) for r, s in enumerate(seeds[p])
    ]
    stored = None
    if store is not None:
        done = {i for _, i, _ in calls if store.has(*divmod(i, runs))}
        stored = _Stored(store, done, runs, seeds)
        calls = [call for call in calls if call[1] not in done]
    reducers = [_PointReducer(point_seeds, keep_runs) for point_seeds in seeds]
    pool_size = workers if workers is not None else os.cpu_count() or 1
    with _progress_bar(len(calls), progress) as bar:
        results = _results(calls, backend, pool_size)
        if store is not None:
            results = _saving(results, store, runs, seeds)
        _reduce_in_order(results, reducers, runs, bar, stored)
    return reducers
