"""The steps of ``granular.langevin.run``, one job each: check and normalise the arguments
(``_checked``, ``_sample_steps``, ``_tamsd_lag_steps``, ``_check_scales``), draw the start
(``_initial_state``), allocate what the engine accumulates into (``_new_sums``) and step the
particles in chunks through the C engine (``_integrate``, every argument by name); the
result is made in granular.langevin (``_result``).  The lag grid's checks (``_lag_steps``)
and the names of the models, schemes and estimators are here too, where the run needs
them first; ``granular.langevin`` shows them to users."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._params import check_positive
from ._scales import SCALE_HI, SCALE_LO, check_range
from .errors import shown

MODELS = ("langevin", "udsbm")
# the TAMSD's windows (csrc/tamsd.h): "strided" starts a lag's windows every power of
# two <= max(1, lag/4) steps, "all" at every step
TAMSD_ESTIMATORS = ("strided", "all")
SCHEMES = ("em", "exact")
INITIAL = ("thermal", "udsbm", "fixed")


def _estimator_code(name: str) -> int:
    if name not in TAMSD_ESTIMATORS:
        raise ValueError(f"tamsd_estimator must be one of {TAMSD_ESTIMATORS}, got {name!r}")
    return TAMSD_ESTIMATORS.index(name)


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


@dataclass(frozen=True)
class _Run:
    """``run``'s arguments checked and normalised: what each of its steps reads."""

    n: int
    gamma0: float
    D0: float
    tau0: float  # inf for the Langevin model
    dt: float
    t_stop: float  # as given; the run ends at n_steps * dt
    n_steps: int
    model: str
    exponent: float  # 1 for the Langevin model
    scheme: str
    dim: int
    threads: int
    mass: float
    tamsd_estimator: str
    forces: _Forces | None = None  # external forces (Langevin model only), or None


@dataclass(frozen=True)
class _Forces:
    """External forces of a Langevin run, checked: per axis the uniform acceleration g
    (``gravity``), the trap's stiffness k and centre c; the force on a particle is
    m g - k (X - c)."""

    gravity: tuple[float, ...]
    trap_stiffness: tuple[float, ...]
    trap_centre: tuple[float, ...]

    def per_mass(self, mass: float) -> NDArray[np.float64]:
        """w = k / m per axis, the engine's stiffness."""
        return np.array(self.trap_stiffness, dtype=np.float64) / mass


