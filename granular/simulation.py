"""Simulation: the event-driven engine (EDMD) behind a small Python API."""

from __future__ import annotations

import contextlib
import math
import os
import threading
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _edmd, _shear, checkpoint
from . import restitution as _restitution
from ._edmd import check_memory as _check_memory
from ._rough import rough_keeps_energy
from ._scene_params import RUN_PARAMETERS, spin_shape
from .errors import (
    ClusteringWarning,
    FrozenGasError,
    GranularError,
    HeatedWallsError,
    InelasticCollapseError,
    NoProgressError,
)
from .scene import BIG_RATIO, Scene, frozen_energy, rotational_dim, rotational_energy
from .trajectory import Trajectory, _pressure_volume

_STOP_KEYS = ("collisions_per_particle", "kinetic_energy", "events")
_CHUNK = _edmd.CHUNK
_STORE = ("positions", "velocities", "angular_velocities")
_STORE_DEFAULT = ("positions", "velocities")
# What a sample records besides positions, velocities and momentum: the engine's counters
# at that instant.  One name each, shared by the engine's counters, the binding's sample
# buffers and Trajectory's attributes.
_COUNTED = (
    ("kinetic_energy", np.float64),
    ("pair_collisions", np.int64),
    ("wall_collisions", np.int64),
    ("virial", np.float64),
    ("wall_impulse", np.float64),
)
_LIST_SHELL = _edmd.LIST_SHELL  # see _edmd
# The stress tensor's parts a sample records with Simulation(stress=True), each (d, d):
# the cumulative collisional sum, the cumulative kinetic integral, the kinetic tensor now.
_TENSORS = ("stress_collisional", "kinetic_time_tensor", "kinetic_tensor")
# A vibrating wall's energy books a sample records (cumulative, as the counters'), with
# such a wall only: the work it did and the energy collisions dissipated.
_WALL_BOOKS = ("wall_work", "collision_loss")


