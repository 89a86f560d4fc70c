"""Trajectory: what a run recorded, with the physics that follows from it."""
from __future__ import annotations

import numpy as np


class Trajectory:
    """Samples of one run.

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
    stop_reason : why the run ended: "time", "collisions", "kinetic_energy", "events"
        or "idle" (no event will ever happen)
    masses, radii, lower, upper, boundary : copied from the scene
    """

    def __init__(self, times, positions, velocities, kinetic_energy, momentum,
                 pair_collisions, wall_collisions, virial, wall_impulse, *, masses, radii,
                 lower, upper, boundary, stop_reason):
        self.times = times
        self.positions = positions
        self.velocities = velocities
        self.kinetic_energy = kinetic_energy
        self.momentum = momentum
        self.pair_collisions = pair_collisions
        self.wall_collisions = wall_collisions
        self.virial = virial
        self.wall_impulse = wall_impulse
        self.masses = masses
        self.radii = radii
        self.lower = lower
        self.upper = upper
        self.boundary = boundary
        self.stop_reason = stop_reason

    @property
    def n(self):
        return len(self.masses)

    @property
    def dim(self):
        return len(self.lower)

    @property
    def volume(self):
        return float(np.prod(self.upper - self.lower))

    @property
    def temperature(self):
        """(T,) granular temperature 2 E_kin / (d N), k_B = 1."""
        return 2.0 * self.kinetic_energy / (self.dim * self.n)

    @property
    def collisions_per_particle(self):
        """(T,) mean collisions per particle, counting pair collisions for both partners
        and wall collisions once (as the thesis does)."""
        return (2.0 * self.pair_collisions + self.wall_collisions) / self.n

    def _need(self, name):
        value = getattr(self, name)
        if value is None:
            raise ValueError(f"this trajectory did not store {name}; run with store including {name!r}")
        return value

    def pressure(self):
        """Pressure over the run from the collision virial,
        P = (2 <E_kin> + W / dt) / (d V), with W the virial of the pair collisions between
        the first and last sample and <E_kin> the time average of the kinetic energy
        (trapezoid over the samples: exact for a molecular gas, which keeps E_kin
        constant; sample densely when it changes).  Walls add no virial here: for a
        walled box see ``wall_pressure``."""
        t = self.times
        if len(t) < 2 or t[-1] <= t[0]:
            raise ValueError("pressure needs at least two samples spanning some time")
        span = t[-1] - t[0]
        mean_k = np.trapezoid(self.kinetic_energy, t) / span
        w = self.virial[-1] - self.virial[0]
        return float((2.0 * mean_k + w / span) / (self.dim * self.volume))

    def wall_pressure(self):
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

    def msd(self, per_dimension=False):
        """Ensemble mean squared displacement from the first sample, at every sample
        (summed over dimensions, or (T, d) per dimension)."""
        positions = self._need("positions")
        from . import analysis

        return analysis.msd(positions, per_dimension=per_dimension)

    def tamsd(self, lags, **kwargs):
        """Time-averaged MSD at the given lags; see ``granular.analysis.tamsd``."""
        positions = self._need("positions")
        from . import analysis

        return analysis.tamsd(positions, lags, times=self.times, **kwargs)

    def to_universe(self):
        """An MDAnalysis Universe of the particles (see ``granular.interop.to_universe``)."""
        positions = self._need("positions")
        from . import interop

        box = (self.upper - self.lower) if self.boundary == "periodic" else None
        return interop.to_universe(self.times, positions, box=box, radii=self.radii)

    def __len__(self):
        return len(self.times)

    def __repr__(self):
        span = f"t = {self.times[0]:.4g} .. {self.times[-1]:.4g}" if len(self.times) else "empty"
        return (f"Trajectory({len(self.times)} samples, {span}, n={self.n}, dim={self.dim}, "
                f"stop_reason={self.stop_reason!r})")