def _vector(name: str, value: ArrayLike, dim: int, meaning: str) -> tuple[float, ...]:
    """A length-``dim`` vector of finite floats, or ValueError naming ``name``."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} ({meaning}) must be numbers, got {value!r}") from None
    if a.shape != (dim,):
        raise ValueError(
            f"{name} ({meaning}) must have dim = {dim} components, got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} ({meaning}) must be finite, got {shown(a)}")
    return tuple(float(x) for x in a)


def _forces(
    gravity: ArrayLike | None,
    trap_stiffness: ArrayLike | None,
    trap_centre: ArrayLike | None,
    *,
    dim: int,
    model: str,
) -> _Forces | None:
    """``run``'s force arguments checked (None for none of them): ``gravity`` and
    ``trap_centre`` length-dim vectors, ``trap_stiffness`` one number for every axis or
    one per axis, each >= 0 (0: no trap along that axis)."""
    if gravity is None and trap_stiffness is None and trap_centre is None:
        return None
    if model != "langevin":
        raise ValueError(
            "external forces (gravity, trap_stiffness) are in the Langevin model only "
            f"(tau0 = inf), got model={model!r}: UDSBM's time-dependent temperature has no "
            "closed-form step in a trap here"
        )
    g = (0.0,) * dim if gravity is None else _vector("gravity", gravity, dim, "an acceleration")
    if trap_centre is not None and trap_stiffness is None:
        raise ValueError("trap_centre is the centre of a trap: give trap_stiffness too")
    k: tuple[float, ...] = (0.0,) * dim
    if trap_stiffness is not None:
        meaning = "the trap's stiffness per axis, force per length"
        try:
            ks = np.asarray(trap_stiffness, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(
                f"trap_stiffness ({meaning}) must be a number or dim numbers, got "
                f"{trap_stiffness!r}"
            ) from None
        k = _vector("trap_stiffness", np.full(dim, float(ks)) if ks.ndim == 0 else ks, dim, meaning)
        if min(k) < 0:
            raise ValueError(
                f"trap_stiffness must be >= 0 along every axis (0: no trap along it), got "
                f"{shown(np.array(k))}"
            )
    c = (
        (0.0,) * dim
        if trap_centre is None
        else _vector("trap_centre", trap_centre, dim, "the trap's centre")
    )
    return _Forces(gravity=g, trap_stiffness=k, trap_centre=c)


def _check_forces(p: _Run) -> None:
    """The forces' scales and Euler-Maruyama's stability limit in a trap.

    Per axis EM's map on the mean is [[1, dt], [-w dt, 1 - gamma0 dt]], w = k/m; with
    gamma0 dt < 2 its eigenvalues lie inside the unit circle iff w dt < gamma0 (Jury's
    conditions; docs/langevin_forces.md): beyond, the variance grows without bound, and
    the run is refused (UnstableStepError), as gamma0 dt >= 2 is.  The exact scheme is
    stable at any step."""
    f = p.forces
    if f is None:
        return
    lo, hi = SCALE_LO, SCALE_HI
    w = f.per_mass(p.mass)
    arithmetic = "the Langevin arithmetic (displacements, squared and summed)"
    for a in range(p.dim):
        if w[a] > 0:
            check_range(
                f"trap_stiffness / mass along axis {a}",
                float(w[a]),
                lo * lo,
                hi * hi,
                arithmetic,
                "a squared trap frequency k/m nearer the squared rates gamma0^2",
            )
        check_range(
            f"|gravity| t_stop^2 along axis {a} (the fall's length)",
            abs(f.gravity[a]) * p.t_stop * p.t_stop,
            0.0,
            hi,
            arithmetic,
            "a smaller gravity or a shorter t_stop",
        )
        check_range(f"|trap_centre| along axis {a}", abs(f.trap_centre[a]), 0.0, hi, arithmetic, "")
    if p.scheme == "em" and np.any(w * p.dt >= p.gamma0):
        from .errors import UnstableStepError

        a = int(np.argmax(w * p.dt / p.gamma0))
        raise UnstableStepError(
            f"Euler-Maruyama in a harmonic trap diverges for (k/m) dt >= gamma0: along axis "
            f"{a} k/m = {shown(float(w[a]))}, dt = {shown(p.dt)}, (k/m) dt / gamma0 = "
            f"{w[a] * p.dt / p.gamma0:.4g}; take dt < gamma0 m / k = "
            f"{p.gamma0 / w[a]:.4g} or scheme='exact', which is stable at any step",
            value=float(w[a] * p.dt / p.gamma0),
        )


def _checked(
    n: int,
    *,
    gamma0: float,
    D0: float,
    dt: float,
    t_stop: float,
    tau0: float,
    model: str | None,
    exponent: float,
    scheme: str,
    dim: int,
    threads: int | None,
    mass: float,
    tamsd_estimator: str,
    gravity: ArrayLike | None = None,
    trap_stiffness: ArrayLike | None = None,
    trap_centre: ArrayLike | None = None,
) -> _Run:
    """``run``'s scalar arguments, each checked in turn (the first out of its range raises,
    by name) and normalised: floats, the model chosen from tau0, tau0 infinite for the
    Langevin model, t_stop as a whole number of steps."""
    n = int(n)
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    n_threads = _threads(threads)
    mass = check_positive("mass", mass)
    _estimator_code(tamsd_estimator)
    if dim not in (1, 2, 3):
        raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
    gamma0, D0 = check_positive("gamma0", gamma0), check_positive("D0", D0)
    dt = check_positive("dt", dt, "the time step")
    t_stop = check_positive("t_stop", t_stop, "the time the run ends at")
    tau0 = float(tau0)
    if not tau0 > 0:
        raise ValueError(f"tau0 must be positive (inf for the Langevin model), got {tau0}")
    if model is None:
        model = "langevin" if math.isinf(tau0) else "udsbm"
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")
    if model == "udsbm" and math.isinf(tau0):
        raise ValueError("UDSBM needs a finite tau0")
    exponent = check_positive("exponent", exponent)
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
    return _Run(
        n=n,
        gamma0=gamma0,
        D0=D0,
        tau0=tau0,
        dt=dt,
        t_stop=t_stop,
        n_steps=n_steps,
        model=model,
        exponent=exponent,
        scheme=scheme,
        dim=dim,
        threads=n_threads,
        mass=mass,
        tamsd_estimator=tamsd_estimator,
        forces=_forces(gravity, trap_stiffness, trap_centre, dim=dim, model=model),
    )


# Sample steps and lags are compared with n_steps as floats, before they become int64.


def _sample_steps(sample_times: ArrayLike | None, dt: float, n_steps: int) -> NDArray[np.int64]:
    """The steps at which the ensemble MSD is sampled: ``sample_times`` rounded to whole
    steps, once each, or by default 0, 60 log-spaced steps and the last."""
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
    return np.unique(steps_f).astype(np.int64)


def _tamsd_lag_steps(tamsd_lags: ArrayLike | None, dt: float, n_steps: int) -> NDArray[np.int64]:
    """The TAMSD's lags in steps (none for ``tamsd_lags=None``): increasing, each a whole
    number of steps and a different one."""
    if tamsd_lags is None:
        return np.zeros(0, dtype=np.int64)
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
    return lags


def _initial_positions(p: _Run, initial: str, rng: np.random.Generator) -> NDArray[np.float64]:
    """(N, d) starting positions in the lab frame: the origin, but for a thermal start in a
    trap, where each trapped axis starts in its stationary (Boltzmann) density, Gaussian
    about the force's balance c + g m / k with variance T / k = D0 gamma0 m / k, so that the
    run is stationary from the start.  Drawn after the velocities, from their stream, so
    that the velocities are those of a run without force."""
    x0 = np.zeros((p.n, p.dim))
    f = p.forces
    if f is None or initial != "thermal":
        return x0
    w = f.per_mass(p.mass)
    for a in np.flatnonzero(w > 0):
        mean = f.trap_centre[a] + f.gravity[a] / w[a]
        x0[:, a] = mean + math.sqrt(p.D0 * p.gamma0 / w[a]) * rng.normal(size=p.n)
    return x0


def _initial_state(
    p: _Run, initial: str, speed: float | None, seed: Any
) -> tuple[int, NDArray[np.float64], NDArray[np.float64], float, NDArray[np.float64]]:
    """The engine's noise key, and the start: (N, d) displacements from the start (zero),
    (N, d) velocities drawn as ``initial`` says, their mean square per component v0_sq,
    and the (N, d) starting positions in the lab frame (``_initial_positions``).
    ``seed`` gives two independent streams, the key and the velocities'."""
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    key_seq, vel_seq = ss.spawn(2)
    key = int(key_seq.generate_state(1, dtype=np.uint64)[0])
    rng = np.random.default_rng(vel_seq)
    n, dim = p.n, p.dim
    thermal = p.D0 * p.gamma0  # T0/m (2.55)
    if initial == "thermal":
        v0_sq = thermal
        v = rng.normal(scale=math.sqrt(v0_sq), size=(n, dim))
    elif initial == "udsbm":
        if p.model != "udsbm":
            raise ValueError("initial='udsbm' is App. C's initial speed of the UDSBM model")
        if p.exponent != 1.0:
            raise ValueError(
                "initial='udsbm' is App. C's initial speed for exponent 1; with exponent "
                f"{p.exponent} start 'thermal' or 'fixed' (theory.msd_powerlaw_udsbm takes any "
                "initial speed)"
            )
        from .theory import udsbm_v0_sq

        v0_sq = udsbm_v0_sq(D0=p.D0, gamma0=p.gamma0, tau0=p.tau0)
        v = rng.normal(scale=math.sqrt(v0_sq), size=(n, dim))
    elif initial == "fixed":
        s = (
            math.sqrt(dim * thermal)
            if speed is None
            else check_positive("speed", speed, "every particle's initial speed")
        )
        g = rng.normal(size=(n, dim))
        g /= np.maximum(np.linalg.norm(g, axis=1), 1e-300)[:, None]
        v = s * g
        v0_sq = s * s / dim
    else:
        raise ValueError(f"initial must be one of {INITIAL}, got {initial!r}")
    # the start in the lab frame, drawn after the velocities
    return key, np.zeros((n, dim)), v, v0_sq, _initial_positions(p, initial, rng)


