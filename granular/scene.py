"""Scenes: the state a simulation starts from, as a validated value object."""

from __future__ import annotations

import inspect
import math
import os
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _edmd, gsd_io
from ._params import check_positive
from ._scales import SCALE_HI, SCALE_LO, check_range
from ._scene_params import BOUNDARIES, NAMES, PARAMETERS, SIGNATURE, engine_keywords, real
from ._scene_params import box_corners as _box_corners
from ._scene_params import docstring as _parameters_doc
from .driving import PairThermostat, WhiteNoise
from .placement import draw_velocities, lattice_order, place_lattice, place_rsa
from .restitution import RestitutionLaw
from .walls import VibratingWall

# Random sequential addition jams near these packing fractions (3D ~0.38, 2D ~0.55);
# above a safe fraction of them Scene.random places on a lattice and melts it instead.
_RSA_LIMIT = {2: 0.40, 3: 0.28}
# The lattice is melted by elastic collisions in blocks of this many per particle until
# no lattice order is left (at most _LATTICE_MELT_MAX), below the packing fraction where
# the fluid freezes (hard spheres 0.494, hard disks ~0.70: above it the equilibrium state
# is not a homogeneous fluid, and a defective lattice is what is left).
_LATTICE_MELT_COLLISIONS = 20.0
_LATTICE_MELT_MAX = 1000.0
_FREEZING = {2: 0.70, 3: 0.494}
# Lattice order Q (see lattice_order) below which the melt counts as done: N for the
# lattice, the mean of S(G) over the stars in a fluid: about 1 (S <= 2.85 below freezing,
# Hansen-Verlet); 3 leaves residual order well below what tests/test_scene.py detects.
_MELTED_ORDER = 3.0
# Up to _core.BIG_MAX particles wider than BIG_RATIO times the median diameter (a tracer)
# are kept out of neighbour searches sized for the others: in the engine's cell grid
# (Simulation's big_ratio) and in random placement.  The rule and its default belong to
# the engine (csrc/big.c); both ask it through _core.
BIG_RATIO: float = _core.BIG_RATIO


# The collision arithmetic (csrc/collide.h) squares lengths, speeds and length x speed (the
# contact-time quadratic) and multiplies a squared length by a mass (the impulse): each is
# kept within granular._scales' range (SCALE_LO to SCALE_HI).
#
# Coordinates must resolve a diameter far more finely than the engine's overlap
# tolerance (a relative 1e-10 of the contact distance, csrc/validate.c): at most this
# fraction of the smallest diameter per float64 step at the box's farthest corner.
_RESOLUTION = 1e-11


def _check_range(name, value, lo, hi):
    check_range(
        name,
        value,
        lo,
        hi,
        "the collision arithmetic",
        "choose units in which diameters, masses and speeds are nearer 1 (e.g. a diameter, "
        "a mass and the thermal speed)",
    )


@np.errstate(over="ignore", under="ignore")
def _check_scales(radii, masses, velocities, lower, upper):
    """Refuse a scene whose scales would under- or overflow the collision formulas, or
    whose coordinates cannot resolve its smallest diameter (see SCALE_LO, _RESOLUTION)."""
    # NumPy scalars: a product past float64 becomes inf (refused below), not OverflowError
    sigma_min, sigma_max = 2.0 * radii.min(), 2.0 * radii.max()
    m_min, m_max = masses.min(), masses.max()
    edge = np.max(upper - lower)
    lo2, hi2 = SCALE_LO**2, SCALE_HI**2
    _check_range("the smallest diameter", sigma_min, SCALE_LO, SCALE_HI)
    _check_range("the largest diameter", sigma_max, SCALE_LO, SCALE_HI)
    _check_range("the longest box edge", edge, SCALE_LO, SCALE_HI)
    _check_range("the smallest mass", m_min, lo2, hi2)
    _check_range("the largest mass", m_max, lo2, hi2)
    _check_range(
        "the smallest diameter squared times the smallest mass", sigma_min**2 * m_min, lo2, hi2
    )
    _check_range(
        "the largest diameter squared times the largest mass", sigma_max**2 * m_max, lo2, hi2
    )
    v_max = np.max(np.abs(velocities))
    # Speeds only from above: a gas too slow to resolve a contact in float64 (a diameter
    # times its speeds below SCALE_LO) is a valid state, e.g. one that inelastic walls
    # cooled; Simulation.run refuses to advance it (FrozenGasError).
    _check_range("the largest speed", v_max, 0.0, SCALE_HI)
    _check_range("the longest box edge times the largest speed", edge * v_max, 0.0, SCALE_HI)
    _check_range("the largest mass times speed squared", m_max * v_max**2, 0.0, hi2)
    far = float(max(np.max(np.abs(lower)), np.max(np.abs(upper))))
    step = float(np.spacing(far))
    if step > _RESOLUTION * sigma_min:
        raise ValueError(
            f"float64 resolves coordinates near {far:.6g} only to steps of {step:.3g}, not "
            f"far enough below the smallest diameter {sigma_min:.3g} (at most "
            f"{_RESOLUTION:g} of it): particles would pass through each other; move the box "
            "nearer the origin"
        )


