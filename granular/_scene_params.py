"""A Scene's parameters, each declared once: its name, type, shape, default, unit, meaning,
the check that normalises it, the keywords it becomes in the C engine and how a checkpoint
stores it.  That one declaration (``PARAMETERS``) drives Scene's constructor (its signature
and checks), ``replace``, ``repr``, the engine's arguments (``engine_keywords``), the
checkpoints (arrays or JSON) and the GSD reader's keywords.

Adding a parameter (docs/engine.md, "Adding a scene parameter"): one ``SceneParameter``
here, its field in the engine's config (csrc/edmd.h ``gr_edmd_config``; a number is also
one line of csrc/scene_params.h, which gives the binding its keyword and a checkpoint its
bytes), its check in csrc/validate.c, and the physics that uses it.
tests/test_scene_params.py checks that every parameter reaches the engine by name
(``_core.EDMD_KEYWORDS``), goes through ``replace`` and survives a checkpoint.

Units as in docs/conventions.md: ``L`` the length unit, ``m`` the mass unit, speeds in
``sqrt(eps/m)``, time in ``L sqrt(m/eps)``.
"""

from __future__ import annotations

import inspect
import math
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import driving as _driving
from ._params import check_positive
from ._scales import SCALE_HI, SCALE_LO
from .restitution import ConstantRestitution, RestitutionLaw, engine_law
from .walls import check_scene_wall, engine_wall

BOUNDARIES = ("periodic", "walls")

REQUIRED = inspect.Parameter.empty


@dataclass(frozen=True)
class SceneParameter:
    """One parameter of a Scene.

    Parameters
    ----------
    name : str
        The constructor's and ``replace``'s keyword.
    type : str
        Its type as the documentation states it.
    shape : tuple of str, or None
        An array's shape in ``"N"`` (particles) and ``"d"`` (dimension); None: not an array.
    default : object
        The value when it is not given (``REQUIRED``: it must be).
    unit : str
        Its unit (docs/conventions.md).
    doc : str
        What it means (the constructor's docstring).
    check : callable
        ``check(value, n, d)``: the value as the Scene keeps it, checked (ValueError or
        TypeError naming it otherwise).
    engine : callable
        ``engine(kept)``: the keywords of ``_core.EDMD`` it becomes.
    attributes : tuple of str
        The Scene's attributes that hold it (its name, unless it is split: the box into
        ``lower`` and ``upper``); a checkpoint stores an array under each.
    positional : bool
        Whether the constructor also takes it by position (the particles' arrays).
    """

    name: str
    type: str
    shape: tuple[str, ...] | None
    default: Any
    unit: str
    doc: str
    check: Callable[[Any, int, int], Any]
    engine: Callable[[Any], dict[str, Any]]
    attributes: tuple[str, ...] = ()
    positional: bool = False

    @property
    def fields(self) -> tuple[str, ...]:
        """The Scene's attributes holding the value."""
        return self.attributes or (self.name,)

    @property
    def is_array(self) -> bool:
        """Stored as arrays (a checkpoint's ``scene_<attribute>`` members), else as JSON."""
        return self.shape is not None

    def get(self, scene: Any) -> Any:
        """The value as a Scene keeps it (a tuple of its attributes if it is split)."""
        values = tuple(getattr(scene, a) for a in self.fields)
        return values if self.attributes else values[0]


# -- the checks ---------------------------------------------------------------------------


def real(value: Any, name: str) -> np.ndarray:
    """value as a float64 array, refusing what float64 would silently change: complex
    numbers (the imaginary part dropped) and non-numbers."""
    a = np.asarray(value)
    if np.iscomplexobj(a):
        raise TypeError(f"{name} must be real numbers, got complex")
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be numbers, got dtype {a.dtype}")
    return a.astype(np.float64, copy=False)  # callers that keep it copy it (array)