def _initial_speed(initial: str, speed: float | None, dim: int, v0_sq: float) -> tuple[str, float]:
    """The initial speed as ``_check_scales`` bounds it, with the name it is refused by:
    ``speed`` as given, else the rms speed of the start."""
    if initial == "fixed" and speed is not None:
        return "speed", float(speed)
    return f"the initial rms speed sqrt(dim v0_sq) ({initial})", math.sqrt(dim * v0_sq)


def _check_scales(p: _Run, speed_name: str, speed: float) -> None:
    """Refuse a run's coefficients whose squares and products would leave float64 over the run,
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
    gamma0, D0, dt, t_stop, tau0 = p.gamma0, p.D0, p.dt, p.t_stop, p.tau0
    exponent, mass = p.exponent, p.mass
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


@dataclass
class _Sums:
    """What the engine accumulates into, over all calls: the sums over particles of the
    squared displacements and velocities at the sample steps, the positions there (or
    None), each particle's TAMSD sums over windows, and the state one call leaves to the
    next (``ring``: a particle's past positions; ``carry``: a block's open sums)."""

    x2: NDArray[np.float64]  # (T, d)
    v2: NDArray[np.float64]  # (T, d)
    positions: NDArray[np.float64] | None  # (T, N, d)
    tamsd: NDArray[np.float64]  # (N, L)
    ring: NDArray[np.float64]
    carry: NDArray[np.float64]  # (2, T, d)


def _new_sums(
    p: _Run, steps: NDArray[np.int64], lags: NDArray[np.int64], store_positions: bool
) -> _Sums:
    """The engine's accumulators, zeroed, after refusing those that would not fit."""
    T, L, n, dim = len(steps), len(lags), p.n, p.dim
    if store_positions:
        need = 8.0 * T * n * dim
        if need > 8e9:
            raise MemoryError(
                f"storing positions needs {need / 2**30:.1f} GiB; sample fewer "
                "times or leave store_positions off (the MSD is accumulated anyway)"
            )
    ring_size = _core.sde_ring_size(dim, lags, _estimator_code(p.tamsd_estimator))
    if 8.0 * ring_size * p.threads > 2**31:
        raise MemoryError(
            f"tamsd_estimator={p.tamsd_estimator!r} keeps {8.0 * ring_size / 2**30:.1f} GiB of "
            f"past positions per thread for lags up to {int(lags[-1])} steps; take "
            "tamsd_estimator='strided' (a few kB) or fewer threads"
        )
    return _Sums(
        x2=np.zeros((T, dim)),
        v2=np.zeros((T, dim)),
        positions=np.zeros((T, n, dim)) if store_positions else None,
        tamsd=np.zeros((n, L)),
        ring=np.zeros(ring_size),
        carry=np.zeros((2, T, dim)),
    )