@np.errstate(over="ignore")
def _check_spin_scales(scene):
    """Rough particles' spins: a radius times a spin is a speed, kept within the speeds'
    limits (the collision formulas add it to the velocities, the energy squares it)."""
    r = scene.radii if scene.dim == 2 else scene.radii[:, None]
    u = float(np.max(np.abs(r * scene.angular_velocities), initial=0.0))
    _check_range("the largest radius times spin", u, 0.0, SCALE_HI)
    _check_range(
        "the largest mass times (radius times spin) squared",
        float(np.max(scene.masses)) * u * u,
        0.0,
        SCALE_HI**2,
    )


def _check_gravity(scene: Scene) -> None:
    """Gravity that needs the box and the boundary: in a periodic box only with
    ``free_fall=True`` (else the centre of mass falls forever unasked), and |g| times the
    box's longest edge (a speed squared: the flight quadratics' 4 a d, csrc/flight.h)
    within SCALE_HI**2, where float64 can still time a flight across a cell."""
    g = scene.gravity
    if g is None:
        return
    if scene.boundary == "periodic" and not scene.free_fall:
        raise ValueError(
            f"gravity = {g.tolist()} in a periodic box has no floor: the centre of mass would "
            "fall forever, its speed growing as g t.  Use boundary='walls' for a floor, or "
            "pass free_fall=True to simulate the freely falling box"
        )
    edge = float(np.max(scene.upper - scene.lower))
    _check_range(
        "|g| times the longest box edge", float(np.max(np.abs(g))) * edge, 0.0, SCALE_HI**2
    )


def frozen_energy(radii, masses):
    """Total kinetic energy below which the speeds times the smallest diameter fall below
    SCALE_LO, where the contact-time arithmetic underflows and pairs would pass through
    each other (speeds estimated with the largest mass, to be safe)."""
    speed = SCALE_LO / (2.0 * float(np.min(radii)))
    return 0.5 * len(radii) * float(np.max(masses)) * speed * speed


def rotational_dim(dim: int) -> int:
    """The rotational degrees of freedom of a particle: 1 in 2D, 3 in 3D."""
    return 1 if dim == 2 else 3


def rotational_energy(spins: Any, scene: Any) -> Any:
    """Rotational kinetic energy sum I w^2 / 2 = sum q m (r w)^2 / 2 of spins (..., N) in 2D
    or (..., N, 3) in 3D of a scene's particles: a float, or an array over the leading axes.
    (r w is a speed: written so, the product stays within float64 wherever the scene's
    scales do.)"""
    w = np.asarray(spins, dtype=np.float64)
    r = np.asarray(scene.radii)
    rw = r * w if scene.dim == 2 else r[:, None] * w
    u2 = rw * rw if scene.dim == 2 else np.sum(rw * rw, axis=-1)
    e = 0.5 * scene.inertia_factor * np.sum(np.asarray(scene.masses) * u2, axis=-1)
    return float(e) if np.ndim(e) == 0 else e


def _set(scene: Scene, name: str, value: Any) -> None:
    """Set a field while the Scene is made (``Scene.__setattr__`` refuses it after)."""
    object.__setattr__(scene, name, value)


