"""Trajectory: what a run recorded, with the physics that follows from it."""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import gsd_io
from ._results import ergodicity_breaking, readonly
from ._scene_params import RUN_PARAMETERS
from .scene import Scene


def _pressure_volume(lower, upper, radii, boundary):
    """The volume in the virial pressure: the box when periodic; in a walled box the volume
    the centres reach, each side shrunk by the largest diameter (exact for equal radii)."""
    lengths = np.asarray(upper) - np.asarray(lower)
    if boundary == "walls":
        lengths = lengths - 2.0 * float(np.max(radii))
    return float(np.prod(lengths))


class Trajectory:
    """Samples of one EDMD run: read-only (its attributes cannot be set, its arrays are
    read-only views), as every result is (see docs/analysis.md, "Results").

    The quantities every result offers under the same names and units: ``times``,
    ``temperature`` (an energy, k_B = 1), ``msd()``, ``tamsd()``, ``tamsd_lags`` and
    ``ergodicity_breaking()``.

    Attributes
    ----------
    times : (T,) sample times (absolute simulation time)
    positions : (T, N, d) unwrapped positions, or None if not stored
    velocities : (T, N, d), or None if not stored
    kinetic_energy : (T,) total kinetic energy
    momentum : (T, d) total momentum
    pair_collisions, wall_collisions : (T,) cumulative counts since the simulation began
    virial : (T,) cumulative sum over pair collisions of r_ij . dp_j
    wall_impulse : (T,) cumulative normal momentum given to the walls
    stress_collisional : (T, d, d) cumulative sum over pair collisions of r_a dp_b (r =
        x_j - x_i at contact, dp the momentum j received), or None unless the Simulation
        was built with ``stress=True``
    kinetic_time_tensor : (T, d, d) cumulative integral over time of sum_i m_i v_a v_b,
        or None (as above)
    kinetic_tensor : (T, d, d) sum_i m_i v_a v_b at each sample, or None (as above)
    wall_work : (T,) cumulative work a vibrating wall did on the particles since the
        simulation began (the sum over its hits of J U, J the normal impulse it gave, U its
        velocity then), or None without a vibrating wall (``stats["wall_work"]`` is the
        last value of a run that ends with a sample)
    collision_loss : (T,) cumulative kinetic energy pair and wall collisions dissipated
        since the simulation began, or None without a vibrating wall; between two samples
        the kinetic (plus potential, under gravity; plus rotational, for rough particles)
        energy changed by the differences of ``wall_work`` less those of ``collision_loss``
        (``wall_power``)
    stop_reason : why the run ended: "time", "collisions", "kinetic_energy", "events",
        "idle" (no event will ever happen); a run cut short carries the samples so far in
        its exception's ``.trajectory``, with "error" or, after Ctrl-C, "interrupted"
    angular_velocities : (T, N) in 2D, (T, N, 3) in 3D, or None if not stored
    rotational_energy : (T,) total rotational energy sum I w^2 / 2, or None (a
        trajectory made without it)
    masses, radii, lower, upper, boundary : copied from the scene
    scene_parameters : dict, the run's scene's parameters other than the positions and
        velocities (radii, masses, box, boundary, restitutions, contact_duration, ...), as
        the Scene keeps them (the box as its corners (lower, upper))
    temperature : (T,) granular temperature, an energy (translational)
    rotational_temperature : (T,) T_rot = 2 E_rot / (d_rot N), d_rot = 1 in 2D, 3 in 3D
    temperature_ratio : (T,) T_rot / T
    tamsd_lags : (T - 1,) the lags of ``tamsd()`` by default
    """

    # the fields, set once in __init__ (through object.__setattr__: __setattr__ refuses)
    times: NDArray[np.float64]
    positions: NDArray[np.float64] | None
    velocities: NDArray[np.float64] | None
    kinetic_energy: NDArray[np.float64]
    momentum: NDArray[np.float64]
    pair_collisions: NDArray[np.int64]
    wall_collisions: NDArray[np.int64]
    virial: NDArray[np.float64]
    wall_impulse: NDArray[np.float64]
    stress_collisional: NDArray[np.float64] | None
    kinetic_time_tensor: NDArray[np.float64] | None
    kinetic_tensor: NDArray[np.float64] | None
    wall_work: NDArray[np.float64] | None
    collision_loss: NDArray[np.float64] | None
    angular_velocities: NDArray[np.float64] | None
    rotational_energy: NDArray[np.float64] | None
    masses: NDArray[np.float64]
    radii: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    boundary: str
    stop_reason: str
    _parameters: tuple[tuple[str, Any], ...]  # scene_parameters, a tuple: read-only

    def __init__(
        self,
        times: NDArray[np.float64],
        positions: NDArray[np.float64] | None,
        velocities: NDArray[np.float64] | None,
        kinetic_energy: NDArray[np.float64],
        momentum: NDArray[np.float64],
        pair_collisions: NDArray[np.int64],
        wall_collisions: NDArray[np.int64],
        virial: NDArray[np.float64],
        wall_impulse: NDArray[np.float64],
        *,
        masses: NDArray[np.float64],
        radii: NDArray[np.float64],
        lower: NDArray[np.float64],
        upper: NDArray[np.float64],
        boundary: str,
        stop_reason: str,
        parameters: dict[str, Any] | None = None,
        stress_collisional: NDArray[np.float64] | None = None,
        kinetic_time_tensor: NDArray[np.float64] | None = None,
        kinetic_tensor: NDArray[np.float64] | None = None,
        angular_velocities: NDArray[np.float64] | None = None,
        rotational_energy: NDArray[np.float64] | None = None,
        wall_work: NDArray[np.float64] | None = None,
        collision_loss: NDArray[np.float64] | None = None,
    ) -> None:
        # read-only views: a caller writing into an array the trajectory hands out gets a
        # ValueError instead of changing the trajectory unseen
        fields = dict(
            times=times,
            positions=positions,
            velocities=velocities,
            kinetic_energy=kinetic_energy,
            momentum=momentum,
            pair_collisions=pair_collisions,
            wall_collisions=wall_collisions,
            virial=virial,
            wall_impulse=wall_impulse,
            stress_collisional=stress_collisional,
            kinetic_time_tensor=kinetic_time_tensor,
            kinetic_tensor=kinetic_tensor,
            angular_velocities=angular_velocities,
            rotational_energy=rotational_energy,
            wall_work=wall_work,
            collision_loss=collision_loss,
            masses=masses,
            radii=radii,
            lower=lower,
            upper=upper,
            boundary=boundary,
            stop_reason=stop_reason,
        )
        for name, value in fields.items():
            object.__setattr__(self, name, readonly(value))
        object.__setattr__(self, "_parameters", self._run_parameters(parameters or {}))

    def _run_parameters(self, given: dict[str, Any]) -> tuple[tuple[str, Any], ...]:
        """The scene's run parameters (see ``scene_parameters``): those the trajectory's own
        fields hold (radii, masses, the box, the boundary) from them, the others from
        ``given`` (checked as a Scene checks them) or their defaults (a trajectory made by
        hand)."""
        held = [p for p in RUN_PARAMETERS if all(a in type(self).__annotations__ for a in p.fields)]
        others = {p.name: p for p in RUN_PARAMETERS if p not in held}
        unknown = set(given) - set(others) - {p.name for p in held}
        if unknown:
            raise TypeError(
                f"unknown scene parameters {sorted(unknown)}; a trajectory keeps {sorted(others)}"
            )
        n, d = len(self.masses), len(self.lower)
        values = {p.name: p.get(self) for p in held}
        for name, p in others.items():
            values[name] = p.check(given.get(name, p.default), n, d)
        return tuple((p.name, values[p.name]) for p in RUN_PARAMETERS)

    @property
    def scene_parameters(self) -> dict[str, Any]:
        """The run's scene's parameters other than the positions and velocities, as the
        Scene keeps them: ``scene.replace(**traj.scene_parameters)`` has them all."""
        return dict(self._parameters)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(
            f"a Trajectory is read-only: {name} cannot be set (it is what the run recorded)"
        )

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"a Trajectory is read-only: {name} cannot be deleted")

    def __setstate__(self, state: dict[str, Any]) -> None:
        # unpickled (and copied) read-only too: NumPy does not keep the flag
        for name, value in state.items():
            object.__setattr__(self, name, readonly(value))

    @property
    def n(self) -> int:
        return len(self.masses)

    @property
    def dim(self) -> int:
        return len(self.lower)

    @property
    def volume(self) -> float:
        return float(np.prod(self.upper - self.lower))

    @property
    def temperature(self) -> NDArray[np.float64]:
        """(T,) granular temperature 2 E_kin / (d N), k_B = 1.  In a sheared box the
        kinetic energy of the peculiar velocities, the velocities less the mean flow
        shear_rate (y - y_c) along x (granular/_shear.py), which needs the positions and
        velocities stored."""
        rate = self._parameters_dict().get("shear_rate", 0.0)
        if rate == 0.0:
            return 2.0 * self.kinetic_energy / (self.dim * self.n)
        if self.positions is None or self.velocities is None:
            raise ValueError(
                "the temperature of a sheared run is that of the velocities less the mean "
                "flow, which needs the positions and velocities: run with "
                "store=('positions', 'velocities')"
            )
        from ._shear import flow_temperature

        return readonly(
            flow_temperature(
                self.positions, self.velocities, self.masses, self.lower, self.upper, rate
            )
        )

    def _parameters_dict(self) -> dict[str, Any]:
        return dict(self._parameters)

    @property
    def rotational_temperature(self) -> NDArray[np.float64]:
        """(T,) rotational temperature T_rot = 2 E_rot / (d_rot N) = <I w^2> / d_rot, d_rot =
        1 in 2D (the spin along z), 3 in 3D (Huthmann & Zippelius 1997), k_B = 1."""
        rot = self._need("rotational_energy")
        return 2.0 * rot / ((1 if self.dim == 2 else 3) * self.n)

    @property
    def temperature_ratio(self) -> NDArray[np.float64]:
        """(T,) T_rot / T_tr, the rotational over the translational temperature."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.rotational_temperature / self.temperature

    @property
    def collisions_per_particle(self) -> NDArray[np.float64]:
        """(T,) mean collisions per particle, counting pair collisions for both partners
        and wall collisions once (as the thesis does)."""
        return (2.0 * self.pair_collisions + self.wall_collisions) / self.n

    def _need(self, name: str) -> Any:
        value = getattr(self, name)
        if value is None:
            raise ValueError(
                f"this trajectory did not store {name}; run with store including {name!r}"
            )
        return value

    def pressure(self) -> float:
        """Pressure over the run from the virial theorem, P = (2 <E_kin> + W / dt) / (d V),
        with W the virial of the pair collisions between the first and last sample and
        <E_kin> the time average of the kinetic energy (trapezoid over the samples: exact
        for a molecular gas, which keeps E_kin constant; sample densely when it changes).

        In a periodic box V is the box volume.  In a walled box the walls' own virial is
        -P d V_reach, with V_reach the volume the centres reach (each side shrunk by one
        diameter), so V = V_reach: the same pressure as ``wall_pressure``, estimated from
        the pair collisions instead of the wall hits.  Exact for equal radii; for a mixture
        V_reach uses the largest radius, which is approximate (smaller particles reach
        closer to the walls), to a relative error of order (r_max - r_min) / L.

        In a sheared box the kinetic part is that of the velocities less the mean flow, which
        only the stress tensor keeps: there the pressure is trace(``pressure_tensor()``) / d,
        and it needs ``Simulation(stress=True)``."""
        t = self.times
        if len(t) < 2 or t[-1] <= t[0]:
            raise ValueError("pressure needs at least two samples spanning some time")
        if self._parameters_dict().get("shear_rate", 0.0) != 0.0:
            if self.kinetic_time_tensor is None:
                raise ValueError(
                    "the pressure of a sheared gas counts the velocities less the mean flow, "
                    "which only the stress tensor keeps: run with Simulation(stress=True)"
                )
            return float(np.trace(self.pressure_tensor()) / self.dim)
        span = t[-1] - t[0]
        mean_k = np.trapezoid(self.kinetic_energy, t) / span
        w = self.virial[-1] - self.virial[0]
        volume = _pressure_volume(self.lower, self.upper, self.radii, self.boundary)
        return float((2.0 * mean_k + w / span) / (self.dim * volume))

    def pressure_tensor(self, per_window: bool = False) -> NDArray[np.float64]:
        """The pressure tensor P_ab = (int sum_i m_i v_a v_b dt + sum r_a dp_b) / (V dt),
        kinetic plus collisional (docs/stress.md), over the run between the first and the
        last sample: exact up to rounding (the kinetic part is integrated through every
        collision, not from the samples).  Its trace over d is ``pressure()`` to rounding;
        V as there (the box; between walls the volume the centres reach: wall impulses do
        not enter, as they do not enter ``pressure``).  Needs ``Simulation(stress=True)``.

        Parameters
        ----------
        per_window : bool
            Return (T - 1, d, d), the tensor averaged over each window between consecutive
            samples, instead of (d, d) over the whole run.
        """
        coll = self._need_stress()
        kin = self.kinetic_time_tensor
        assert kin is not None
        t = self.times
        volume = _pressure_volume(self.lower, self.upper, self.radii, self.boundary)
        if per_window:
            if len(t) < 2:
                raise ValueError("pressure_tensor needs at least two samples")
            return np.asarray(
                (np.diff(kin, axis=0) + np.diff(coll, axis=0))
                / (np.diff(t)[:, None, None] * volume)
            )
        if len(t) < 2 or t[-1] <= t[0]:
            raise ValueError("pressure_tensor needs at least two samples spanning some time")
        return np.asarray(((kin[-1] - kin[0]) + (coll[-1] - coll[0])) / ((t[-1] - t[0]) * volume))

    def kinetic_pressure_tensor(self) -> NDArray[np.float64]:
        """(T, d, d) the instantaneous kinetic part of the pressure tensor at each sample,
        sum_i m_i v_a v_b / V (V as in ``pressure_tensor``).  Needs
        ``Simulation(stress=True)``."""
        self._need_stress()
        kin = self.kinetic_tensor
        assert kin is not None
        return np.asarray(kin / _pressure_volume(self.lower, self.upper, self.radii, self.boundary))

    def _need_stress(self) -> NDArray[np.float64]:
        if self.stress_collisional is None:
            raise ValueError(
                "this trajectory has no stress tensor: build the Simulation with stress=True"
            )
        return self.stress_collisional

    def wall_power(self, per_window: bool = False) -> tuple[Any, Any]:
        """The vibrating wall's mean power input and the mean power collisions dissipate,
        (input, loss), from ``wall_work`` and ``collision_loss``: over the run between the
        first and the last sample, or per window between consecutive samples.  Exact (the
        engine sums both at every hit and collision); their difference is the rate of change
        of the kinetic (plus potential, under gravity; plus rotational, for rough particles)
        energy, zero on average in a steady state (docs/vibrated.md).

        Parameters
        ----------
        per_window : bool
            Return two (T - 1,) arrays, one value per window, instead of two floats.
        """
        if self.wall_work is None or self.collision_loss is None:
            raise ValueError(
                "this trajectory has no vibrating wall's books (wall_work, collision_loss): "
                "its scene had no vibrating wall"
            )
        t = self.times
        if per_window:
            if len(t) < 2:
                raise ValueError("wall_power needs at least two samples")
            spans = np.diff(t)
            return np.diff(self.wall_work) / spans, np.diff(self.collision_loss) / spans
        if len(t) < 2 or t[-1] <= t[0]:
            raise ValueError("wall_power needs at least two samples spanning some time")
        span = float(t[-1] - t[0])
        work = float(self.wall_work[-1] - self.wall_work[0])
        return work / span, float(self.collision_loss[-1] - self.collision_loss[0]) / span

    def wall_pressure(self) -> float:
        """Mechanical pressure on the walls between the first and last sample: the normal
        momentum given to them per unit time, over the area the particle centres can
        reach (each face shrunk by one radius at each edge; exact for equal radii, the
        largest radius is used for mixtures).  This is the bulk pressure of the gas,
        ``n_c T Z`` with ``n_c`` the centres' density in the volume they can reach."""
        if self.boundary != "walls":
            raise ValueError("wall_pressure needs a walled box")
        t = self.times
        if len(t) < 2 or t[-1] <= t[0]:
            raise ValueError("wall_pressure needs at least two samples spanning some time")
        reach = self.upper - self.lower - 2.0 * float(np.max(self.radii))
        area = 2.0 * sum(np.prod(np.delete(reach, a)) for a in range(self.dim))
        return float((self.wall_impulse[-1] - self.wall_impulse[0]) / ((t[-1] - t[0]) * area))

    def msd(
        self, per_dimension: bool = False, particles: ArrayLike | None = None
    ) -> NDArray[np.float64]:
        """Ensemble mean squared displacement from the first sample, at every sample:
        (T,) summed over dimensions, or (T, d) with ``per_dimension=True``; see
        ``granular.analysis.msd``.  The same call as ``LangevinResult.msd`` and
        ``EnsembleResult.msd``.

        Parameters
        ----------
        per_dimension : bool
            Return (T, d), one column per axis, instead of the sum over axes.
        particles : array_like of int or bool, optional
            Average over these particles only (indices, or a boolean mask over all N),
            e.g. a tracer; by default over all.
        """
        positions = self._need("positions")
        from . import analysis

        return analysis.msd(positions, per_dimension=per_dimension, particles=particles)

    @property
    def tamsd_lags(self) -> NDArray[np.float64]:
        """(T - 1,) the lags ``tamsd()`` takes by default: every sample time after the first,
        less the first (``times[k] - times[0]``), each a difference of sample times; with
        uniform sampling, every multiple of the spacing the run spans."""
        return readonly(self.times[1:] - self.times[:1])

    def tamsd(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
        per_particle: bool = False,
        method: str = "auto",
    ) -> NDArray[np.float64]:
        """Time-averaged MSD, (L,) averaged over particles or (N, L) with
        ``per_particle=True``; see ``granular.analysis.tamsd``.  The same call, defaults
        and errors as ``LangevinResult.tamsd`` and ``EnsembleResult.tamsd``: by default at
        every lag the result has (``tamsd_lags``), or at those chosen by ``lags`` (in time)
        or ``lag_samples`` (in samples), at most one of the two.

        Parameters
        ----------
        lags : array_like of float, optional
            Lags in time, each a difference of sample times (with uniform sampling, a
            multiple of the spacing); any other is refused, naming the nearest lags the
            samples have (as ``LangevinResult.tamsd`` refuses a lag it did not accumulate).
            Default: ``tamsd_lags``.
        lag_samples : array_like of int, optional
            Lags as whole numbers of samples instead (uniformly spaced samples).
        particles : array_like of int or bool, optional
            Average over these particles only (indices or a boolean mask over all N).
        per_particle : bool
            Return (N, L) (a row per chosen particle) instead of the mean.
        method : "auto", "fft" or "direct"
            How ``analysis.tamsd`` computes it: a trajectory's own keyword, since it
            computes the TAMSD from its positions where the other results hold one the
            engine accumulated.

        Raises
        ------
        TypeError
            Both ``lags`` and ``lag_samples`` given.
        ValueError
            No positions stored, or a lag the samples do not have.
        """
        positions = self._need("positions")
        from . import analysis

        if lags is not None and lag_samples is not None:
            raise TypeError("give at most one of lags (in time) and lag_samples (in samples)")
        if lags is None and lag_samples is None:
            if len(self.times) < 2:
                raise ValueError("a TAMSD needs at least two samples")
            lags = self.tamsd_lags
        return analysis.tamsd(
            positions,
            lags,
            times=self.times,
            lag_samples=lag_samples,
            method=method,
            per_particle=per_particle,
            particles=particles,
        )

    def ergodicity_breaking(
        self,
        lags: ArrayLike | None = None,
        *,
        lag_samples: ArrayLike | None = None,
        particles: ArrayLike | None = None,
    ) -> NDArray[np.float64]:
        """The measured ergodicity-breaking parameter at the lags of ``tamsd()`` (by
        default ``tamsd_lags``), over the particles: ``analysis.ergodicity_breaking`` of
        ``tamsd(..., per_particle=True)``.  The same call as on the other results.

        Parameters
        ----------
        lags, lag_samples, particles : as in ``tamsd``.
        """
        return ergodicity_breaking(self, lags, lag_samples, particles)

    def structure_factor(self, n_max: float = 2.0) -> Any:
        """Density structure factor S(k, t) at the box's smallest wave vectors, per ``|k|``
        shell; see ``granular.clustering.structure_factor``."""
        from . import clustering

        return clustering.structure_factor(self._need("positions"), self.upper - self.lower, n_max)

    def current_correlations(self, n_max: float = 2.0) -> Any:
        """Transverse (vortices) and longitudinal momentum-current correlations at the box's
        smallest wave vectors; see ``granular.clustering.current_correlations``."""
        from . import clustering

        return clustering.current_correlations(
            self._need("positions"),
            self._need("velocities"),
            self.masses,
            self.upper - self.lower,
            n_max,
        )

    def flow_energy(self, cells: int = 4) -> Any:
        """Kinetic energy of the coarse-grained flow field (cells per side) against the
        thermal energy, with the finite-sample noise level; see
        ``granular.clustering.flow_energy``."""
        from . import clustering

        return clustering.flow_energy(
            self._need("positions"),
            self._need("velocities"),
            self.masses,
            self.lower,
            self.upper,
            cells,
        )

    def to_universe(self) -> Any:
        """An MDAnalysis Universe of the particles: one atom per particle, one frame per
        sample, unwrapped positions (see ``granular.interop.to_universe``).  Its dimensions
        are the box's, as MDAnalysis reads them from the GSD file ``write`` makes: in 2D
        ``[Lx, Ly, max(Lx, Ly), 90, 90, 90]``, the disks in the plane z = 0.  MDAnalysis
        treats every box as periodic, a walled one too (see ``granular.interop``)."""
        positions = self._need("positions")
        from . import interop

        return interop.to_universe(
            self.times, positions, box=self.upper - self.lower, radii=self.radii
        )

    def write(self, path: str | os.PathLike) -> None:
        """Write the samples to a GSD file (``path`` ending in .gsd), which OVITO, freud,
        HOOMD and MDAnalysis read and ``granular.read`` reads back exactly: the standard
        particle fields are float32 (HOOMD's schema), the exact float64 positions,
        velocities, times and counters go in its log section (see ``granular.gsd_io``).
        Other formats (XYZ, TRR, ...): MDAnalysis' writers on ``to_universe()``.  Needs
        the positions stored."""
        gsd_io.write(self, path)

    def __len__(self) -> int:
        return len(self.times)

    def __repr__(self) -> str:
        span = f"t = {self.times[0]:.4g} .. {self.times[-1]:.4g}" if len(self.times) else "empty"
        return (
            f"Trajectory({len(self.times)} samples, {span}, n={self.n}, dim={self.dim}, "
            f"stop_reason={self.stop_reason!r})"
        )


def read(path: str | os.PathLike) -> Trajectory:
    """Read a GSD file written by ``Trajectory.write`` back into a Trajectory, with the
    exact float64 values of the log section.

    Every frame is checked as a Scene is (finite positions and velocities, positive radii
    and masses, a valid box and boundary, particles inside it and not overlapping), the
    sample times must increase and the collision counts must be whole numbers that never
    decrease.  Only the log section is read, no more of it than the file holds.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.gsd`` file.

    Returns
    -------
    Trajectory

    Raises
    ------
    GSDFileError
        Not a GSD file, truncated or corrupt, not written by granular, or a field missing,
        of the wrong shape or an impossible value; the message names the file, the frame
        and the field.
    FileNotFoundError
        No file at ``path``.
    """
    return gsd_io.read(path, Scene, Trajectory)