class Simulation:
    """Event-driven molecular dynamics of a Scene.

    The engine keeps its state between calls, so ``run`` can be called again to continue.
    Particles fly straight between instantaneous collisions, so the dynamics are exact
    up to rounding; see the README for the algorithm and its cost.

    Parameters
    ----------
    scene : Scene
    cell_factor : float >= 1
        Cell width in largest diameters of the particles in the cell grid (a speed knob;
        the result does not depend on it beyond rounding).
    big_ratio : float >= 1
        Up to 16 particles wider than ``big_ratio`` times the median diameter (a large
        tracer) stay out of the cell grid, so that they do not make every cell as wide
        as they are; ``math.inf`` puts everyone in the grid.  A speed knob too.
    shell : "auto" or float >= 0
        Neighbour lists with a shell this many largest diameters thick instead of cell
        crossings (0), another speed knob: lists pay in dense 3D gases (packing fraction
        0.4 and up, 1.5-2x at 0.5) and cost elsewhere.  "auto" uses shell 0.25
        there, when no particle is big (see ``big_ratio``; lists keep none out), and
        cells otherwise.  A number must be 0 or at least 0.01; lists with a big particle
        are refused unless ``big_ratio=math.inf``.  ``stats["shell"]`` says which mode
        ran.
    stress : bool
        Keep the stress (pressure) tensor, kinetic plus collisional (see docs/stress.md):
        samples then carry its parts (``Trajectory.pressure_tensor``) and ``stats`` its
        average since the start.  Off by default: it costs some 100 instructions a
        collision, about a tenth of an event.
    """

    def __init__(
        self,
        scene: Scene,
        *,
        cell_factor: float = 1.0,
        big_ratio: float = BIG_RATIO,
        shell: str | float = "auto",
        stress: bool = False,
    ) -> None:
        if not isinstance(scene, Scene):
            raise TypeError(f"Simulation needs a granular.Scene, got {type(scene).__name__}")
        if not isinstance(stress, (bool, np.bool_)):
            from .errors import shown

            raise TypeError(f"stress must be True or False, got {shown(stress)}")
        stress = bool(stress)
        self._initial = scene
        self._engine = _edmd.build(scene, cell_factor, big_ratio, shell, stress)
        self._knobs: dict[str, Any] = dict(
            cell_factor=cell_factor, big_ratio=big_ratio, shell=shell
        )
        if stress:  # only when set: checkpoints of other Simulations keep their knobs
            self._knobs["stress"] = True
        # held for a whole run: the engine's own busy flag covers one C call only, and two
        # interleaved runs would write each other's samples
        self._running = threading.Lock()
        self._clustering_checked = False  # ClusteringWarning: once per Simulation

    # -- checkpoints ----------------------------------------------------------------
    def save(self, path: str | os.PathLike) -> None:
        """Write the whole engine state to ``path`` (a NumPy ``.npz`` file), so that
        ``Simulation.load(path)`` continues the run bit for bit as if it never stopped.

        Everything that decides the future is saved, not just positions and velocities:
        each particle's position at its own clock, image and collision counters, the
        predicted events as they were computed, the event queue, cell and neighbour
        lists, the renumbering, the time and the statistics so far, the scene the
        Simulation was built from and the knobs (``cell_factor``, ``big_ratio``,
        ``shell``).  The file is written to a temporary name and renamed, so a crash
        never leaves a half-written checkpoint, with the permissions ``open()`` would
        give it (0o666 less the umask): about 270 (2D) to 370 (3D, neighbour lists)
        bytes per particle.

        Parameters
        ----------
        path : str or os.PathLike
            Where to write (used as given: no suffix is added).

        Raises
        ------
        RuntimeError
            If another thread is running this Simulation.
        CheckpointError
            If the state cannot continue (non-finite or overflowing velocities, as a
            ``NonFiniteError`` leaves them, or anything else ``load`` would refuse):
            nothing is written.
        """
        with self._exclusive():
            checkpoint.save(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Simulation:
        """The Simulation saved by ``save``, ready to ``run`` on exactly as the saved one
        would have (same events, same bits).

        Parameters
        ----------
        path : str or os.PathLike
            A file written by ``save`` (a regular file: not a device or a pipe).

        Returns
        -------
        Simulation

        Raises
        ------
        CheckpointError
            If the file is not a checkpoint (a GSD file is named as one: read it with
            ``granular.read``), is truncated, corrupt or crafted (every part is checked,
            the state also as a Scene and against its initial scene's energy and
            momentum), or was written by another granular version or engine layout (a
            run continues bit for bit only in the version that saved it).
        FileNotFoundError, PermissionError
            If there is no file at ``path`` or it may not be read (as ``open`` says it).
        """
        return checkpoint.load(path, cls)

    @classmethod
    def _loads(cls, data: bytes) -> Simulation:
        """The Simulation in checkpoint bytes (``checkpoint.dumps``): what unpickling calls."""
        return checkpoint.loads(data, cls)

    def __reduce__(self):
        # pickling (and copy.copy / copy.deepcopy, Dask) goes through a checkpoint: the
        # copy gets its own engine with the same state, never a shared one
        with self._exclusive():
            return (type(self)._loads, (checkpoint.dumps(self),))

    @contextlib.contextmanager
    def _exclusive(self, instead: str = "save or copy it between runs") -> Iterator[None]:
        """Hold the run lock, or raise RuntimeError if a run holds it, saying what to do
        ``instead``."""
        if not self._running.acquire(blocking=False):
            raise RuntimeError(f"another thread is running this Simulation; {instead}")
        try:
            yield
        finally:
            self._running.release()

    # -- state ----------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Current simulation time."""
        return self._engine.counters()["time"]

    @property
    def stats(self) -> dict[str, Any]:
        """Counters since the start: events, pair_collisions, wall_collisions,
        cell_crossings (cell mode), shell_exits (neighbour lists: each rebuilds one
        list), stale_events,
        tc_elastic_collisions (pair collisions the TC model made elastic; a wall collision
        it made elastic is not counted), law_clamped_collisions (past a viscoelastic law's
        range, see ``granular.Viscoelastic``), virial, wall_impulse, kinetic_energy,
        kinetic_time_integral, time, cells, shell (0: cells), shear_work (the work of a
        sheared box's sliding images, csrc/boundary.h); kicks, drive_energy and drive_power
        (a random driving's kicks, the kinetic energy they gave, and that per unit time since
        the start); temperature, 2 E_kin / (d N) now, in a sheared box that of the velocities
        less the mean flow (granular/_shear.py); and the pressure averaged over
        the whole simulation from the virial theorem, P = (2 <E_kin>_t + W / t) / (d V)
        with the time average <E_kin>_t (exact for a cooling gas too) and W the pair
        collisions' virial (in a sheared box, whose kinetic part is that of the velocities
        less the mean flow, trace(pressure_tensor) / d with ``stress=True`` and NaN
        without).  In a periodic box V is the box volume.  In a walled box the
        walls' virial is -P d V_reach, so V is the volume the centres reach, the box shrunk
        by one radius at each face (see ``Trajectory.pressure``: exact for equal radii,
        approximate for mixtures).

        Rough particles (docs/rough.md): rotational_energy (sum I w^2 / 2; kinetic_energy
        is the translational part), translational_temperature, rotational_temperature
        (T_rot = <I w^2> / d_rot, d_rot = 1 in 2D, 3 in 3D) and temperature_ratio
        T_rot / T_tr (NaN when T_tr = 0); for smooth particles their spins' values, which
        never change.

        With a vibrating wall (``granular.VibratingWall``) also
        wall_work, the work it did on the particles (the sum over its hits of J U, J the
        normal impulse it gave and U its velocity then), and collision_loss, the kinetic
        energy dissipated by pair and wall collisions (a heated wall's gain counts as a
        negative loss): the kinetic energy (plus the potential one under gravity, plus the
        rotational one of rough particles, whose pair losses count both) changed by
        wall_work - collision_loss (+ drive_energy with a random driving) since the start,
        up to rounding (per sample: ``Trajectory.wall_work``, ``.collision_loss``); its
        stale_events also count a particle's arrival at the band
        the wall sweeps, where the exact search for its hit starts (docs/vibrated.md).

        Rough particles in a periodic box (sheared or not) also have collision_loss: the
        energy, translational and rotational, their pair collisions dissipated, summed from
        the collision rule's formulas (csrc/rule.h); in a sheared box kinetic_energy +
        rotational_energy changed by shear_work - collision_loss since the start, up to
        rounding.

        With ``Simulation(stress=True)`` also: stress_collisional, kinetic_time_tensor,
        kinetic_tensor (each d rows of d numbers, a tuple of tuples: ``np.array`` makes
        the matrix; see ``Trajectory``) and pressure_tensor, their average since the start
        in the same volume, whose trace over d is ``pressure`` to rounding."""
        c = self._engine.counters()
        s = self._initial
        d = s.dim
        # the engine gives nine numbers, the first d*d the tensor; stats holds plain values
        # (tuples of rows, as "cells"), so that two stats compare with ==
        tensors = {name: np.array(c.pop(name)[: d * d]).reshape(d, d) for name in _TENSORS}
        if c["time"] > 0:
            volume = _pressure_volume(s.lower, s.upper, s.radii, s.boundary)
            c["pressure"] = (
                (2.0 * c["kinetic_time_integral"] + c["virial"]) / c["time"] / (s.dim * volume)
            )
            tensors["pressure_tensor"] = (
                (tensors["kinetic_time_tensor"] + tensors["stress_collisional"])
                / c["time"]
                / volume
            )
        else:
            c["pressure"] = float("nan")
            tensors["pressure_tensor"] = np.full((d, d), np.nan)
        if self._knobs.get("stress"):
            c.update({k: tuple(map(tuple, v.tolist())) for k, v in tensors.items()})
        if s.shear_rate != 0.0:  # the peculiar velocities' pressure: the tensor's alone
            c["pressure"] = (
                float(np.trace(tensors["pressure_tensor"])) / d
                if self._knobs.get("stress")
                else float("nan")
            )
        c["collisions_per_particle"] = (2 * c["pair_collisions"] + c["wall_collisions"]) / s.n
        if s.shear_rate != 0.0:  # the peculiar velocities' (granular/_shear.py)
            pos, vel, _ = self._engine.state()
            c["temperature"] = float(
                _shear.flow_temperature(pos, vel, s.masses, s.lower, s.upper, s.shear_rate)
            )
        else:
            c["temperature"] = 2.0 * c["kinetic_energy"] / (s.dim * s.n)
        # the random driving's energy input per unit time (0 before any time has passed)
        c["drive_power"] = c["drive_energy"] / c["time"] if c["time"] > 0 else 0.0
        # rough particles (kinetic_energy is the translational part)
        c["rotational_energy"] = rotational_energy(self._spins(), s)
        c["translational_temperature"] = c["temperature"]  # (the peculiar one when sheared)
        c["rotational_temperature"] = 2.0 * c["rotational_energy"] / (rotational_dim(s.dim) * s.n)
        c["temperature_ratio"] = (
            c["rotational_temperature"] / c["translational_temperature"]
            if c["translational_temperature"] > 0
            else float("nan")
        )
        if s.vibrating_wall is None:  # kept by the engine only where a wall vibrates
            del c["wall_work"]
            # and for rough particles' pair collisions (csrc/rule.h): whole in a periodic box
            if not (s.boundary == "periodic" and s.tangential_restitution != -1.0):
                del c["collision_loss"]
        return c

    def _spins(self) -> NDArray[np.float64]:
        """The angular velocities now: the engine's for rough particles, else the scene's
        (smooth particles' spins never change)."""
        w = self._engine.angular_velocities()
        return self._initial.angular_velocities if w is None else w

    @property
    def scene(self) -> Scene:
        """The current state as a new Scene (positions wrapped into a periodic box; a
        sheared box's image offset the one now; a vibrating wall's phase moved on to the
        current time, ``VibratingWall.at_time``)."""
        pos, vel, _ = self._engine.state()
        s = self._initial
        if s.vibrating_wall is not None:  # (a walled box: never sheared)
            wall = s.vibrating_wall.at_time(self.time)
            return s.replace(
                positions=pos, velocities=vel, angular_velocities=self._spins(), vibrating_wall=wall
            )
        if s.shear_rate != 0.0:
            offset = shear_offset_at(s, self.time)
            return s.replace(
                positions=pos, velocities=vel, angular_velocities=self._spins(), shear_offset=offset
            )
        return s.replace(positions=pos, velocities=vel, angular_velocities=self._spins())

    @property
    def unwrapped_positions(self) -> NDArray[np.float64]:
        """(N, d) positions at the current time with periodic images undone (sheared:
        x gains img_y times the accumulated image offset, csrc/boundary.h)."""
        pos, _, img = self._engine.state()
        s = self._initial
        out = pos + img * (s.upper - s.lower)
        if s.shear_rate != 0.0:
            ly = float(s.upper[1] - s.lower[1])
            out[:, 0] += img[:, 1] * _shear.total_offset(
                s.shear_rate, s.shear_offset, ly, self.time
            )
        return out

    # -- running --------------------------------------------------------------------
    def run(
        self,
        t_stop: float | None = None,
        *,
        sample_times: ArrayLike | None = None,
        stop_when: Mapping[str, float] | None = None,
        store: tuple[str, ...] | list[str] = _STORE_DEFAULT,
        progress: bool = False,
    ) -> Trajectory:
        """Advance until ``t_stop`` (absolute time) or a ``stop_when`` criterion, whichever
        comes first, and return the samples as a Trajectory.

        Parameters
        ----------
        t_stop : float, optional
            Absolute time to stop at.
        sample_times : array_like, optional
            Increasing absolute times >= the current time (uniform, log-spaced, anything).
            Sampling only reads the state: it never changes the dynamics.  By default the
            current state and the final state are sampled.
        stop_when : dict, optional
            ``collisions_per_particle`` (mean collisions per particle since the start,
            pair collisions counting for both partners), ``kinetic_energy`` (stop when
            the mean kinetic energy per particle falls to this), ``events`` (events this
            run may process, cell crossings included).
        store : tuple of {"positions", "velocities", "angular_velocities"}
            Which per-particle arrays to keep (statistics are always kept).  Storing
            nothing keeps memory O(T) for long runs.
        progress : bool
            Show a tqdm progress bar.

        Raises
        ------
        RuntimeError
            If another thread is running this Simulation at the same time.
        HeatedWallsError
            If heated walls (``wall_restitution > 1``) pumped the energy up beyond what
            float64 event times can resolve.
        GranularError, KeyboardInterrupt
            Every error of the run, and Ctrl-C (seen between chunks of events, the state
            intact), carry ``.trajectory``: the samples taken so far, with ``stop_reason``
            ``"error"`` or ``"interrupted"``.

        Warns
        -----
        ClusteringWarning
            On the first run of a granular gas (constant xi < 1) in a periodic box beyond
            the critical size of the shear instability (``granular.clustering``) that can
            reach the instability's onset t* (by ``t_stop`` or the collisions per particle
            asked for; a run to an energy or an event count may); for a ``Viscoelastic``
            law, on the first run if the box is beyond the critical size at the law's
            effective restitution at the present temperature
            (``granular.clustering.effective_restitution``).
        """
        if not getattr(self, "_clustering_checked", False):  # also for restored Simulations
            self._warn_clustering(t_stop, stop_when)
        with self._exclusive(
            "a Simulation runs one run at a time (wait for it, or give each thread its own "
            "Simulation(scene))"
        ):
            return self._run(t_stop, sample_times, stop_when, store, progress)

    def _run(self, t_stop, sample_times, stop_when, store, progress):
        crit = dict(stop_when or {})
        unknown = set(crit) - set(_STOP_KEYS)
        if unknown:
            raise ValueError(f"unknown stop_when keys {sorted(unknown)}; use {_STOP_KEYS}")
        store = tuple(store)
        if set(store) - set(_STORE):
            from .errors import shown

            raise ValueError(f"store may contain only {_STORE}, got {shown(store)}")
        t_now = self.time
        t_end = math.inf if t_stop is None else float(t_stop)
        if math.isnan(t_end):
            raise ValueError("t_stop is NaN")
        if t_end < t_now:
            raise ValueError(f"t_stop = {t_end} lies before the current time {t_now}")
        cpp = float(crit.get("collisions_per_particle", math.inf))
        kin = float(crit.get("kinetic_energy", -1.0))
        if math.isnan(cpp) or math.isnan(kin):
            from .errors import shown

            raise ValueError(f"stop_when criteria must be numbers, got {shown(crit)}")
        frozen = frozen_energy(self._initial.radii, self._initial.masses)
        if "kinetic_energy" in crit and not kin * self._initial.n > frozen:
            raise ValueError(
                f"stop_when kinetic_energy = {kin:g} is not above {frozen / self._initial.n:.3g},"
                " the mean kinetic energy below which float64 cannot resolve this gas' "
                "collisions (a cooling gas only approaches 0): give a larger target"
            )
        budget = crit.get("events")
        if budget is not None and (isinstance(budget, bool) or int(budget) != budget or budget < 0):
            from .errors import shown

            raise ValueError(
                f"stop_when['events'] must be a whole number >= 0, got {shown(budget)}"
            )
        budget = math.inf if budget is None else int(budget)
        if t_end == math.inf and cpp == math.inf and kin < 0 and budget == math.inf:
            raise ValueError("run needs a finite t_stop or a stop_when criterion")
        unbounded = t_end == math.inf and budget == math.inf
        if unbounded and cpp == math.inf:
            self._check_energy_reachable(kin)

        final_sample = sample_times is None
        if final_sample:
            times = np.array([t_now])
        else:
            times = np.array(sample_times, dtype=np.float64)
            if times.ndim != 1:
                raise ValueError(f"sample_times must be one-dimensional, got shape {times.shape}")
            if not np.all(np.isfinite(times)):
                raise ValueError("sample_times must be finite")
            if len(times) and times[0] < t_now:
                raise ValueError(
                    f"sample_times start at {times[0]}, before the current time {t_now}"
                )
            if np.any(np.diff(times) <= 0):
                raise ValueError("sample_times must be strictly increasing")
            if len(times) and times[-1] > t_end:
                if times[-1] > t_end + 1e-12 * max(1.0, abs(t_end)):
                    raise ValueError(f"sample_times reach {times[-1]}, past t_stop = {t_end}")
                # past t_stop by rounding only (e.g. np.logspace's end): run on to the last
                # sample so that every sample is taken at the time asked for
                t_end = float(times[-1])
        count = len(times) + final_sample
        # rough particles' spins are sampled for the rotational energy even when not stored
        self._spins_stored = "angular_velocities" in store
        rough = self._engine.angular_velocities() is not None
        _check_memory(
            8.0 * count * self._initial.n * self._initial.dim * (len(store) + rough),
            f"storing {count} samples of {' and '.join(store)} (sample less often, "
            f"or run with store=() and keep only the statistics)",
        )
        buf = self._buffers(count, store, rough)

        # the C loop fills the first len(times) samples; a final one may follow
        views = {k: (None if v is None else v[: len(times)]) for k, v in buf.items()}
        reason, nxt, done = "events", 0, 0
        bar = _progress_bar(progress, t_now, t_end, cpp)
        stall = _StallGuard(self, dissipative_only=cpp == math.inf) if unbounded else None
        energy0 = self._initial.kinetic_energy
        start = self._engine.counters()  # counters() sums over particles: once a chunk
        events = start["events"]
        # under gravity nothing stays too slow for float64: the pull sets a speed
        moving = start["kinetic_energy"] > 0.0 and self._initial.gravity is None
        try:
            self._check_not_frozen(start, frozen, moving)
            while budget - done > 0:
                chunk = int(min(_CHUNK, budget - done))
                code, nxt = self._engine.advance(
                    t_stop=t_end,
                    collisions_per_particle=cpp,
                    stop_kinetic_energy=kin,
                    max_events=chunk,
                    sample_times=times,
                    next=nxt,
                    **views,
                )
                after = self._engine.counters()
                done += after["events"] - events
                events = after["events"]
                if bar is not None:
                    bar.update(self)
                self._check_not_frozen(after, frozen, moving)
                if code != _core.STOP_BUDGET:
                    reason = _REASONS[code]
                    break
                if stall is not None:
                    stall.check(after, crit)
        except (GranularError, KeyboardInterrupt) as exc:
            # keep what was sampled: every sample time up to the engine's clock is written
            k = int(np.searchsorted(times, self.time, side="right"))
            why = "interrupted" if isinstance(exc, KeyboardInterrupt) else "error"
            trajectory = self._trajectory(times[:k], buf, k, why)
            heated = self._heated_walls_error(exc, energy0)
            if heated is not None:
                heated.trajectory = trajectory
                raise heated from exc
            # the samples so far ride on the exception, whatever it is (a KeyboardInterrupt too)
            exc.trajectory = trajectory  # type: ignore[union-attr]
            raise
        finally:
            if bar is not None:
                bar.close()
        clamped = (
            self._engine.counters()["law_clamped_collisions"] - start["law_clamped_collisions"]
        )
        if clamped:
            _warn_clamped(clamped, self._initial)
        if final_sample and (nxt == 0 or self.time > times[0]):
            times = np.append(times[:nxt], self.time)
            self._sample_now(buf, nxt)
            nxt += 1
        return self._trajectory(times[:nxt], buf, nxt, reason)

    # a collapse cools the gas; an energy this far above the start can only come from
    # heated walls, and it puts the event times beyond float64's resolution
    _BLOWUP_RATIO = 1e6

    def _warn_clustering(self, t_stop, stop_when):
        """ClusteringWarning, once per Simulation, for the first run that can reach the
        shear instability's onset: a run that must stop before t* (a box barely beyond L_c
        can put it past anything float64 can time) has nothing to be warned of."""
        from .clustering import unstable_box

        # (the homogeneous cooling state's instability: a sheared gas has no such state,
        # nor has a driven one, docs/driven.md)
        sheared = self._initial.shear_rate != 0.0
        driven = self._initial.driving is not None
        found = None if sheared or driven else unstable_box(self._initial)
        if found is None:
            self._clustering_checked = True
            return
        message, t_star, cpp = found
        criteria = stop_when or {}
        if t_stop is not None and t_stop < t_star:
            return
        if t_stop is None and set(criteria) == {"collisions_per_particle"}:
            if criteria["collisions_per_particle"] < cpp:
                return
        self._clustering_checked = True
        import warnings

        warnings.warn(message, ClusteringWarning, stacklevel=3)

    def _heated_walls_error(self, exc, energy0):
        """The error to raise instead of ``exc`` when heated walls blew the gas up, else
        None (the engine reports the unresolvable event times as a collapse)."""
        s = self._initial
        if not (
            isinstance(exc, InelasticCollapseError)
            and s.boundary == "walls"
            and _restitution.heats(s.wall_restitution)
            and energy0 > 0
        ):
            return None
        c = self._engine.counters()
        ratio = c["kinetic_energy"] / energy0
        if not ratio > self._BLOWUP_RATIO:
            return None  # a real collapse of inelastic pairs
        return HeatedWallsError(
            f"the heated walls (wall_restitution = {s.wall_restitution} > 1) pumped the kinetic "
            f"energy up by a factor {ratio:.3g} by t = {c['time']:.6g}: the particles are so fast "
            "that the event times can no longer be resolved in float64.  Lower "
            "wall_restitution, or stop earlier (t_stop, or stop_when with kinetic_energy or "
            "collisions_per_particle)",
            time=c["time"],
            value=ratio,
        )

    @staticmethod
    def _check_not_frozen(c, frozen, moving):
        """Stop a gas too slow for float64 (at the start, or cooled there by inelastic
        walls or collisions, possibly to 0 by underflow) before pairs pass through each
        other unseen.  A gas at rest from the start of the run is left alone: nothing moves."""
        energy = c["kinetic_energy"]
        if moving and energy < frozen:
            raise FrozenGasError(
                f"at t = {c['time']:.6g} the kinetic energy is {energy:.3g}, below {frozen:.3g}: "
                "the speeds times the smallest diameter are under 1e-140 and float64 can no "
                "longer resolve when two particles touch.  Stop earlier (t_stop, or "
                "stop_when kinetic_energy), or rescale the velocities (scene.replace)",
                time=c["time"],
                value=energy,
            )

    def _check_energy_reachable(self, target):
        """Refuse a kinetic-energy stop that can never come, before running forever: the
        energy never falls without a dissipative channel (inelastic pairs, of which there
        must be two, or absorbing walls)."""
        s = self._initial
        if s.gravity is not None and s.boundary == "periodic":
            # the freely falling box: its kinetic energy counts the fall, M g^2 t^2 / 2, which
            # outgrows any cooling, so an energy target alone may never come
            raise ValueError(
                f"stop_when kinetic_energy = {target} alone cannot bound a run in the freely "
                "falling box (free_fall=True): its kinetic energy counts the fall, which grows "
                "as M g^2 t^2 / 2; give t_stop, or stop_when collisions_per_particle or events"
            )
        pairs_lose = (
            _restitution.loses_energy(s.restitution) or not rough_keeps_energy(s)
        ) and s.n >= 2
        walls_lose = s.boundary == "walls" and _restitution.loses_energy(s.wall_restitution)
        mean = self._engine.counters()["kinetic_energy"] / s.n
        # (gravity trades kinetic energy for potential: it can fall either way)
        if not (pairs_lose or walls_lose) and target < mean and s.gravity is None:
            why = (
                "a single particle has no partner to collide with" if s.n == 1 else "restitution 1"
            )
            walls = "" if s.boundary == "periodic" else ", walls that do not absorb"
            raise ValueError(
                f"stop_when kinetic_energy = {target} can never be reached: the mean kinetic "
                f"energy is {mean:.6g} and this scene does not lose energy ({why}{walls}); "
                "give t_stop"
            )

    def _sample_now(self, buf, k):
        """Write the current state as sample k (reads the state, processes no event)."""
        _, vel, _ = self._engine.state()
        c = self._engine.counters()
        m = self._initial.masses[:, None]
        if buf["positions"] is not None:
            buf["positions"][k] = self.unwrapped_positions
        if buf["velocities"] is not None:
            buf["velocities"][k] = vel
        if buf["angular_velocities"] is not None:
            buf["angular_velocities"][k] = self._spins()
        buf["momentum"][k] = (m * vel).sum(axis=0)
        for name, _ in _COUNTED:
            buf[name][k] = c[name]
        for name in _TENSORS:
            if buf.get(name) is not None:
                buf[name][k] = np.array(c[name][: vel.shape[1] ** 2]).reshape(vel.shape[1], -1)
        for name in _WALL_BOOKS:
            if buf.get(name) is not None:
                buf[name][k] = c[name]

    def _buffers(self, count, store, rough=False):
        n, d = self._initial.n, self._initial.dim
        spins = None
        if rough or "angular_velocities" in store:  # smooth ones keep the scene's spins
            spins = np.zeros((count, *spin_shape(n, d)))
            spins[:] = self._initial.angular_velocities
        return dict(
            positions=np.zeros((count, n, d)) if "positions" in store else None,
            velocities=np.zeros((count, n, d)) if "velocities" in store else None,
            angular_velocities=spins,
            momentum=np.zeros((count, d)),
            **{name: np.zeros(count, dtype=dtype) for name, dtype in _COUNTED},
            **{
                name: np.zeros((count, d, d)) if self._knobs.get("stress") else None
                for name in _TENSORS
            },
            **{
                name: np.zeros(count) if self._initial.vibrating_wall is not None else None
                for name in _WALL_BOOKS
            },
        )

    def _trajectory(self, times, buf, k, reason):
        s = self._initial
        cut: dict[str, Any] = {
            name: (None if a is None else a[:k].copy()) for name, a in buf.items()
        }
        spins = cut["angular_velocities"]
        cut["rotational_energy"] = (
            np.full(k, s.rotational_energy) if spins is None else rotational_energy(spins, s)
        )
        if not getattr(self, "_spins_stored", False):
            cut["angular_velocities"] = None
        return Trajectory(
            times.copy(),
            **cut,
            masses=s.masses,
            radii=s.radii,
            lower=s.lower,
            upper=s.upper,
            boundary=s.boundary,
            stop_reason=reason,
            parameters={p.name: p.get(s) for p in RUN_PARAMETERS},
        )


_REASONS = {
    _core.STOP_TIME: "time",
    _core.STOP_COLLISIONS: "collisions",
    _core.STOP_ENERGY: "kinetic_energy",
    _core.STOP_IDLE: "idle",
    _core.STOP_BUDGET: "events",
}


class _StallGuard:
    """A run with no time limit and no event budget that stops on collisions or energy
    must not spin forever where no progress can come (a lone particle in a periodic box,
    particles on parallel lines, elastic walls under an energy target): after this many
    events without progress it raises.  Progress is any collision for a
    collisions_per_particle criterion, and only a dissipative one for an energy target
    alone: an inelastic pair collision (not one the TC model made elastic), a hit on an
    absorbing wall.  A gas needs a handful of events (cell crossings) per collision; a very
    dilute one many more, so the bound is generous."""

    MIN_LIMIT = 10**7

    def __init__(self, sim, dissipative_only):
        s = sim._initial
        self.limit = max(self.MIN_LIMIT, 1000 * s.n)
        self.pairs = (
            not dissipative_only
            or _restitution.loses_energy(s.restitution)
            or not rough_keeps_energy(s)
        )
        self.walls = not dissipative_only or (
            s.boundary == "walls" and _restitution.loses_energy(s.wall_restitution)
        )
        self.dissipative_only = dissipative_only
        c = sim._engine.counters()
        self.progress = self._progress(c)
        self.events = c["events"]

    def _progress(self, c):
        count = 0
        if self.pairs:
            count += c["pair_collisions"]
            if self.dissipative_only:  # pairs the TC model made elastic dissipate nothing
                count -= c["tc_elastic_collisions"]
        if self.walls:
            count += c["wall_collisions"]
        return count

    def check(self, c, criteria):
        """c: the engine's counters now."""
        progress = self._progress(c)
        if progress != self.progress:
            self.progress, self.events = progress, c["events"]
        elif c["events"] - self.events >= self.limit:
            from .errors import shown

            what = "dissipative collision" if self.dissipative_only else "collision"
            raise NoProgressError(
                f"no {what} in {c['events'] - self.events} events (t = {c['time']:.6g}): the "
                f"stop criteria {shown(criteria)} may never be met; give t_stop or "
                "stop_when['events']",
                time=c["time"],
            )


class _ProgressBar:
    """tqdm over simulated time (t_stop given) or over collisions per particle."""

    def __init__(self, start, end, by_time):
        from tqdm.auto import tqdm

        self.start, self.by_time = start, by_time
        self.bar = tqdm(
            total=end - start,
            unit="time" if by_time else "collisions/particle",
            unit_scale=True,
            leave=False,
        )

    def update(self, sim):
        now = sim.time if self.by_time else sim.stats["collisions_per_particle"]
        self.bar.n = min(now - self.start, self.bar.total)
        self.bar.refresh()

    def close(self):
        self.bar.close()


def _progress_bar(progress, t0, t1, collisions):
    if not progress:
        return None
    if math.isfinite(t1):
        return _ProgressBar(t0, t1, by_time=True)
    if math.isfinite(collisions):
        return _ProgressBar(0.0, collisions, by_time=False)
    return None


def _warn_clamped(count, scene):
    """Warn that collisions were faster than a viscoelastic law's series reaches."""
    import warnings

    laws = [x for x in (scene.restitution, scene.wall_restitution) if hasattr(x, "max_speed")]
    speeds = ", ".join(f"{law.max_speed:.4g}" for law in laws)
    warnings.warn(
        f"{count} collisions in this run were faster than the viscoelastic law's range "
        f"(normal impact speed above max_speed = {speeds}) and got the restitution at "
        "max_speed: the second-order series is not valid there (granular.Viscoelastic)",
        RuntimeWarning,
        stacklevel=3,
    )


def shear_offset_at(scene: Scene, t: float) -> float:
    """A sheared scene's image offset delta(t) in [0, L_x) at time t [L] (csrc/boundary.h)."""
    lengths = scene.upper - scene.lower
    return _shear.offset(
        scene.shear_rate, scene.shear_offset, float(lengths[0]), float(lengths[1]), t
    )