def array(value: Any, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """A read-only C-ordered float64 copy of ``value`` of ``shape`` (a number fills a
    one-dimensional shape), finite."""
    a = np.array(real(value, name), dtype=np.float64, order="C", copy=True)
    if a.shape != shape:
        if a.ndim == 0 and len(shape) == 1:
            a = np.full(shape, float(a))
        else:
            raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinity")
    a.setflags(write=False)
    return a


def box_corners(box: Any, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) float64 arrays of length dim from a scalar L, a pair (lo, hi) of
    scalars or a pair of length-dim arrays."""
    if np.ndim(box) == 0:
        lo, hi = np.zeros(dim), np.full(dim, float(box))
    else:
        if len(box) != 2:
            raise ValueError("box must be a length L, or a pair (lower, upper)")
        lo = np.broadcast_to(np.asarray(box[0], dtype=np.float64), (dim,)).copy()
        hi = np.broadcast_to(np.asarray(box[1], dtype=np.float64), (dim,)).copy()
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi > lo)):
        raise ValueError(f"box needs finite lower < upper on every axis, got {lo} and {hi}")
    with np.errstate(over="ignore", under="ignore"):
        lengths = hi - lo
        volume = float(np.prod(lengths))
    if not (np.all(np.isfinite(lengths)) and SCALE_LO**2 <= volume <= SCALE_HI**2):
        raise ValueError(
            f"the box's volume {volume:.3g} is outside {SCALE_LO**2:g} .. "
            f"{SCALE_HI**2:g}: choose units nearer the box's size"
        )
    return lo, hi


def _restitution(value: Any, name: str) -> float | RestitutionLaw:
    """A restitution as a Scene keeps it: a law, or a float (a ConstantRestitution's
    number); the caller checks the number's range."""
    if isinstance(value, ConstantRestitution):
        return value.value
    if isinstance(value, RestitutionLaw):
        return value
    try:
        return float(value)
    except TypeError:
        raise TypeError(f"{name} must be a number or a restitution law, got {value!r}") from None


def _positions(value: Any, n: int, d: int) -> np.ndarray:
    return array(value, "positions", (n, d))  # its shape gave n and d (Scene.__init__)


def _velocities(value: Any, n: int, d: int) -> np.ndarray:
    return array(value, "velocities", (n, d))


def _positive(name: str, meaning: str) -> Callable[[Any, int, int], np.ndarray]:
    def check(value: Any, n: int, d: int) -> np.ndarray:
        a = array(value, name, (n,))
        check_positive(name, a, meaning)  # the index in the array is the particle's
        return a

    return check


def _box(value: Any, n: int, d: int) -> tuple[np.ndarray, np.ndarray]:
    lower, upper = box_corners(value, d)
    lower.setflags(write=False)
    upper.setflags(write=False)
    return lower, upper


def _boundary(value: Any, n: int, d: int) -> str:
    if value not in BOUNDARIES:
        raise ValueError(f"boundary must be one of {BOUNDARIES}, got {value!r}")
    return str(value)


def _wall_restitution(value: Any, n: int, d: int) -> float | RestitutionLaw:
    kept = _restitution(value, "wall_restitution")
    if not isinstance(kept, RestitutionLaw):
        kept = check_positive("wall_restitution", kept, "the walls' restitution, > 1 heats")
    return kept


def _pair_restitution(value: Any, n: int, d: int) -> float | RestitutionLaw:
    kept = _restitution(value, "restitution")
    if not isinstance(kept, RestitutionLaw) and not (0.0 <= kept <= 1.0):
        raise ValueError(f"restitution must lie in [0, 1], got {value}")
    return kept


def _contact_duration(value: Any, n: int, d: int) -> float:
    kept = float(value)
    if not (kept >= 0 and math.isfinite(kept)):
        raise ValueError(f"contact_duration must be finite and >= 0, got {value}")
    return kept


# -- rough particles (csrc/rule.h, docs/rough.md) ----------------------------------------

# A spin array's shape symbol: (N,) in 2D (the spin along z), (N, 3) in 3D.
SPIN = "w"
# The default inertia factor q (I = q m r^2): a uniform disk in 2D, a solid sphere in 3D.
INERTIA_FACTOR = {2: 0.5, 3: 0.4}


def spin_shape(n: int, d: int) -> tuple[int, ...]:
    """The shape of N particles' angular velocities in d dimensions."""
    return (n,) if d == 2 else (n, 3)


def _angular_velocities(value: Any, n: int, d: int) -> np.ndarray:
    shape = spin_shape(n, d)
    if value is None:
        a = np.zeros(shape)
        a.setflags(write=False)
        return a
    a = np.array(real(value, "angular_velocities"), dtype=np.float64, order="C", copy=True)
    if a.shape != shape:
        raise ValueError(
            f"angular_velocities must have shape {shape} ((N,) in 2D, (N, 3) in 3D), got {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise ValueError("angular_velocities contains NaN or infinity")
    if np.any(np.abs(a) > SCALE_HI):
        raise ValueError(f"angular_velocities must lie within +-{SCALE_HI:g}")
    a.setflags(write=False)
    return a


def _tangential_restitution(value: Any, n: int, d: int) -> float:
    kept = float(value)
    if not -1.0 <= kept <= 1.0:
        raise ValueError(
            f"tangential_restitution must lie in [-1, 1] (-1 smooth, 1 perfectly rough), "
            f"got {value}"
        )
    return kept


def _inertia_factor(value: Any, n: int, d: int) -> float:
    if value is None:
        return INERTIA_FACTOR[d]
    kept = float(value)
    if not 0.0 < kept <= 1.0:
        raise ValueError(
            f"inertia_factor q (I = q m r^2) must lie in (0, 1] (2/5 a solid sphere, 1/2 a "
            f"disk, 2/3 a hollow sphere), got {value}"
        )
    return kept


def _friction(value: Any, n: int, d: int) -> float:
    kept = float(value)
    if not kept >= 0.0:  # NaN too
        raise ValueError(f"friction must be >= 0 (inf: no Coulomb limit), got {value}")
    return kept


def _spin_keywords(kept: Any) -> dict[str, Any]:
    # engine_keywords gives None instead for a smooth scene (tangential_restitution -1)
    return {"angular_velocities": kept}


def _gravity(value: Any, n: int, d: int) -> np.ndarray | None:
    """None (no field) or a read-only length-d acceleration, finite; all zeros is None
    (the engine's constant-velocity loop either way)."""
    if value is None:
        return None
    a = real(value, "gravity")
    if a.shape != (d,):
        raise ValueError(f"gravity must have one component per axis, shape ({d},), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"gravity must be finite, got {a.tolist()}")
    if not np.any(a):
        return None
    return array(a, "gravity", (d,))


def _free_fall(value: Any, n: int, d: int) -> bool:
    # a number 0 or 1 too: a GSD file logs it as one
    if not (isinstance(value, (bool, np.bool_)) or (np.ndim(value) == 0 and value in (0, 1))):
        raise TypeError(f"free_fall must be True or False, got {value!r}")
    return bool(value)


def _law_keywords(number: str, law: str) -> Callable[[Any], dict[str, Any]]:
    """A restitution's keywords: the number (1, unused, for a law) and the law (None for a
    number: the engine's constant loop)."""

    def engine(kept: Any) -> dict[str, Any]:
        is_law = isinstance(kept, RestitutionLaw)
        return {number: 1.0 if is_law else kept, law: engine_law(kept)}

    return engine


def _same(name: str) -> Callable[[Any], dict[str, Any]]:
    return lambda kept: {name: kept}


# -- the declaration ----------------------------------------------------------------------

PARAMETERS: tuple[SceneParameter, ...] = (
    SceneParameter(
        "positions",
        "array_like",
        ("N", "d"),
        REQUIRED,
        "L",
        "Particle centres, d = 2 or 3.",
        _positions,
        _same("positions"),
        positional=True,
    ),
    SceneParameter(
        "velocities",
        "array_like",
        ("N", "d"),
        REQUIRED,
        "sqrt(eps/m)",
        "Particle velocities.",
        _velocities,
        _same("velocities"),
        positional=True,
    ),
    SceneParameter(
        "radii",
        "float or array_like",
        ("N",),
        REQUIRED,
        "L",
        "Particle radii, > 0 (a number: all alike).",
        _positive("radii", "the particles' radii"),
        _same("radii"),
        positional=True,
    ),
    SceneParameter(
        "masses",
        "float or array_like",
        ("N",),
        1.0,
        "m",
        "Particle masses, > 0 (a number: all alike).",
        _positive("masses", "the particles' masses"),
        _same("masses"),
        positional=True,
    ),
    SceneParameter(
        "box",
        "float, or (lower, upper) with scalars or length-d arrays",
        ("d",),
        1.0,
        "L",
        "A float L means the box [0, L]^d (the thesis' unit box is ``box=1``); the Scene "
        "keeps its corners as ``lower`` and ``upper``.",
        _box,
        lambda kept: {"lower": kept[0], "upper": kept[1]},
        attributes=("lower", "upper"),
    ),
    SceneParameter(
        "boundary",
        '{"periodic", "walls"}',
        None,
        "periodic",
        "",
        "A periodic box, or reflecting walls.",
        _boundary,
        lambda kept: {"periodic": kept == "periodic"},
    ),
    SceneParameter(
        "wall_restitution",
        "float > 0 or RestitutionLaw",
        None,
        1.0,
        "dimensionless",
        "Walls reflect with ``v' = e_w * (v mirrored)`` (thesis eq. 2.22): 1 elastic, < 1 "
        'inelastic, > 1 "heated".  A law (``granular.restitution``) gives e_w from the '
        "normal impact speed ``|v_n|`` of each hit, in the same rule (so the tangential "
        "velocity is scaled by e_w too).  Ignored for periodic boxes.",
        _wall_restitution,
        _law_keywords("wall_restitution", "wall_law"),
    ),
    SceneParameter(
        "restitution",
        "float in [0, 1] or RestitutionLaw",
        None,
        1.0,
        "dimensionless",
        "Coefficient of restitution xi of pair collisions (thesis 2.10-2.11), or a law "
        "xi(v_n) of the normal impact speed: ``granular.Viscoelastic``, "
        "``granular.TabulatedRestitution`` (a ``ConstantRestitution`` is stored as its "
        "number).",
        _pair_restitution,
        _law_keywords("restitution", "law"),
    ),
    SceneParameter(
        "contact_duration",
        "float >= 0",
        None,
        0.0,
        "L sqrt(m/eps)",
        "TC model t_c (thesis 3.6): a collision within t_c of a particle's previous one is "
        "elastic, which prevents inelastic collapse.  0 turns it off.",
        _contact_duration,
        _same("contact_duration"),
    ),
    SceneParameter(
        "driving",
        "None, WhiteNoise or PairThermostat",
        None,
        None,
        "",
        "A random driving force (``granular.driving``): kicks to random pairs at random "
        "times, momentum kept, that heat the gas as white noise (``WhiteNoise``, van Noije "
        "& Ernst 1998) or thermostat it (``PairThermostat``).  None: no driving.",
        lambda value, n, d: _driving.check(value),
        _driving.engine_keywords,
    ),
)


def _finite(name: str) -> Callable[[Any, int, int], float]:
    def check(value: Any, n: int, d: int) -> float:
        kept = float(real(value, name))
        if not math.isfinite(kept):
            raise ValueError(f"{name} must be finite, got {value}")
        return kept

    return check


# Lees-Edwards shear (csrc/boundary.h; docs/shear.md): flow along x, gradient along y
PARAMETERS += (
    SceneParameter(
        "shear_rate",
        "float",
        None,
        0.0,
        "sqrt(eps/m) / L",
        "Shear rate of Lees-Edwards (sliding-brick) boundaries, periodic boxes only: the "
        "images across the upper (lower) y face move along x with +(-) shear_rate * L_y, so "
        "the mean flow is shear_rate * (y - y_centre) along x.  0: a plain periodic box.",
        _finite("shear_rate"),
        _same("shear_rate"),
    ),
    SceneParameter(
        "shear_offset",
        "float in [0, L_x)",
        None,
        0.0,
        "L",
        "The x offset of the image across the upper y face at time 0 (it grows by "
        "shear_rate * L_y per unit time, modulo L_x); a sheared state read back carries its "
        "own.",
        _finite("shear_offset"),
        _same("shear_offset"),
    ),
    # rough particles (csrc/rule.h; docs/rough.md)
    SceneParameter(
        "angular_velocities",
        "array_like or None",
        ("N", SPIN),
        None,
        "sqrt(eps/m) / L",
        "Rough particles' angular velocities: shape (N,) in 2D (the spin along z), (N, 3) "
        "in 3D; None: all at rest.  They change only in collisions of rough particles "
        "(``tangential_restitution`` > -1).",
        _angular_velocities,
        _spin_keywords,
    ),
    SceneParameter(
        "tangential_restitution",
        "float in [-1, 1]",
        None,
        -1.0,
        "dimensionless",
        "Tangential restitution beta of pair collisions (Huthmann & Zippelius 1997): the "
        "contact point's tangential relative velocity becomes -beta times itself.  -1 "
        "smooth (the default: the smooth rule, no spins change), 0 the tangential motion "
        "stopped, 1 perfectly rough (energy kept).  With a finite ``friction`` it is "
        "Walton's beta_0, the sticking value.  Walls stay smooth.",
        _tangential_restitution,
        _same("tangential_restitution"),
    ),
    SceneParameter(
        "inertia_factor",
        "float in (0, 1] or None",
        None,
        None,
        "dimensionless",
        "q in the moment of inertia I = q m r^2 of rough particles; None: 1/2 (a uniform "
        "disk) in 2D, 2/5 (a solid sphere) in 3D.",
        _inertia_factor,
        _same("inertia_factor"),
    ),
    SceneParameter(
        "friction",
        "float >= 0",
        None,
        math.inf,
        "dimensionless",
        "Coulomb friction coefficient mu of Walton's rule (Walton & Braun 1986): a "
        "collision whose tangential impulse would exceed mu times the normal one slides, "
        "with the tangential impulse mu times the normal one; inf: always "
        "``tangential_restitution`` (no Coulomb limit).",
        _friction,
        _same("friction"),
    ),
    # a vibrating wall (csrc/vibwall.h; docs/vibrated.md)
    SceneParameter(
        "vibrating_wall",
        "VibratingWall or None",
        None,
        None,
        "",
        "A wall of a walled box moving along its axis (``granular.VibratingWall``: axis, "
        "side, amplitude, angular frequency, phase, sine or triangle wave), reflecting in "
        "its own frame with ``wall_restitution``; the wall sweeps 2A inwards from its face.  "
        "None: every wall fixed.",
        check_scene_wall,
        engine_wall,
    ),
    # gravity (csrc/flight.h; docs/gravity.md)
    SceneParameter(
        "gravity",
        "array_like or None",
        ("d",),
        None,
        "eps/(m L)",
        "Uniform acceleration g on every particle (an acceleration: length per time "
        "squared), one component per axis: parabolic flight between events "
        "(docs/gravity.md).  None (or zeros): none.  Between walls the floor is the wall g "
        "points at; in a periodic box it needs ``free_fall=True``.",
        _gravity,
        _same("gravity"),
    ),
    SceneParameter(
        "free_fall",
        "bool",
        None,
        False,
        "",
        "Allow gravity in a periodic box: the lab frame of a box falling freely, where the "
        "centre of mass accelerates forever (v grows as g t) while the motion relative to "
        "it is that of the gas without gravity.  Without it such a scene is refused; "
        "between walls it changes nothing.",
        _free_fall,
        _same("free_fall"),
    ),
)

BY_NAME: dict[str, SceneParameter] = {p.name: p for p in PARAMETERS}
# what a trajectory samples; the other parameters are the run's, the same at every sample
# (a Trajectory and a GSD file keep them once)
SAMPLED: tuple[str, ...] = ("positions", "velocities", "angular_velocities")
RUN_PARAMETERS: tuple[SceneParameter, ...] = tuple(p for p in PARAMETERS if p.name not in SAMPLED)
NAMES: tuple[str, ...] = tuple(BY_NAME)
# the Scene's attributes that hold parameters (the box's corners for the box)
FIELDS: tuple[str, ...] = tuple(a for p in PARAMETERS for a in p.fields)

# Scene(positions, velocities, radii, masses=1.0, *, box=1.0, ...), made from the declaration
SIGNATURE = inspect.Signature(
    [
        inspect.Parameter(
            p.name,
            inspect.Parameter.POSITIONAL_OR_KEYWORD
            if p.positional
            else inspect.Parameter.KEYWORD_ONLY,
            default=p.default,
        )
        for p in PARAMETERS
    ]
)


def shape_of(parameter: SceneParameter, n: int, d: int) -> tuple[int, ...]:
    """An array parameter's shape for N particles in d dimensions."""
    assert parameter.shape is not None
    if parameter.shape == ("N", SPIN):
        return spin_shape(n, d)
    return tuple(n if s == "N" else d for s in parameter.shape)


def split(parameter: SceneParameter, kept: Any) -> dict[str, Any]:
    """A kept value as the Scene's attributes that hold it: ``{"lower": .., "upper": ..}``
    for the box, ``{name: kept}`` for the others."""
    return dict(zip(parameter.fields, kept if parameter.attributes else (kept,), strict=True))


def engine_keywords(scene: Any) -> dict[str, Any]:
    """The scene as the C engine takes it: the keywords of ``_core.edmd_check`` and
    ``_core.EDMD``, each parameter's own."""
    keywords: dict[str, Any] = {}
    for p in PARAMETERS:
        keywords.update(p.engine(p.get(scene)))
    if keywords["tangential_restitution"] == -1.0:
        # smooth particles: no spins, so the engine runs the smooth rule (csrc/rule.h), bit
        # for bit the loop of scenes without rough particles; the spins stay as given
        keywords["angular_velocities"] = None
    return keywords


def shape_text(parameter: SceneParameter) -> str:
    """An array parameter's shape as the docs write it: (N, d), (N,)."""
    assert parameter.shape is not None
    if parameter.shape == ("N", SPIN):
        return "(N,) in 2D, (N, 3) in 3D"
    return f"({', '.join(parameter.shape)}{',' if len(parameter.shape) == 1 else ''})"


def docstring() -> str:
    """The constructor's Parameters section, from the declaration."""
    lines = ["Parameters", "----------"]
    for p in PARAMETERS:
        default = "" if p.default is REQUIRED else f", default {p.default!r}"
        unit = f" [{p.unit}]" if p.unit and p.unit != "dimensionless" else ""
        shape = f", shape {shape_text(p)}" if p.shape and p.positional else ""
        lines.append(f"{p.name} : {p.type}{shape}{default}")
        lines += textwrap.wrap(
            f"{p.doc}{unit}", 84, initial_indent="    ", subsequent_indent="    "
        )
    return "\n".join(lines)