_DOC = """Hard disks (2D) or hard spheres (3D) in a box: positions, velocities, radii, masses.

    {parameters}

    Notes
    -----
    A Scene is immutable: its attributes cannot be set (AttributeError) and its arrays are
    read-only; ``replace`` makes a changed copy, checked anew.  It is checked on
    construction: shapes, finite numbers, positive radii and masses, particles inside the
    box, and no two particles overlapping (``OverlapError`` names the pair).  Its parameters
    are declared once, in granular/_scene_params.py.
    """


class Scene:
    # the docstring is _DOC, with the parameters' section made from the declaration
    # (granular/_scene_params.py); so are the constructor's signature and checks

    # the fields, set once in __init__ (through _set: __setattr__ refuses)
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    radii: NDArray[np.float64]
    masses: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    boundary: str
    wall_restitution: float | RestitutionLaw
    restitution: float | RestitutionLaw
    contact_duration: float
    shear_rate: float
    shear_offset: float
    driving: WhiteNoise | PairThermostat | None
    angular_velocities: NDArray[np.float64]
    tangential_restitution: float
    inertia_factor: float
    friction: float
    vibrating_wall: VibratingWall | None
    gravity: NDArray[np.float64] | None
    free_fall: bool

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        try:
            bound = SIGNATURE.bind(*args, **kwargs)
        except TypeError as exc:
            raise TypeError(f"Scene{SIGNATURE}: {exc}") from None
        bound.apply_defaults()
        given = bound.arguments
        pos = real(given["positions"], "positions")
        if pos.ndim != 2 or pos.shape[1] not in (2, 3) or pos.shape[0] < 1:
            raise ValueError(
                f"positions must have shape (N, 2) or (N, 3) with N >= 1, got {pos.shape}"
            )
        n, d = pos.shape
        for p in PARAMETERS:
            kept = p.check(pos if p.name == "positions" else given[p.name], n, d)
            for field, value in zip(p.fields, kept if p.attributes else (kept,), strict=True):
                _set(self, field, value)
            if p.name == "box":  # the scales need the particles' arrays and the box
                _check_scales(self.radii, self.masses, self.velocities, self.lower, self.upper)
                with np.errstate(over="ignore"):
                    finite_energy = math.isfinite(self.kinetic_energy)
                if not finite_energy:
                    raise ValueError(
                        "the kinetic energy overflows: velocities too large for float64"
                    )
        _check_spin_scales(self)
        _check_gravity(self)
        # The geometry (inside the box, overlaps, a periodic box wide enough), checked by
        # the engine's own rules in O(N) through a cell grid, without building an engine.
        _core.edmd_check(**self._engine_keywords())

    def __setattr__(self, name: str, value: Any) -> None:
        # a field set after the checks would skip them (a restitution of 7.5, an overlap)
        field = "box" if name in ("lower", "upper") else name
        how = (
            f"scene.replace({field}=...)"
            if field in NAMES
            else f"scene.replace(...) of its fields {', '.join(NAMES)}"
        )
        raise AttributeError(
            f"a Scene is immutable: {name} cannot be set; make a changed copy, checked "
            f"anew, with {how}"
        )

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"a Scene is immutable: {name} cannot be deleted")

    def _engine_keywords(self) -> dict[str, Any]:
        """The scene as the C engine takes it: the keywords of ``_core.edmd_check`` and
        ``_core.EDMD``, made from the declaration (``_scene_params.engine_keywords``)."""
        return engine_keywords(self)

    # -- derived quantities ---------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of particles."""
        return self.positions.shape[0]

    @property
    def dim(self) -> int:
        """Dimension, 2 or 3."""
        return self.positions.shape[1]

    @property
    def lengths(self) -> NDArray[np.float64]:
        """Box edge lengths, shape (d,)."""
        return self.upper - self.lower

    @property
    def volume(self) -> float:
        """Box volume (area in 2D)."""
        return float(np.prod(self.lengths))

    @property
    def density(self) -> float:
        """Number density N / V."""
        return self.n / self.volume

    @property
    def packing_fraction(self) -> float:
        """Fraction of the box covered by particles (eta, thesis 2.44)."""
        r = self.radii
        unit = math.pi * r**2 if self.dim == 2 else 4.0 / 3.0 * math.pi * r**3
        return float(unit.sum() / self.volume)

    @property
    def kinetic_energy(self) -> float:
        """Total kinetic energy."""
        return float(0.5 * np.sum(self.masses[:, None] * self.velocities**2))

    @property
    def temperature(self) -> float:
        """Granular temperature T = 2 <E_kin> / d per particle (k_B = 1)."""
        return 2.0 * self.kinetic_energy / (self.dim * self.n)

    @property
    def moments_of_inertia(self) -> NDArray[np.float64]:
        """Each particle's moment of inertia I = q m r^2 (q: ``inertia_factor``), shape (N,)."""
        return self.inertia_factor * self.masses * self.radii**2

    @property
    def rotational_energy(self) -> float:
        """Total rotational kinetic energy, sum of I w^2 / 2."""
        return rotational_energy(self.angular_velocities, self)

    @property
    def rotational_temperature(self) -> float:
        """Rotational temperature T_rot = <I w^2> / d_rot per particle, d_rot = 1 in 2D
        (the spin along z), 3 in 3D (Huthmann & Zippelius 1997; k_B = 1)."""
        return 2.0 * self.rotational_energy / (rotational_dim(self.dim) * self.n)

    def replace(self, **changes: Any) -> Scene:
        """A copy with some fields changed, e.g. ``scene.replace(restitution=0.8)``; the
        box is changed as ``box=`` (a length, or the corners (lower, upper))."""
        unknown = set(changes) - set(NAMES)
        if unknown:
            raise TypeError(f"unknown Scene fields: {sorted(unknown)}; a Scene has {NAMES}")
        return Scene(**{p.name: changes.get(p.name, p.get(self)) for p in PARAMETERS})

    def __repr__(self):
        # the gas' summary, then each parameter that is not an array (the wall restitution
        # only where there are walls)
        # (the rough particles' parameters only for rough particles)
        rough = ("tangential_restitution", "inertia_factor", "friction")
        shown = [
            f"{p.name}={p.get(self)!r}"
            for p in PARAMETERS
            if not p.is_array
            and (p.name != "wall_restitution" or self.boundary == "walls")
            and (p.name not in rough or self.tangential_restitution != -1.0)
        ]
        return (
            f"Scene(n={self.n}, dim={self.dim}, packing_fraction={self.packing_fraction:.4g}, "
            f"temperature={self.temperature:.4g}, {', '.join(shown)})"
        )

    # -- constructors ---------------------------------------------------------------
    @classmethod
    def from_gsd(cls, path: str | os.PathLike, frame: int = -1, **params: Any) -> Scene:
        """The scene at one frame (default the last) of a GSD file: exact float64 positions
        (wrapped into the box), velocities and every other parameter of the run's scene
        (restitutions, ...) when granular wrote it (``Trajectory.write``), else from the
        float32 HOOMD fields.  ``params`` are Scene parameters to set (as ``replace``
        does): the boundary of a foreign file, say."""
        return gsd_io.scene_from_gsd(path, frame, cls, **params)

    @classmethod
    def random(
        cls,
        n: int,
        radius: float | ArrayLike,
        dim: int = 3,
        box: float | ArrayLike = 1.0,
        boundary: str = "periodic",
        restitution: float | RestitutionLaw = 1.0,
        *,
        speed: float | None = None,
        temperature: float | None = None,
        mass: float | ArrayLike = 1.0,
        wall_restitution: float | RestitutionLaw = 1.0,
        contact_duration: float = 0.0,
        remove_drift: bool = True,
        seed: Any = None,
    ) -> Scene:
        """Particles placed uniformly without overlap, with random velocities.

        Positions: random sequential addition (accepting uniform candidates that overlap
        nothing), also across periodic images.  Above packing fractions where that jams
        (about 0.28 in 3D, 0.40 in 2D) particles start on a lattice that an elastic EDMD
        run melts, in blocks of 20 collisions per particle until no lattice order is left
        (at most 1000), into an equilibrium fluid.  Above freezing (0.494 in 3D, ~0.70 in
        2D) the equilibrium state is not a homogeneous fluid and the scene stays a
        defective lattice after 20 collisions per particle.  Very dense scenes (past the
        lattice's own limit) raise ValueError.

        Velocities: with ``speed`` (default sqrt(2), the thesis' choice) every particle
        gets that speed in an isotropic random direction -- a normalised Gaussian vector.
        (The thesis' eq. 3.3 draws the polar angle uniformly in [0, pi], which is not
        isotropic: it puts too much speed along z.)  With ``temperature`` velocities are
        Maxwell-Boltzmann, v_a ~ N(0, T/m).  Then the centre-of-mass velocity is
        removed (unless ``remove_drift=False`` or N = 1), so speeds are fixed only up
        to that O(1/sqrt(N)) shift.

        ``seed`` is anything ``numpy.random.SeedSequence`` accepts (or a SeedSequence);
        the same seed gives the same scene bit for bit.
        """
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim}")
        try:
            whole = not isinstance(n, bool) and int(n) == n
        except (OverflowError, ValueError, TypeError):  # inf, nan, "ten"
            whole = False
        if not whole:
            from .errors import shown

            raise ValueError(f"n must be a whole number, got {shown(n)}")
        n = int(n)
        if n < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        if speed is not None and temperature is not None:
            raise ValueError("give speed or temperature, not both")
        radii = np.broadcast_to(check_positive("radius", radius), (n,)).astype(np.float64)
        masses = np.broadcast_to(check_positive("mass", mass), (n,)).astype(np.float64)
        lo, hi = _box_corners(box, dim)
        if boundary not in BOUNDARIES:
            raise ValueError(f"boundary must be one of {BOUNDARIES}, got {boundary!r}")
        ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
        rng_pos, rng_vel, rng_melt = (np.random.default_rng(s) for s in ss.spawn(3))

        volume = float(np.prod(hi - lo))
        unit = math.pi * radii**2 if dim == 2 else 4.0 / 3.0 * math.pi * radii**3
        eta = float(unit.sum() / volume)
        periodic = boundary == "periodic"
        common: dict[str, Any] = dict(
            box=(lo, hi),
            boundary=boundary,
            wall_restitution=wall_restitution,
            restitution=restitution,
            contact_duration=contact_duration,
        )
        velocities = draw_velocities(rng_vel, n, dim, masses, speed, temperature, remove_drift)
        if eta <= _RSA_LIMIT[dim]:
            positions = place_rsa(rng_pos, radii, lo, hi, periodic)
            if positions is not None:
                return cls(positions, velocities, radii, masses, **common)
        positions, G = place_lattice(rng_pos, radii, lo, hi, periodic)
        # Melt the lattice: elastic collisions with thermal velocities until no lattice
        # order is left, then keep the positions and give the scene the velocities asked for.
        melt_v = draw_velocities(rng_melt, n, dim, masses, None, 1.0, n > 1)
        hot = cls(positions, melt_v, radii, masses, box=(lo, hi), boundary=boundary)
        engine = _edmd.build(hot)  # as Simulation(hot) would
        melt = _LATTICE_MELT_COLLISIONS
        while True:
            _edmd.run_collisions(engine, melt)
            if eta >= _FREEZING[dim] or melt >= _LATTICE_MELT_MAX or n < 50:
                break
            # unwrapped positions: G is a reciprocal vector of the periodic box too
            wrapped, _, image = engine.state()
            if lattice_order(wrapped + image * hot.lengths, G) < _MELTED_ORDER:
                break
            melt += _LATTICE_MELT_COLLISIONS
        return cls(engine.state()[0], velocities, radii, masses, **common)

    @classmethod
    def seed_brownian_disks(
        cls,
        seed: Any = None,
        *,
        tracer: bool | None = None,
        tracer_radius: float | None = None,
        tracer_mass: float | None = None,
    ) -> Scene:
        """The 2D Brownian-motion note's scene: 150 elastic hard disks of radius 0.1 and
        mass 1 between elastic walls at +-3, unit speed in random directions; or, with a
        Brownian tracer, one large heavy disk among them.

        Parameters
        ----------
        seed : anything ``numpy.random.SeedSequence`` takes
        tracer : bool, optional
            Add the tracer (implied by ``tracer_radius`` or ``tracer_mass``).  Without it
            the scene is the note's, bit for bit as before the tracer existed.
        tracer_radius : float, default 0.5
            Five times the small disks' radius: a disk that stands out in a picture and
            whose Knudsen number (gas mean free path ~0.3 over its radius) is still near 1.
            Kinetic theory's friction (``theory.tracer_friction``) holds for it at short
            times; over longer ones it diffuses ~20% faster (docs/brownian_tracer.md).
        tracer_mass : float, default (tracer_radius / 0.1)^2
            The small disks' mass per area (25 at the default radius): as heavy as a disk
            of the same material.  Heavy against the gas, as Brownian motion needs
            (m / M = 0.04): its velocity changes little per collision.

        Returns
        -------
        Scene
            Without a tracer, ``Scene.random`` of the note's parameters.  With one, the
            tracer is particle 0, in the middle of the box (where the walls are
            farthest); the 150 small disks are placed around it without overlap (random
            sequential addition); all velocities are Maxwell-Boltzmann at the note's
            temperature T = 0.5 (its unit speed is m v^2 / 2 = 0.5), so that the gas is
            in equilibrium from the start and the tracer has its share of the energy.

        Raises
        ------
        ValueError
            A tracer radius or mass that is not positive and finite, ``tracer=False`` with
            tracer arguments, or a tracer too large to leave room for the gas.
        """
        wants = tracer_radius is not None or tracer_mass is not None
        if tracer is False and wants:
            raise ValueError("tracer=False contradicts tracer_radius / tracer_mass")
        if not (tracer or wants):
            return cls.random(
                150,
                0.1,
                dim=2,
                box=(-3.0, 3.0),
                boundary="walls",
                speed=1.0,
                remove_drift=False,
                seed=seed,
            )
        r, m, lo, hi = 0.1, 1.0, np.full(2, -3.0), np.full(2, 3.0)
        big_r = 5.0 * r if tracer_radius is None else check_positive("tracer_radius", tracer_radius)
        if big_r >= 3.0:
            raise ValueError(f"tracer_radius = {big_r:g} does not fit between the walls at +-3")
        big_m = (
            m * (big_r / r) ** 2
            if tracer_mass is None
            else check_positive("tracer_mass", tracer_mass)
        )
        ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
        rng_pos, rng_vel, rng_tracer = (np.random.default_rng(s) for s in ss.spawn(3))
        radii = np.full(150, r)
        gas = place_rsa(rng_pos, radii, lo, hi, False, fixed=(np.zeros((1, 2)), [big_r]))
        if gas is None:
            raise ValueError(
                f"150 disks of radius {r:g} found no room around a tracer of radius {big_r:g}"
            )
        # Maxwell-Boltzmann at the note's temperature (speed 1 for all is T = m / 2): the
        # tracer meets an equilibrium gas from t = 0, as the Langevin prediction assumes
        # (unit speeds would make its friction 13% larger until the gas relaxes: the
        # friction goes with the gas' mean speed, 1 against sqrt(pi T / 2m) = 0.886)
        temperature = 0.5 * m
        v_gas = draw_velocities(rng_vel, 150, 2, np.full(150, m), None, temperature, False)
        v_big = rng_tracer.normal(size=(1, 2)) * math.sqrt(temperature / big_m)
        return cls(
            np.vstack([np.zeros((1, 2)), gas]),
            np.vstack([v_big, v_gas]),
            np.concatenate([[big_r], radii]),
            np.concatenate([[big_m], np.full(150, m)]),
            box=(lo, hi),
            boundary="walls",
        )

    @classmethod
    def seed_ideal_gas(cls, n: int = 100, radius: float = 0.01, seed: Any = None) -> Scene:
        """The lecture notes' ideal gas: elastic spheres in the unit box with reflecting
        walls and Maxwell-Boltzmann velocities at T = 1."""
        return cls.random(n, radius, dim=3, box=1.0, boundary="walls", temperature=1.0, seed=seed)


Scene.__doc__ = _DOC.format(parameters=_parameters_doc().replace("\n", "\n    "))
Scene.__init__.__signature__ = SIGNATURE.replace(  # type: ignore[attr-defined]
    parameters=[
        inspect.Parameter("self", inspect.Parameter.POSITIONAL_ONLY),
        *SIGNATURE.parameters.values(),
    ]
)
