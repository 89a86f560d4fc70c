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

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _langevin_run
from ._deprecation import _MethodWithArrayShim, deprecated
from ._langevin_run import INITIAL as INITIAL
from ._langevin_run import MODELS as MODELS
from ._langevin_run import SCHEMES as SCHEMES
from ._langevin_run import TAMSD_ESTIMATORS as TAMSD_ESTIMATORS
from ._langevin_run import (
    _check_forces,
    _check_scales,
    _checked,
    _estimator_code,
    _initial_speed,
    _initial_state,
    _integrate,
    _lag_steps,
    _new_sums,
    _sample_steps,
    _tamsd_lag_steps,
)
from ._langevin_run import _threads as _threads  # the CLI's benchmark asks it for the cores
from ._results import _lag_indices, _no_lags, ergodicity_breaking, readonly
from .errors import shown

if TYPE_CHECKING:  # for the hints only: scene imports nothing from here, but stay light
    from .scene import Scene
    from .theory import LangevinCoefficients


# Work per call into C, in particle-steps: a block of particles over the whole run, or one
# particle over a segment of its steps -- at most ~0.6 s (exact UDSBM, ~60 ns a step),
# so Ctrl-C is prompt however few the particles and many the steps.
_CHUNK_PARTICLE_STEPS = 10_000_000


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
    gravity, trap_stiffness, trap_centre : (d,) the external force's g, k and c (zeros
        without force; ``run``), None on results made before forces existed
    initial_positions : (N, d) the starts in the lab frame (the origin, or in a trap the
        stationary draw of ``run``); positions and the MSD are displacements from them
    """

    @property
    def has_force(self) -> bool:
        """Whether an external force acted (a gravity or a trap stiffness not zero)."""
        return any(
            a is not None and bool(np.any(a != 0)) for a in (self.gravity, self.trap_stiffness)
        )

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
    gravity: NDArray[np.float64] | None = None
    trap_stiffness: NDArray[np.float64] | None = None
    trap_centre: NDArray[np.float64] | None = None
    initial_positions: NDArray[np.float64] | None = None

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
        use goes in granular 0.3.0."""
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
        that use goes in granular 0.3.0."""
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
        particles), which warns (FutureWarning) until granular 0.3.0."""
        if self.mass != 1.0:
            deprecated(
                f"LangevinResult.temperature is an energy now, mass * v2 / dim with this "
                f"run's mass {shown(self.mass)}; the temperature per unit mass it used to be",
                "that is result.v2 / result.dim",
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
        for name in ("gravity", "trap_stiffness", "trap_centre", "initial_positions"):
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        return out

    def theory_msd(
        self,
        t: float | NDArray[np.float64] | None = None,
    ) -> float | NDArray[np.float64]:
        """The analytic ensemble MSD of this model from ``granular.theory`` (with this
        run's initial speed) at the sample times or at t; with an external force axis by
        axis from ``theory.trap`` (``msd_trap``, ``gravity_mean_displacement``)."""
        from . import theory

        t = self.times if t is None else t
        if self.has_force:
            return self._theory_msd_forced(t)
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

    def _theory_msd_forced(self, t: float | NDArray[np.float64]) -> float | NDArray[np.float64]:
        """The MSD under this run's forces, axis by axis (theory.trap): a trapped axis from
        its stationary start (``initial="thermal"``) or from the origin with this run's
        v0_sq; a free axis as the free model's plus the squared drift under gravity."""
        from . import theory
        from .theory import trap

        assert self.gravity is not None and self.trap_stiffness is not None
        assert self.trap_centre is not None
        total: float | NDArray[np.float64] = 0.0
        for a in range(self.dim):
            g, w = float(self.gravity[a]), float(self.trap_stiffness[a]) / self.mass
            if w > 0 and self.initial == "thermal":
                e11 = trap._propagator(t, self.gamma0, w)[0]
                total = total + 2.0 * self.D0 * self.gamma0 / w * (1.0 - e11)
            elif w > 0:  # from the origin: offset from the balance point c + g/w
                offset = -(float(self.trap_centre[a]) + g / w)
                total = total + trap._msd_trap_axis(
                    t, D0=self.D0, gamma0=self.gamma0, w=w, v0_sq=self.v0_sq, offset=offset
                )
            else:
                free = theory.msd_langevin(
                    t, D0=self.D0, gamma0=self.gamma0, dim=2, v0_sq=self.v0_sq
                )
                drift = theory.gravity_mean_displacement(t, gravity=g, gamma0=self.gamma0)
                total = total + free / 2 + drift * drift
        return total

    def _refuse_unless_stationary(self, what: str) -> None:
        """ValueError unless this forced run is stationary from its start."""
        assert self.gravity is not None and self.trap_stiffness is not None
        falls = bool(np.any((self.trap_stiffness == 0) & (self.gravity != 0)))
        if self.initial != "thermal" or falls:
            raise ValueError(
                f"{what} under an external force is known here for a stationary run only "
                "(initial='thermal', gravity only along trapped axes); this run started "
                f"with initial={self.initial!r}"
                + (" and falls freely along an untrapped axis" if falls else "")
            )

    def theory_tamsd(self, lags: ArrayLike | None = None) -> NDArray[np.float64]:
        """The expected time-averaged MSD of this run at its lags (or at ``lags``), as the
        engine measures it: see ``theory_tamsd``.  Under an external force: for a stationary
        run (``initial="thermal"``, no gravity along an untrapped axis) the MSD at the lag
        (``theory_msd``), since the increments are stationary; any other forced run raises
        ValueError."""
        if lags is None and len(self.tamsd_lags) == 0:
            raise _no_lags()
        if self.has_force:
            self._refuse_unless_stationary("theory_tamsd")
            lag_t = np.asarray(self.tamsd_lags if lags is None else lags, dtype=np.float64)
            return np.asarray(self._theory_msd_forced(lag_t), dtype=np.float64)
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
        return ergodicity_breaking(self, lags, lag_samples, particles)

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

        if self.has_force:
            raise ValueError(
                "theory_ergodicity_breaking is the free Langevin/UDSBM model's; under an "
                "external force measure it (ergodicity_breaking)"
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
            f"lags={len(self.tamsd_lags)}{self._force_repr()})"
        )

    def _force_repr(self) -> str:
        """The external force for ``repr``: empty without one."""
        if not self.has_force:
            return ""

        def vec(a: NDArray[np.float64] | None) -> str:
            return "(" + ", ".join(f"{float(x):g}" for x in np.asarray(a)) + ")"

        return (
            f", gravity={vec(self.gravity)}, trap_stiffness={vec(self.trap_stiffness)}, "
            f"trap_centre={vec(self.trap_centre)}"
        )


def _result(
    p: _langevin_run._Run,
    initial: str,
    steps: NDArray[np.int64],
    lags: NDArray[np.int64],
    sums: _langevin_run._Sums,
    x: NDArray[np.float64],
    v: NDArray[np.float64],
    v0_sq: float,
    x0: NDArray[np.float64],
) -> LangevinResult:
    """The result of a run: the engine's sums divided into means (the TAMSD by each lag's
    number of windows), with what the run was given."""
    f = p.forces
    zero = (0.0,) * p.dim
    n, L = p.n, len(lags)
    estimator = _estimator_code(p.tamsd_estimator)
    strides = np.array([_core.sde_lag_stride(int(k), estimator) for k in lags], dtype=np.int64)
    windows = (p.n_steps - lags) // np.maximum(strides, 1) + 1
    per_particle = sums.tamsd / windows if L else sums.tamsd
    return LangevinResult(
        times=(steps * p.dt).astype(np.float64, copy=False),
        steps=steps,
        msd_total=sums.x2.sum(1) / n,
        msd_per_dimension=sums.x2 / n,
        v2=sums.v2.sum(1) / n,
        tamsd_lags=(lags * p.dt).astype(np.float64, copy=False),
        tamsd_mean=per_particle.mean(0) if L else np.zeros(0),
        tamsd_per_particle=per_particle,
        positions=sums.positions,
        final_positions=x,
        final_velocities=v,
        model=p.model,
        scheme=p.scheme,
        tamsd_estimator=p.tamsd_estimator,
        gamma0=p.gamma0,
        D0=p.D0,
        tau0=p.tau0,
        dt=p.dt,
        n=n,
        dim=p.dim,
        t_stop=p.n_steps * p.dt,
        v0_sq=v0_sq,
        exponent=p.exponent if p.model == "udsbm" else 1.0,
        initial=initial,
        mass=p.mass,
        gravity=np.array(f.gravity if f else zero),
        trap_stiffness=np.array(f.trap_stiffness if f else zero),
        trap_centre=np.array(f.trap_centre if f else zero),
        initial_positions=x0,
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
    gravity: ArrayLike | None = None,
    trap_stiffness: ArrayLike | None = None,
    trap_centre: ArrayLike | None = None,
) -> LangevinResult:
    """Integrate N independent particles from a common start at the origin (in a trap,
    from its stationary density: ``initial``).

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
    gravity : length-dim vector g, a uniform acceleration (force m g on every particle),
        L/time^2; the Langevin model only (docs/langevin_forces.md)
    trap_stiffness : k of a harmonic trap, potential k (X - c)^2 / 2 per axis, force per
        length (m/time^2): one number for every axis or one per axis, each >= 0 (0: no
        trap along that axis); the Langevin model only.  With a trap, ``initial="thermal"``
        also draws each trapped axis' start from its stationary (Boltzmann) density,
        Gaussian about c + m g / k with variance T / k (T = m D0 gamma0), so the run is
        stationary from t = 0 and its MSD is ``theory.msd_trap``; the other starts begin
        at the origin.  ``result.initial_positions`` holds the starts; the MSD, positions
        and final_positions are displacements from them
    trap_centre : length-dim vector c, the trap's centre (default the origin)

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
        Euler-Maruyama with gamma0 dt >= 2, or in a trap with (k/m) dt >= gamma0 along an
        axis (its stability limit there).
    MemoryError
        Stored positions or the every-window TAMSD's rings that would not fit.
    """
    p = _checked(
        n,
        gamma0=gamma0,
        D0=D0,
        dt=dt,
        t_stop=t_stop,
        tau0=tau0,
        model=model,
        exponent=exponent,
        scheme=scheme,
        dim=dim,
        threads=threads,
        mass=mass,
        tamsd_estimator=tamsd_estimator,
        gravity=gravity,
        trap_stiffness=trap_stiffness,
        trap_centre=trap_centre,
    )
    steps = _sample_steps(sample_times, p.dt, p.n_steps)
    lags = _tamsd_lag_steps(tamsd_lags, p.dt, p.n_steps)
    key, x, v, v0_sq, x0 = _initial_state(p, initial, speed, seed)
    _check_scales(p, *_initial_speed(initial, speed, p.dim, v0_sq))
    _check_forces(p)
    sums = _new_sums(p, steps, lags, store_positions)
    _integrate(p, key, x, v, steps, lags, sums, progress, work=_CHUNK_PARTICLE_STEPS, x0=x0)
    return _result(p, initial, steps, lags, sums, x, v, v0_sq, x0)


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
