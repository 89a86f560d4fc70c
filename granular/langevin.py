"""Langevin models of molecular and granular gases (thesis 2.9, 4.2, App. C, E.2).

Each of N independent particles follows

    dx = v dt,    dv = -gamma(t) v dt + sqrt(2 D(t)) gamma(t) dW

- ``model="langevin"``: constant gamma0, D0 -- the underdamped Langevin equation, a model of
  a molecular gas (its MSD is the molecular gas' (2.68));
- ``model="udsbm"``: gamma0 (1 + t/tau0)^-a and D0 (1 + t/tau0)^-a -- underdamped scaled
  Brownian motion, a model of a granular gas.  ``exponent`` a = 1 (the default) is the
  thesis' UDSBM, cooling by Haff's law T ~ t^-2 (MSD 2.113); a = 5/6 is the gas of
  viscoelastic particles, T ~ t^(-5/3), D ~ T^(1/2) ~ t^(-5/6), MSD ~ t^(1/6)
  (Bodrova, Chechkin, Cherstvy & Metzler, PCCP 17, 21791 (2015); ``theory.viscoelastic_*``).
  In general the temperature D gamma ~ (1 + t/tau0)^(-2a).

Schemes
-------
``scheme="em"``: Euler-Maruyama exactly as (2.92)/(2.110), ``x += v dt``,
``v += -gamma_n v dt + sqrt(2 D_n) gamma_n dW`` with dW ~ N(0, dt) (the thesis' printed
noise term lost a bracket in conversion; this is the intended one).  It is unstable for
gamma0 dt >= 2, which is refused, and biased before: the stationary velocity variance of
the Langevin model is ``(T/m) * 2 / (2 - gamma0 dt)`` instead of T/m.

``scheme="exact"``: the exact Gaussian update of (x, v) over a step of the
Ornstein-Uhlenbeck process with the step's coefficients -- exact for the Langevin model at
any step, and stable at any step.  For UDSBM the coefficients are frozen at the step's
midpoint; since they change on the time scale 1 + t/tau0, the local error per step is
O((dt / tau0)^2) relative, and the integrated error O(dt^2 / (tau0 (tau0 + t))) -- far
below Euler-Maruyama's O(gamma0 dt) bias.  The same holds for any exponent a: the step
takes gamma0 w^-a, D0 w^-a at the midpoint's w = 1 + t/tau0 (measured in
docs/powerlaw_udsbm.md).

The exact scheme is the default; Euler-Maruyama, the thesis' scheme, is one keyword away.

Random numbers are counter-based (see ``csrc/rng.h``): each particle's noise at each step
is a function of (seed, step, particle) only, so results are bit-identical whatever the
chunking or the number of threads.  Nothing of size N x steps is stored: the ensemble MSD
at the sample times and the time-averaged MSD at the requested lags are accumulated on the
fly.  The TAMSD averages, for each lag, the windows starting every ``s`` steps:
``tamsd_estimator="strided"`` (the default) takes s the largest power of two <= max(1,
lag/4), so that 4 to 8 windows overlap any one -- its variance is at most 3.1% above that
of every window for Brownian increments, at a cost per step that no longer grows with the
number of long lags; ``"all"`` takes every window (s = 1), the textbook estimator, at one
window per lag per step.  See docs/performance.md.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._deprecation import REMOVAL_VERSION, deprecated
from ._results import readonly
from ._scales import SCALE_HI, SCALE_LO, check_range
from .errors import shown

if TYPE_CHECKING:  # for the hints only: scene imports nothing from here, but stay light
    from .scene import Scene
    from .theory import LangevinCoefficients

MODELS = ("langevin", "udsbm")
# the TAMSD's windows (csrc/tamsd.h): "strided" starts a lag's windows every power of
# two <= max(1, lag/4) steps, "all" at every step
TAMSD_ESTIMATORS = ("strided", "all")
SCHEMES = ("em", "exact")
INITIAL = ("thermal", "udsbm", "fixed")
# Work per call into C, in particle-steps: a block of particles over the whole run, or one
# particle over a segment of its steps -- at most ~0.6 s (exact UDSBM, ~60 ns a step),
# so Ctrl-C is prompt however few the particles and many the steps.
_CHUNK_PARTICLE_STEPS = 10_000_000


class _ArrayAndMethod(np.ndarray):
    """The transition from an array attribute to a method of the same name:
    ``result.msd`` used to be the (T,) array and is now the method ``result.msd()``.
    This object is both -- called, it runs the method; used as an array (indexing,
    arithmetic, NumPy functions), it is the old array and warns (FutureWarning) that this
    use goes in granular ``REMOVAL_VERSION``.  Results of array use are plain arrays.
    ``inspect.signature`` gives the method's.  Goes in ``REMOVAL_VERSION`` with the array
    use, leaving plain methods."""

    _method: Any  # the bound method (None only on views made by NumPy itself)
    _name: str

    def __new__(
        cls, values: NDArray[np.float64], method: Callable[..., NDArray[np.float64]], name: str
    ) -> _ArrayAndMethod:
        obj = np.asarray(values).view(cls)
        obj._method, obj._name = method, name
        return obj

    def __array_finalize__(self, obj: object) -> None:
        self._method = getattr(obj, "_method", None)
        self._name = getattr(obj, "_name", "")

    def __call__(self, *args: Any, **kwargs: Any) -> NDArray[np.float64]:
        return self._method(*args, **kwargs)

    @property
    def __signature__(self) -> inspect.Signature:
        return inspect.signature(self._method)

    def _deprecated(self) -> None:
        deprecated(
            f"using result.{self._name} as an array",
            f"call result.{self._name}() (the same numbers)",
            stacklevel=4,
        )

    def __getitem__(self, index: Any) -> Any:
        self._deprecated()
        return self.view(np.ndarray)[index]

    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: Any, **kwargs: Any) -> Any:
        self._deprecated()
        plain = tuple(x.view(np.ndarray) if isinstance(x, _ArrayAndMethod) else x for x in inputs)
        if "out" in kwargs:
            kwargs["out"] = tuple(
                x.view(np.ndarray) if isinstance(x, _ArrayAndMethod) else x for x in kwargs["out"]
            )
        return getattr(ufunc, method)(*plain, **kwargs)

    def __array_function__(self, func: Any, types: Any, args: Any, kwargs: Any) -> Any:
        self._deprecated()

        def plain(x: Any) -> Any:
            if isinstance(x, _ArrayAndMethod):
                return x.view(np.ndarray)
            if isinstance(x, (list, tuple)):
                return type(x)(plain(y) for y in x)
            return x

        return func(*plain(args), **{k: plain(v) for k, v in kwargs.items()})

    def __repr__(self) -> str:
        return repr(self.view(np.ndarray))

    def __reduce__(self) -> Any:  # pickles as the plain array it holds
        return self.view(np.ndarray).__reduce__()


class _MethodWithArrayShim:
    """A method that, for one more release, is also the array it replaced: on the class it
    is the plain function (so ``inspect.signature(LangevinResult.msd)`` and ``help`` work),
    on a result an ``_ArrayAndMethod`` of the array in ``values`` (an attribute name).
    Goes in ``REMOVAL_VERSION``: the methods then are plain methods."""

    def __init__(self, values: str) -> None:
        self.values = values

    def __call__(self, method: Callable[..., Any]) -> _MethodWithArrayShim:
        self.method = method
        functools.update_wrapper(self, method)
        return self

    def __get__(self, result: Any, owner: type | None = None) -> Any:
        if result is None:
            return self.method
        bound = self.method.__get__(result, owner)
        return _ArrayAndMethod(getattr(result, self.values), bound, self.method.__name__)


def _no_lags() -> ValueError:
    """The error of a TAMSD asked of a run that accumulated none (no ``tamsd_lags``)."""
    return ValueError(
        "no time-averaged MSD was accumulated (the run had no tamsd_lags): ask for it "
        "before the run, with langevin.run(..., tamsd_lags=[...]) -- lags in time, whole "
        "steps of dt, at most t_stop (e.g. tamsd_lags=[dt, 10 * dt, 100 * dt])"
    )


def _lag_steps(lags: ArrayLike, dt: float, n_steps: int, name: str) -> NDArray[np.int64]:
    """Lags in time as whole numbers of steps, 1 to ``n_steps``.  The engine samples the
    path at whole steps only, so a lag between two steps is refused with the nearest two
    that are whole steps, rather than rounded to one of them unseen (``Trajectory.tamsd``
    refuses a lag off its samples in the same way)."""
    from .analysis import _nearest_on_grid

    t = np.asarray(lags, dtype=np.float64).reshape(-1)
    k = np.rint(t / dt)
    inside = (k >= 1) & (k <= n_steps)  # NaN fails too
    if not np.all(inside):
        raise ValueError(
            f"{name} must be at least dt and at most t_stop ({shown(dt)} .. "
            f"{shown(n_steps * dt)}), got {shown(t[~inside][0])}"
        )
    off = ~np.isclose(t, k * dt, rtol=1e-9, atol=0.0)
    if np.any(off):
        lag = float(t[off][0])
        raise ValueError(
            f"{name}: {shown(lag)} is not a whole number of steps of dt = {shown(dt)}, and the "
            f"engine samples the path at whole steps only; the nearest lags that are: "
            f"{_nearest_on_grid(lag, dt, n_steps)} (to round lags to whole steps: "
            f"numpy.unique(numpy.rint(lags / dt)) * dt)"
        )
    return k.astype(np.int64)


def _lag_indices(
    available: NDArray[np.float64], dt: float, lags: ArrayLike | None, lag_samples: ArrayLike | None
) -> NDArray[np.intp]:
    """Indices into ``available`` (lags in time, whole multiples of ``dt``) of the lags
    asked for: all of them when neither ``lags`` (in time) nor ``lag_samples`` (in steps)
    is given.  An engine that accumulates the TAMSD on the fly has it at those lags
    only, so any other lag is refused by name, with the nearest that were accumulated."""
    if lags is not None and lag_samples is not None:
        raise TypeError("give at most one of lags (in time) and lag_samples (in steps)")
    have = np.rint(np.asarray(available, dtype=np.float64) / dt).astype(np.int64)
    if len(have) == 0:
        raise _no_lags()
    if lags is None and lag_samples is None:
        return np.arange(len(have))
    if lag_samples is not None:
        k = np.atleast_1d(np.asarray(lag_samples))
        if k.size and not np.issubdtype(k.dtype, np.integer):
            if not np.all(np.isfinite(k)) or np.any(k != np.rint(k)):
                raise ValueError(f"lag_samples must be whole numbers of steps, got {shown(k)}")
        k = k.astype(np.int64).reshape(-1)
    else:
        t = np.atleast_1d(np.asarray(lags, dtype=np.float64)).reshape(-1)
        k = np.rint(t / dt).astype(np.int64) if np.all(np.isfinite(t)) else np.full(t.shape, -1)
        off = ~np.isclose(t, k * dt, rtol=1e-9, atol=0.0)
        k[off] = -1  # not a whole number of steps: never accumulated
    pos = np.searchsorted(have, k)
    found = (pos < len(have)) & (have[np.minimum(pos, len(have) - 1)] == k)
    if not np.all(found):
        miss = int(np.argmin(found))
        asked = (np.asarray(lag_samples) if lags is None else np.asarray(lags)).reshape(-1)[miss]
        # the accumulated lags on either side of the one asked for
        at = np.searchsorted(have, (asked if lags is None else asked / dt))
        near = np.unique(have[[max(at - 1, 0), min(at, len(have) - 1)]])
        unit, scale = (" steps", 1) if lags is None else ("", dt)
        raise ValueError(
            f"lag {shown(asked)}{unit} was not accumulated: the engine keeps the TAMSD only "
            f"at the lags given to run(tamsd_lags=...); the nearest of those: "
            f"{' and '.join(shown(k * scale) for k in near)}{unit} (all: {shown(have * scale)})"
        )
    return pos


@dataclass(frozen=True, eq=False, repr=False)
class LangevinResult:
    """What a Langevin/UDSBM run measured: read-only (a frozen dataclass whose arrays are
    read-only views), as every result is (see docs/analysis.md, "Results").

    The quantities every result offers under the same names and units, as a
    ``Trajectory`` and an ``EnsembleResult`` do: ``times``, ``temperature`` (an energy,
    k_B = 1), ``msd(per_dimension=False, particles=None)``, ``tamsd(lags=None, *,
    lag_samples=None, particles=None, per_particle=False)``, ``tamsd_lags`` and
    ``ergodicity_breaking(lags=None, *, lag_samples=None, particles=None)``.

    Attributes
    ----------
    times : (T,) sample times (whole steps: ``steps * dt``)
    steps : (T,) the sample steps
    msd_total, msd_per_dimension : (T,), (T, d) ensemble MSD from the common start at the
        origin, summed over dimensions and per dimension (``msd()`` returns them)
    v2 : (T,) mean squared speed, per particle
    temperature : (T,) the temperature, an energy: ``mass * v2 / dim``
    tamsd_lags : (L,) lags in time at which the TAMSD was accumulated
    tamsd_mean : (L,) particle-averaged time-averaged MSD (``tamsd()`` returns it)
    tamsd_per_particle : (N, L)
    tamsd_estimator : "strided" or "all", the windows the TAMSD averages (see ``run``)
    positions : (T, N, d) positions at the sample times, or None (``store_positions``)
    final_positions, final_velocities : (N, d) the state at ``t_stop``
    model, scheme : as given to ``run``
    gamma0, D0, tau0, dt, t_stop : the coefficients, step and duration (whole steps)
    exponent : a of UDSBM's (1 + t/tau0)^-a (1 for the Langevin model)
    n, dim : particles and dimensions
    v0_sq : initial mean squared velocity per component
    initial : the initial velocities, as given to ``run``: "thermal" or "udsbm" (Gaussian)
        or "fixed" (one speed for every particle)
    mass : the particles' mass (``run(mass=...)``; the scene's for ``from_scene``): the
        dynamics depend on D0 and gamma0 only, the temperature is ``mass`` times
        ``D0 gamma0`` in equilibrium
    """

    times: NDArray[np.float64]
    steps: NDArray[np.int64]
    msd_total: NDArray[np.float64]
    msd_per_dimension: NDArray[np.float64]
    v2: NDArray[np.float64]
    tamsd_lags: NDArray[np.float64]
    tamsd_mean: NDArray[np.float64]
    tamsd_per_particle: NDArray[np.float64]
    positions: NDArray[np.float64] | None
    final_positions: NDArray[np.float64]
    final_velocities: NDArray[np.float64]
    model: str
    scheme: str
    tamsd_estimator: str
    gamma0: float
    D0: float
    tau0: float
    dt: float
    n: int
    dim: int
    t_stop: float
    v0_sq: float
    exponent: float = 1.0
    initial: str = "thermal"
    mass: float = 1.0

    def __post_init__(self) -> None:
        # read-only views: a caller writing into an array the result hands out gets a
        # ValueError instead of changing the result unseen
        self.__setstate__(dict(vars(self)))

    def __setstate__(self, state: dict[str, Any]) -> None:
        # unpickled (and copied) read-only too: NumPy does not keep the flag
        for name, value in state.items():
            object.__setattr__(self, name, readonly(value))

    @_MethodWithArrayShim("msd_total")
    def msd(
        self, per_dimension: bool = False, particles: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """The ensemble MSD at the sample times, (T,) summed over dimensions or (T, d) per
        dimension.  The same call as ``Trajectory.msd`` and ``EnsembleResult.msd``.

        Parameters
        ----------
        per_dimension : bool
            Return (T, d), one column per axis, instead of the sum over axes.
        particles : array_like of int or bool, optional
            Average over these particles only (indices, or a boolean mask over all N);
            needs the positions (``run(store_positions=True)``), since the engine
            accumulates the MSD of all particles only.

        Notes
        -----
        Used as an array, ``result.msd`` is still the (T,) MSD, with a FutureWarning: that
        use goes in granular ``REMOVAL_VERSION``."""
        if particles is None:
            return self.msd_per_dimension if per_dimension else self.msd_total
        if self.positions is None:
            raise ValueError(
                "msd(particles=...) needs the positions: run with "
                "store_positions=True (the engine accumulates the MSD of all "
                "particles only)"
            )
        from .analysis import _select

        # every particle starts at the origin, so |x|^2 is the squared displacement
        x = _select(self.positions, particles)
        per = np.einsum("tna,tna->ta", x, x) / x.shape[1]
        return per if per_dimension else per.sum(axis=1)

    @_MethodWithArrayShim("tamsd_mean")
    def tamsd(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
        per_particle: bool = False,
    ) -> NDArray[np.float64]:
        """The time-averaged MSD, (L,) averaged over particles or (N, L) per particle.
        The same call, defaults and errors as ``Trajectory.tamsd`` and
        ``EnsembleResult.tamsd``.

        The engine accumulates it on the fly at the lags given to ``run(tamsd_lags=...)``
        (``tamsd_lags``) and only there: by default all of them; ``lags`` (in time) or
        ``lag_samples`` (in steps, the engine's samples of the path) pick some of them,
        and any other lag is refused, with the nearest accumulated ones.  A run given no
        ``tamsd_lags`` raises ValueError, saying how to ask for them.

        Parameters
        ----------
        lags, lag_samples : array_like, optional
            The lags to return, in time or in the engine's steps (at most one of the two).
        particles : array_like of int or bool, optional
            Average over these particles only (indices, or a boolean mask over all N).
        per_particle : bool
            Return (N, L) (or one row per chosen particle) instead of the mean.

        Notes
        -----
        Used as an array, ``result.tamsd`` is still the (L,) TAMSD, with a FutureWarning:
        that use goes in granular ``REMOVAL_VERSION``."""
        pick = _lag_indices(self.tamsd_lags, self.dt, lags, lag_samples)
        if particles is None and not per_particle:
            return self.tamsd_mean[pick]
        from .analysis import _select

        # (N, L) as (1, N, L) "positions" so that the particle choice is analysis' own
        per = self.tamsd_per_particle[:, pick]
        if particles is not None:
            per = _select(per[None], particles)[0]
        return per if per_particle else per.mean(axis=0)

    @property
    def temperature(self) -> NDArray[np.float64]:
        """(T,) the temperature at the sample times, an energy (k_B = 1) as on every
        result: ``mass * v2 / dim``.

        It used to be the temperature per unit mass, ``v2 / dim``; the numbers
        differ only for a mass other than 1 (a ``from_scene`` run of heavier or lighter
        particles), which warns (FutureWarning) until granular ``REMOVAL_VERSION``."""
        if self.mass != 1.0:
            warnings.warn(
                f"LangevinResult.temperature is an energy now, mass * v2 / dim with this "
                f"run's mass {shown(self.mass)}; it used to be per unit mass, which is "
                f"result.v2 / result.dim.  This notice goes in granular {REMOVAL_VERSION}",
                FutureWarning,
                stacklevel=2,
            )
        return self._temperature()

    def _temperature(self) -> NDArray[np.float64]:
        return readonly(self.mass * self.v2 / self.dim)

    def arrays(self) -> dict[str, NDArray[Any]]:
        """The NumPy arrays and numbers of this result by name, as ``granular.ensemble``
        collects them from each run (``msd``, ``tamsd`` and ``temperature`` under those
        names, the values of ``msd()``, ``tamsd()`` and ``temperature``): a dict of a
        result's contents, the one dict a result hands out besides an ensemble's
        ``mean`` and ``error``."""
        out = {
            "times": self.times,
            "steps": self.steps,
            "msd": self.msd_total,
            "msd_per_dimension": self.msd_per_dimension,
            "v2": self.v2,
            "temperature": self._temperature(),
            "tamsd_lags": self.tamsd_lags,
            "tamsd": self.tamsd_mean,
            "tamsd_per_particle": self.tamsd_per_particle,
            "final_positions": self.final_positions,
            "final_velocities": self.final_velocities,
        }
        if self.positions is not None:
            out["positions"] = self.positions
        for name in ("gamma0", "D0", "tau0", "dt", "t_stop", "v0_sq", "exponent", "mass"):
            out[name] = np.asarray(getattr(self, name))
        return out

    def theory_msd(
        self,
        t: float | NDArray[np.float64] | None = None,
    ) -> float | NDArray[np.float64]:
        """The analytic ensemble MSD of this model from ``granular.theory`` (with this
        run's initial speed) at the sample times or at t."""
        from . import theory

        t = self.times if t is None else t
        if self.model == "langevin":
            return theory.msd_langevin(
                t, D0=self.D0, gamma0=self.gamma0, dim=self.dim, v0_sq=self.v0_sq
            )
        if self.exponent != 1.0:
            return theory.msd_powerlaw_udsbm(
                t,
                D0=self.D0,
                gamma0=self.gamma0,
                tau0=self.tau0,
                exponent=self.exponent,
                dim=self.dim,
                v0_sq=self.v0_sq,
            )
        return theory.msd_udsbm(
            t, D0=self.D0, gamma0=self.gamma0, tau0=self.tau0, dim=self.dim, v0_sq=self.v0_sq
        )

    def theory_tamsd(self, lags: ArrayLike | None = None) -> NDArray[np.float64]:
        """The expected time-averaged MSD of this run at its lags (or at ``lags``), as the
        engine measures it: see ``theory_tamsd``."""
        if lags is None and len(self.tamsd_lags) == 0:
            raise _no_lags()
        return theory_tamsd(
            self.tamsd_lags if lags is None else lags,
            gamma0=self.gamma0,
            D0=self.D0,
            tau0=self.tau0,
            dt=self.dt,
            t_stop=self.t_stop,
            dim=self.dim,
            v0_sq=self.v0_sq,
            tamsd_estimator=self.tamsd_estimator,
            exponent=self.exponent,
        )

    def ergodicity_breaking(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """The measured ergodicity-breaking parameter at the TAMSD lags (or those chosen as
        in ``tamsd``), over the particles: ``analysis.ergodicity_breaking`` of
        ``tamsd(..., per_particle=True)``; 0 for an ergodic process as t_stop / lag grows.
        The same call as on the other results.  Theory: ``theory_ergodicity_breaking``.

        Parameters
        ----------
        lags, lag_samples, particles : as in ``tamsd``.
        """
        from . import analysis

        per = self.tamsd(lags, lag_samples=lag_samples, particles=particles, per_particle=True)
        return analysis.ergodicity_breaking(per)

    def theory_ergodicity_breaking(self, lags: ArrayLike | None = None) -> NDArray[np.float64]:
        """The expected EB of this run's TAMSD estimator (its window starts, every
        ``sde_lag_stride`` steps) at its lags or at ``lags``:
        ``theory.udsbm_ergodicity_breaking`` (cost: windows x overlapping windows).  It assumes
        Gaussian initial velocities (``initial`` "thermal" or "udsbm"), as Isserlis'
        theorem there needs.

        Raises
        ------
        ValueError
            For a run started with ``initial="fixed"``: every particle at one speed is not
            a Gaussian velocity, so the TAMSD's variance is not the one Isserlis' theorem
            gives (its fourth moments differ), and no number is returned rather than a
            wrong one."""
        from . import theory

        if self.initial not in ("thermal", "udsbm"):
            raise ValueError(
                f"theory_ergodicity_breaking assumes Gaussian initial velocities (initial "
                f"'thermal' or 'udsbm'); this run started with initial={self.initial!r} -- "
                "one speed for every particle -- whose velocities are not Gaussian, so "
                "Isserlis' theorem, on which the theory rests, does not hold: measure EB "
                "(ergodicity_breaking) or run with initial='thermal'"
            )

        if lags is None and len(self.tamsd_lags) == 0:
            raise _no_lags()
        lag_t = self.tamsd_lags if lags is None else lags
        n_steps = round(self.t_stop / self.dt)
        out = []
        for k in _lag_steps(lag_t, self.dt, n_steps, "lags"):
            k = int(k)
            starts = (
                np.arange(
                    0,
                    n_steps - k + 1,
                    _core.sde_lag_stride(k, _estimator_code(self.tamsd_estimator)),
                )
                * self.dt
            )
            out.append(
                theory.udsbm_ergodicity_breaking(
                    k * self.dt,
                    start=starts,
                    D0=self.D0,
                    gamma0=self.gamma0,
                    tau0=self.tau0,
                    exponent=self.exponent,
                    dim=self.dim,
                    v0_sq=self.v0_sq,
                )
            )
        return np.array(out)

    def __repr__(self) -> str:
        return (
            f"LangevinResult(model={self.model!r}, scheme={self.scheme!r}, n={self.n}, "
            f"dim={self.dim}, dt={self.dt}, t_stop={self.t_stop}, samples={len(self.times)}, "
            f"lags={len(self.tamsd_lags)})"
        )


def theory_tamsd(
    lags: ArrayLike,
    *,
    gamma0: float,
    D0: float,
    dt: float,
    t_stop: float,
    tau0: float = math.inf,
    dim: int = 3,
    v0_sq: float | None = None,
    tamsd_estimator: str = "strided",
    exponent: float = 1.0,
) -> NDArray[np.float64]:
    """The expected time-averaged MSD of a run, total over ``dim``: for each lag the mean,
    over the windows the engine averages (starting every ``sde_lag_stride`` steps from 0
    while they end by ``t_stop``; ``tamsd_estimator`` as in ``run``), of the mean squared
    displacement over the window -- ``theory.msd_langevin`` from the velocity variance
    reached at the window's start for the Langevin model (tau0 = inf),
    ``theory.udsbm_increment_msd`` for UDSBM.
    ``v0_sq`` is the initial mean squared velocity per component (None: thermal, or App.
    C's for UDSBM).  Each lag must be a whole number of steps of ``dt`` (as ``run``'s
    ``tamsd_lags``); any other is refused, with the nearest two that are.  Ergodic
    Langevin from a thermal start: the ensemble MSD.  For UDSBM
    with ``exponent`` a != 1, ``theory.powerlaw_udsbm_increment_msd`` (numerical moments;
    ``v0_sq`` must then be given)."""
    from . import theory

    n_steps = round(t_stop / dt)
    lag_t = np.atleast_1d(np.asarray(lags, dtype=np.float64))
    out = []
    for lag, k in zip(lag_t, _lag_steps(lag_t, dt, n_steps, "lags"), strict=True):
        k = int(k)
        stride = _core.sde_lag_stride(k, _estimator_code(tamsd_estimator))
        # float64 already; astype (no copy) tells the type checker, for theory's annotations
        starts = (np.arange(0, n_steps - k + 1, stride) * dt).astype(np.float64, copy=False)
        if math.isinf(tau0):
            thermal = D0 * gamma0
            v_sq = (
                thermal
                if v0_sq is None
                else thermal + (v0_sq - thermal) * np.exp(-2 * gamma0 * starts)
            )
            incr = theory.msd_langevin(lag, D0=D0, gamma0=gamma0, dim=dim, v0_sq=v_sq)
        elif exponent != 1.0:
            if v0_sq is None:
                raise ValueError("the power-law UDSBM (exponent != 1) needs v0_sq")
            incr = theory.powerlaw_udsbm_increment_msd(
                lag,
                start=starts,
                D0=D0,
                gamma0=gamma0,
                tau0=tau0,
                exponent=exponent,
                dim=dim,
                v0_sq=v0_sq,
            )
        else:
            incr = theory.udsbm_increment_msd(
                lag, start=starts, D0=D0, gamma0=gamma0, tau0=tau0, dim=dim, v0_sq=v0_sq
            )
        out.append(float(np.mean(incr)))
    return np.array(out)


def _estimator_code(name: str) -> int:
    if name not in TAMSD_ESTIMATORS:
        raise ValueError(f"tamsd_estimator must be one of {TAMSD_ESTIMATORS}, got {name!r}")
    return TAMSD_ESTIMATORS.index(name)


def _threads(threads: int | None) -> int:
    """The number of threads asked for, checked; None: the cores this process may use."""
    if threads is None:
        try:
            return max(1, len(os.sched_getaffinity(0)))
        except AttributeError:  # not on Linux
            return max(1, os.cpu_count() or 1)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be a whole number >= 1 or None, got {shown(threads)}")
    return min(int(threads), 1024)


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (value > 0 and math.isfinite(value)):
        raise ValueError(f"{name} must be positive and finite, got {value}")
    return value


def _check_scales(
    gamma0: float,
    D0: float,
    dt: float,
    t_stop: float,
    tau0: float,
    exponent: float,
    mass: float,
    speed_name: str,
    speed: float,
) -> None:
    """Refuse coefficients whose squares and products would leave float64 over the run,
    with the limits of granular._scales: the times dt, t_stop, tau0 and the rate gamma0
    (multiplied by one another) each within SCALE_LO .. SCALE_HI; the products D0 (a length
    squared per time), D0 gamma0 (the thermal speed squared) and the mass within their
    squares.  The initial speed (``speed``, rms over the components) is bounded from above
    only, as the scene's speeds are, and so is the largest MSD the run can reach: ballistic,
    at most speed^2 t_stop^2, or diffusive, at most 2 dim D0 t_stop (the friction and the
    diffusivity only decay), so speed t_stop and D0 t_stop are bounded by SCALE_HI and
    SCALE_HI^2.  Each MSD then stays below ~1e281, and its sums over particles and windows
    finite.  UDSBM's friction and diffusivity at t_stop, gamma0 and D0 times
    (1 + t_stop/tau0)^-exponent, stay above the lower limits: a friction that underflows to
    0 would divide 0 by 0 in the exact step."""
    lo, hi = SCALE_LO, SCALE_HI

    def check(name: str, value: float, low: float, high: float, advice: str = "") -> None:
        check_range(
            name,
            value,
            low,
            high,
            "the Langevin arithmetic (squared displacements and speeds, summed over "
            "particles and windows)",
            advice
            or "choose units in which the times, D0, the speeds and the mass are nearer 1 "
            "(e.g. 1/gamma0, the thermal speed sqrt(D0 gamma0) and the particles' mass)",
        )

    for name, value in (("dt", dt), ("t_stop", t_stop), ("gamma0", gamma0)):
        check(name, value, lo, hi)
    if math.isfinite(tau0):
        check("tau0", tau0, lo, hi)
    check("D0", D0, lo * lo, hi * hi)
    check("mass", mass, lo * lo, hi * hi)
    check("D0 * gamma0 (the thermal speed squared)", D0 * gamma0, lo * lo, hi * hi)
    check(
        "D0 * t_stop (the diffusive MSD's scale)",
        D0 * t_stop,
        0.0,
        hi * hi,
        f"D0 at most {hi * hi / t_stop:.3g} for t_stop = {shown(t_stop)}",
    )
    check(speed_name, speed, 0.0, hi)
    check(
        f"{speed_name} * t_stop (the ballistic displacement)",
        speed * t_stop,
        0.0,
        hi,
        f"{speed_name} at most {hi / t_stop:.3g} for t_stop = {shown(t_stop)}",
    )
    fastest = max(speed, math.sqrt(D0 * gamma0))
    check(
        f"mass * speed^2 (the temperature's scale, speed = {fastest:.3g})",
        mass * fastest * fastest,
        0.0,
        hi * hi,
    )
    if math.isfinite(tau0):
        # in logarithms: the decay factor itself may be below the smallest float64
        decay = -exponent * math.log10(1.0 + t_stop / tau0)
        for name, value, low in (("gamma0", gamma0, lo), ("D0", D0, lo * lo)):
            at_end = math.log10(value) + decay
            if at_end < math.log10(low):
                raise ValueError(
                    f"UDSBM's {name} at t_stop, {name} (1 + t_stop/tau0)^-exponent = "
                    f"10^{at_end:.4g}, is below {low:g}, the range in which the Langevin "
                    f"arithmetic stays within float64: a shorter t_stop, a longer tau0 or a "
                    f"smaller exponent (here {name} = {shown(value)}, t_stop = "
                    f"{shown(t_stop)}, tau0 = {shown(tau0)}, exponent = {shown(exponent)})"
                )


def run(
    n: int,
    *,
    gamma0: float,
    D0: float,
    dt: float,
    t_stop: float,
    tau0: float = math.inf,
    model: str | None = None,
    exponent: float = 1.0,
    scheme: str = "exact",
    dim: int = 3,
    sample_times: ArrayLike | None = None,
    tamsd_lags: ArrayLike | None = None,
    initial: str = "thermal",
    speed: float | None = None,
    store_positions: bool = False,
    seed: Any = None,
    progress: bool = False,
    threads: int | None = None,
    tamsd_estimator: str = "strided",
    mass: float = 1.0,
) -> LangevinResult:
    """Integrate N independent particles from a common start at the origin.

    Parameters
    ----------
    n : number of particles
    gamma0, D0 : friction and diffusivity (per dimension) at t = 0
    tau0 : UDSBM time scale (infinite: the Langevin model)
    model : "langevin" or "udsbm" (default: "udsbm" when tau0 is finite)
    exponent : a > 0 of UDSBM's gamma0 (1 + t/tau0)^-a, D0 (1 + t/tau0)^-a: 1 (default)
        the thesis' UDSBM (Haff's law), 5/6 the viscoelastic gas (T ~ t^(-5/3),
        MSD ~ t^(1/6)); only for model="udsbm"
    scheme : "exact" (the default: exact OU update, stable at any step) or "em"
        (Euler-Maruyama, thesis 2.92/2.110)
    dt, t_stop : step and duration (t_stop is rounded to whole steps, at most
        ``_core.SDE_MAX_STEPS`` = 2**62 of them)
    dim : 1, 2 or 3
    sample_times : increasing times to sample the ensemble MSD, rounded to whole steps
        (times that round to the same step are sampled once: ``result.times`` has the
        times used); default 60 log-spaced times and 0
    tamsd_lags : increasing lags (in time) of the time-averaged MSD over [0, t_stop]
        (``result.tamsd_lags``), each a whole number of steps (to 1e-9 relative), from dt
        to t_stop: the engine samples the path at whole steps, so any other lag is refused
        before the run, with the two nearest that are whole steps (round log-spaced lags
        with ``np.unique(np.rint(lags / dt)) * dt``).  None: no TAMSD is accumulated, and
        ``result.tamsd()`` raises
    tamsd_estimator : "strided" (default) or "all": which windows the TAMSD averages --
        starting every power of two <= max(1, lag/4) steps, or at every step (exact, but
        one window per lag per step, and a ring of lag positions per thread; lags up to
        2**30 steps).  See the module docstring for their statistical difference.
    initial : "thermal" -- Gaussian velocities with <v_a^2> = T0/m = D0 gamma0;
        "udsbm" -- Gaussian with App. C's "correct" <v_a^2> = D0 gamma0 a/(a - 1),
        a = gamma0 tau0, for which the UDSBM MSD is exactly (2.113) (exponent 1 only:
        for another exponent no initial variance makes <v^2> a pure power of 1 + t/tau0);
        "fixed" -- every particle at ``speed`` (default sqrt(d D0 gamma0), the thermal rms
        speed) in an isotropic random direction (thesis 3.3, made isotropic).
    store_positions : keep (T, N, d) positions at the sample times
    seed : anything ``numpy.random.SeedSequence`` takes
    progress : tqdm bar over particle-steps
    threads : how many threads step the particles (None: one per core this process may
        run on).  The results are the same to the bit for any number: each particle's
        random numbers depend on (seed, step, particle) only, and the ensemble sums add
        fixed blocks of particles in a fixed order.  A run of fewer particles than
        threads, or so long that one particle is stepped at a time, uses fewer (at most
        1024 are started).
    mass : the particles' mass (default 1): the dynamics take D0 and gamma0 only (the
        temperature per unit mass is D0 gamma0), the mass makes ``result.temperature``
        an energy, ``mass * v2 / dim``, as every result's is

    Returns
    -------
    LangevinResult

    Raises
    ------
    ValueError
        For a parameter out of its range (named in the message), scales among them: the
        times dt, t_stop, tau0 and the rate gamma0 within 1e-140 .. 1e140, D0, D0 gamma0
        and the mass within 1e-280 .. 1e280, the initial speed and speed times t_stop at
        most 1e140 (so that squared displacements and speeds stay within float64).
    UnstableStepError
        Euler-Maruyama with gamma0 dt >= 2.
    MemoryError
        Stored positions or the every-window TAMSD's rings that would not fit.
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    threads = _threads(threads)
    mass = _positive("mass", mass)
    estimator = _estimator_code(tamsd_estimator)
    if dim not in (1, 2, 3):
        raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
    gamma0, D0, dt, t_stop = (
        _positive(k, v) for k, v in (("gamma0", gamma0), ("D0", D0), ("dt", dt), ("t_stop", t_stop))
    )
    tau0 = float(tau0)
    if not tau0 > 0:
        raise ValueError(f"tau0 must be positive (inf for the Langevin model), got {tau0}")
    if model is None:
        model = "langevin" if math.isinf(tau0) else "udsbm"
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if model == "udsbm" and math.isinf(tau0):
        raise ValueError("UDSBM needs a finite tau0")
    exponent = float(exponent)
    if not (exponent > 0 and math.isfinite(exponent)):
        raise ValueError(
            f"exponent must be positive and finite (UDSBM's (1 + t/tau0)^-exponent), got {exponent}"
        )
    if model == "langevin":
        if exponent != 1.0:
            raise ValueError(
                "exponent is UDSBM's (model='udsbm'); the Langevin model has constant "
                f"coefficients, got exponent={exponent}"
            )
        tau0 = math.inf
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    if scheme == "em" and gamma0 * dt >= 2.0:
        from .errors import UnstableStepError

        raise UnstableStepError(
            f"Euler-Maruyama diverges for gamma0*dt >= 2 (here {gamma0 * dt:.4g}); take "
            f"dt < {2 / gamma0:.4g} or scheme='exact', which is stable at any step",
            value=gamma0 * dt,
        )
    n_steps_f = t_stop / dt  # in float first: it may be past any int64, or infinite
    if not n_steps_f <= _core.SDE_MAX_STEPS:
        raise ValueError(
            f"t_stop / dt = {t_stop!r} / {dt!r} = {n_steps_f:.4g} steps; a run "
            f"takes at most 2**62 = {_core.SDE_MAX_STEPS:.4g}"
        )
    n_steps = round(n_steps_f)
    if n_steps < 1:
        raise ValueError("t_stop must be at least one step")

    # sample steps and lags are compared with n_steps as floats, before they become int64
    if sample_times is None:
        steps_f = np.minimum(np.rint(np.logspace(0, math.log10(n_steps), 60)), n_steps)
        steps_f = np.concatenate([[0], steps_f, [n_steps]])
    else:
        st = np.asarray(sample_times, dtype=np.float64).reshape(-1)
        if not np.all(np.isfinite(st)) or np.any(st < 0):
            raise ValueError("sample_times must be finite and >= 0")
        if np.any(np.diff(st) <= 0):
            raise ValueError("sample_times must be strictly increasing")
        steps_f = np.rint(st / dt)  # whole steps; times within one step merge
        if len(steps_f) and not steps_f[-1] <= n_steps:
            raise ValueError(f"sample_times reach past t_stop = {n_steps * dt}")
    steps = np.unique(steps_f).astype(np.int64)
    if tamsd_lags is None:
        lags = np.zeros(0, dtype=np.int64)
    else:
        lag_t = np.asarray(tamsd_lags, dtype=np.float64).reshape(-1)
        if np.any(np.diff(lag_t) <= 0):
            raise ValueError("tamsd_lags must be strictly increasing")
        lags = _lag_steps(lag_t, dt, n_steps, "tamsd_lags")
        if np.any(np.diff(lags) == 0):  # two lags within 1e-9 of one step
            same = int(np.argmin(np.diff(lags)))
            raise ValueError(
                f"tamsd_lags {float(lag_t[same])!r} and {float(lag_t[same + 1])!r} are the "
                f"same number of steps of dt = {shown(dt)}: give each lag once"
            )

    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    key_seq, vel_seq = ss.spawn(2)
    key = int(key_seq.generate_state(1, dtype=np.uint64)[0])
    rng = np.random.default_rng(vel_seq)
    thermal = D0 * gamma0  # T0/m (2.55)
    if initial == "thermal":
        v0_sq = thermal
        v = rng.normal(scale=math.sqrt(v0_sq), size=(n, dim))
    elif initial == "udsbm":
        if model != "udsbm":
            raise ValueError("initial='udsbm' is App. C's initial speed of the UDSBM model")
        if exponent != 1.0:
            raise ValueError(
                "initial='udsbm' is App. C's initial speed for exponent 1; with exponent "
                f"{exponent} start 'thermal' or 'fixed' (theory.msd_powerlaw_udsbm takes any "
                "initial speed)"
            )
        from .theory import udsbm_v0_sq

        v0_sq = udsbm_v0_sq(D0=D0, gamma0=gamma0, tau0=tau0)
        v = rng.normal(scale=math.sqrt(v0_sq), size=(n, dim))
    elif initial == "fixed":
        s = math.sqrt(dim * thermal) if speed is None else _positive("speed", speed)
        g = rng.normal(size=(n, dim))
        g /= np.maximum(np.linalg.norm(g, axis=1), 1e-300)[:, None]
        v = s * g
        v0_sq = s * s / dim
    else:
        raise ValueError(f"initial must be one of {INITIAL}, got {initial!r}")
    if initial == "fixed" and speed is not None:
        speed_name, rms = "speed", s
    else:
        speed_name, rms = (
            f"the initial rms speed sqrt(dim v0_sq) ({initial})",
            math.sqrt(dim * v0_sq),
        )
    _check_scales(gamma0, D0, dt, t_stop, tau0, exponent, mass, speed_name, rms)

    T, L = len(steps), len(lags)
    if store_positions:
        need = 8.0 * T * n * dim
        if need > 8e9:
            raise MemoryError(
                f"storing positions needs {need / 2**30:.1f} GiB; sample fewer "
                "times or leave store_positions off (the MSD is accumulated anyway)"
            )
    x = np.zeros((n, dim))
    x2 = np.zeros((T, dim))
    v2 = np.zeros((T, dim))
    positions = np.zeros((T, n, dim)) if store_positions else None
    tamsd_sum = np.zeros((n, L))
    model_code = MODELS.index(model)
    scheme_code = SCHEMES.index(scheme)
    # Chunk by work: blocks of particles over all steps while a particle's run is short,
    # else one particle at a time over segments of its steps (the C core carries such a
    # particle's past positions from segment to segment in `ring`).  The same numbers to
    # the bit either way.
    # A call of blocks of particles takes `threads` times the work (the threads share it);
    # a segment of one particle's steps runs on one thread.
    work = max(1, _CHUNK_PARTICLE_STEPS)
    steps_per_call = min(n_steps, work)
    per_call = max(1, work * threads // n_steps) if steps_per_call == n_steps else 1
    # whole blocks of particles for every thread (the C core gives each thread whole blocks
    # of SDE_BLOCK, the ensemble sums' unit): 100 particles on 2 threads would be 64 + 36
    for unit in (_core.SDE_BLOCK * threads, _core.SDE_BLOCK):
        if per_call >= unit:
            per_call -= per_call % unit
            break
    ring_size = _core.sde_ring_size(dim, lags, estimator)
    if 8.0 * ring_size * threads > 2**31:
        raise MemoryError(
            f"tamsd_estimator={tamsd_estimator!r} keeps {8.0 * ring_size / 2**30:.1f} GiB of "
            f"past positions per thread for lags up to {int(lags[-1])} steps; take "
            "tamsd_estimator='strided' (a few kB) or fewer threads"
        )
    ring = np.zeros(ring_size)
    carry = np.zeros((2, T, dim))  # the ensemble sums of a block of particles left open
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=n * n_steps, unit="particle-step", unit_scale=True, leave=False)
    try:
        for first in range(0, n, per_call):
            xs = np.ascontiguousarray(x[first : first + per_call])
            vs = np.ascontiguousarray(v[first : first + per_call])
            for step_from in range(0, n_steps, steps_per_call):
                step_to = min(step_from + steps_per_call, n_steps)
                _core.sde_run(
                    dim,
                    model_code,
                    scheme_code,
                    gamma0,
                    D0,
                    tau0,
                    dt,
                    key,
                    n,
                    first,
                    step_from,
                    step_to,
                    n_steps,
                    xs,
                    vs,
                    steps,
                    x2,
                    v2,
                    positions,
                    lags,
                    tamsd_sum,
                    ring,
                    carry,
                    threads,
                    estimator,
                    exponent=exponent,
                )
                if bar is not None:
                    bar.update(len(xs) * (step_to - step_from))
            x[first : first + len(xs)] = xs
            v[first : first + len(vs)] = vs
    finally:
        if bar is not None:
            bar.close()

    strides = np.array([_core.sde_lag_stride(int(k), estimator) for k in lags], dtype=np.int64)
    windows = (n_steps - lags) // np.maximum(strides, 1) + 1
    per_particle = tamsd_sum / windows if L else tamsd_sum
    return LangevinResult(
        times=(steps * dt).astype(np.float64, copy=False),
        steps=steps,
        msd_total=x2.sum(1) / n,
        msd_per_dimension=x2 / n,
        v2=v2.sum(1) / n,
        tamsd_lags=(lags * dt).astype(np.float64, copy=False),
        tamsd_mean=per_particle.mean(0) if L else np.zeros(0),
        tamsd_per_particle=per_particle,
        positions=positions,
        final_positions=x,
        final_velocities=v,
        model=model,
        scheme=scheme,
        tamsd_estimator=tamsd_estimator,
        gamma0=gamma0,
        D0=D0,
        tau0=tau0,
        dt=dt,
        n=n,
        dim=dim,
        t_stop=n_steps * dt,
        v0_sq=v0_sq,
        exponent=exponent if model == "udsbm" else 1.0,
        initial=initial,
        mass=mass,
    )


def coefficients_from_scene(scene: Scene) -> LangevinCoefficients:
    """gamma0, D0 and tau0 of the model that stands for a Scene's gas.

    A number restitution xi: exactly as the thesis derives them (2.45, 2.52, 2.55), from
    its N, radius, mass, xi, box and temperature (tau0 infinite for xi = 1).  A
    ``restitution.Viscoelastic`` law: the power-law UDSBM's (``exponent`` 5/6, see
    ``from_scene``), gamma0 and D0 the same Enskog values at xi = 1 and tau0 the
    viscoelastic cooling time tau0' (``theory.viscoelastic_langevin_coefficients``).

    Parameters
    ----------
    scene : Scene
        Its mean radius and mass are used (the theory is one of equal particles).

    Returns
    -------
    LangevinCoefficients

    Raises
    ------
    TypeError
        If the scene's pair restitution is a law with no Langevin counterpart (e.g. a
        ``TabulatedRestitution``): only a number and ``Viscoelastic`` have one.
    """
    return _scene_model(scene)[0]


def _scene_model(scene: Scene) -> tuple[LangevinCoefficients, float]:
    """The coefficients and the UDSBM exponent (1 or 5/6) of a Scene's gas."""
    from . import theory
    from .restitution import RestitutionLaw, Viscoelastic

    radius = float(np.mean(scene.radii))
    mass = float(np.mean(scene.masses))
    law = scene.restitution
    if isinstance(law, Viscoelastic):
        c = theory.viscoelastic_langevin_coefficients(
            n=scene.n,
            radius=radius,
            volume=scene.volume,
            a_kappa=law,
            temperature0=scene.temperature,
            mass=mass,
            dim=scene.dim,
        )
        return c, VISCOELASTIC_EXPONENT
    if isinstance(law, RestitutionLaw):
        raise TypeError(
            f"no Langevin model stands for the restitution law {type(law).__name__}: "
            "from_scene and coefficients_from_scene support a number xi (Langevin or UDSBM) "
            "and granular.Viscoelastic (power-law UDSBM, exponent 5/6)"
        )
    c = theory.langevin_coefficients(
        n=scene.n,
        radius=radius,
        volume=scene.volume,
        restitution=law,
        temperature0=scene.temperature,
        mass=mass,
        dim=scene.dim,
    )
    return c, 1.0


# UDSBM's exponent for a viscoelastic gas: T ~ t^(-5/3), D ~ t^(-5/6) (theory.viscoelastic_*)
VISCOELASTIC_EXPONENT = 5.0 / 6.0


def from_scene(
    scene: Scene,
    *,
    dt: float,
    t_stop: float,
    scheme: str = "exact",
    n: int | None = None,
    **kwargs: Any,
) -> LangevinResult:
    """A Langevin run (xi = 1), UDSBM run (xi < 1) or power-law UDSBM run (exponent 5/6,
    a ``Viscoelastic`` restitution) with the scene's coefficients
    (``coefficients_from_scene``), so it can be set beside an EDMD run of the same scene.
    ``n`` defaults to the scene's N and ``mass`` to its mean mass (so that
    ``result.temperature`` is the scene's temperature at t = 0, an energy); other
    arguments as in ``run``.

    Raises
    ------
    TypeError
        For a restitution law other than ``Viscoelastic`` (see ``coefficients_from_scene``).
    """
    c, exponent = _scene_model(scene)
    model = "langevin" if math.isinf(c.tau0) else "udsbm"
    if model == "udsbm":
        kwargs.setdefault("exponent", exponent)
    kwargs.setdefault("mass", float(np.mean(scene.masses)))
    return run(
        scene.n if n is None else n,
        gamma0=c.gamma0,
        D0=c.D0,
        tau0=c.tau0,
        model=model,
        scheme=scheme,
        dt=dt,
        t_stop=t_stop,
        dim=scene.dim,
        **kwargs,
    )