def _chunks(n_steps: int, threads: int, work: int) -> tuple[int, int]:
    """Particles and steps per call into C, of about ``work`` particle-steps each.

    Blocks of particles over all steps while a particle's run is short, else one particle
    at a time over segments of its steps (the C core carries such a particle's past
    positions from segment to segment in ``ring``).  The same numbers to the bit either
    way.  A call of blocks of particles takes ``threads`` times the work (the threads share
    it); a segment of one particle's steps runs on one thread."""
    work = max(1, work)
    steps_per_call = min(n_steps, work)
    per_call = max(1, work * threads // n_steps) if steps_per_call == n_steps else 1
    # whole blocks of particles for every thread (the C core gives each thread whole blocks
    # of SDE_BLOCK, the ensemble sums' unit): 100 particles on 2 threads would be 64 + 36
    for unit in (_core.SDE_BLOCK * threads, _core.SDE_BLOCK):
        if per_call >= unit:
            per_call -= per_call % unit
            break
    return per_call, steps_per_call


def _integrate(
    p: _Run,
    key: int,
    x: NDArray[np.float64],
    v: NDArray[np.float64],
    steps: NDArray[np.int64],
    lags: NDArray[np.int64],
    sums: _Sums,
    progress: bool,
    work: int,
    x0: NDArray[np.float64] | None = None,
) -> None:
    """Step every particle from ``x``, ``v`` (overwritten with the final state; ``x0`` the
    starts in the lab frame, which a force needs) to the last step, in calls of about
    ``work`` particle-steps (``_chunks``) so that Ctrl-C, which Python acts on between two
    calls into C, stops a run promptly; the progress bar is closed however the run ends."""
    per_call, steps_per_call = _chunks(p.n_steps, p.threads, work)
    model, scheme = MODELS.index(p.model), SCHEMES.index(p.scheme)
    force: dict[str, NDArray[np.float64]] = {}
    origin = None
    if p.forces is not None:  # the engine's g, k/m, and starts relative to the centre
        force = {
            "accel": np.array(p.forces.gravity, dtype=np.float64),
            "stiffness": p.forces.per_mass(p.mass),
        }
        origin = np.ascontiguousarray(x0 - np.array(p.forces.trap_centre))
    estimator = _estimator_code(p.tamsd_estimator)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=p.n * p.n_steps, unit="particle-step", unit_scale=True, leave=False)
    try:
        for first in range(0, p.n, per_call):
            xs = np.ascontiguousarray(x[first : first + per_call])
            vs = np.ascontiguousarray(v[first : first + per_call])
            if origin is not None:
                force["origin"] = np.ascontiguousarray(origin[first : first + per_call])
            for step_from in range(0, p.n_steps, steps_per_call):
                step_to = min(step_from + steps_per_call, p.n_steps)
                _core.sde_run(
                    dim=p.dim,
                    model=model,
                    scheme=scheme,
                    gamma0=p.gamma0,
                    D0=p.D0,
                    tau0=p.tau0,
                    dt=p.dt,
                    key=key,
                    n=p.n,
                    first=first,
                    step_from=step_from,
                    step_to=step_to,
                    n_steps=p.n_steps,
                    x=xs,
                    v=vs,
                    sample_steps=steps,
                    x2=sums.x2,
                    v2=sums.v2,
                    positions=sums.positions,
                    lags=lags,
                    tamsd=sums.tamsd,
                    ring=sums.ring,
                    carry=sums.carry,
                    threads=p.threads,
                    tamsd_estimator=estimator,
                    exponent=p.exponent,
                    **force,
                )
                if bar is not None:
                    bar.update(len(xs) * (step_to - step_from))
            x[first : first + len(xs)] = xs
            v[first : first + len(vs)] = vs
    finally:
        if bar is not None:
            bar.close()
