"""The parameters of ``granular.theory`` and ``granular.plot``: one name per quantity, with its
meaning, unit and the values it may take, and the one decorator that enforces the calling
convention.

The convention: a function's independent variable (the time ``t``, the ``lag``, a ``speed``,
a packing fraction ``eta``, a ``box`` size; in ``plot`` the data drawn, x then y as in
matplotlib's ``ax.plot(x, y)``) is positional, everything after it keyword-only.  The
coefficients are floats of similar size, so a positional call that swaps two of them would
give a plausible wrong number without an error.

Units (docs/conventions.md): ``L`` the length unit of the scene, ``m`` the particle mass
unit, ``eps`` the energy unit (k_B = 1: a temperature is an energy), time in
``L sqrt(m / eps)``, ``d`` the dimension.
"""

from __future__ import annotations

import functools
import inspect
import itertools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar, cast

import numpy as np

from ._deprecation import deprecated
from .errors import shown

_F = TypeVar("_F", bound=Callable[..., Any])

TIME = "L sqrt(m/eps)"


@dataclass(frozen=True)
class Quantity:
    """What a parameter name means, its unit, and which values it accepts (``check``:
    ``positive`` > 0 and finite, ``positive_or_inf`` > 0, ``nonnegative`` >= 0 and finite,
    ``restitution`` in [0, 1], ``packing`` in [0, 1), ``dim`` 2 or 3, None unchecked)."""

    meaning: str
    unit: str
    check: str | None = None


# every parameter name of theory and plot; the table in docs/conventions.md is this one
QUANTITIES: dict[str, Quantity] = {
    # independent variables of theory
    "t": Quantity("time at which a formula is evaluated", TIME, "nonnegative"),
    "lag": Quantity("lag of a time average (a window's length)", TIME, "nonnegative"),
    "start": Quantity("start time of a time-average window (or windows)", TIME, "nonnegative"),
    "speed": Quantity("particle speed", "sqrt(eps/m)", "nonnegative"),
    "eta": Quantity("packing fraction (area fraction in 2D)", "dimensionless", "packing"),
    "box": Quantity("side length of a periodic box", "L", "positive"),
    "z": Quantity("height along the axis opposite to gravity", "L"),
    # the gas
    "n": Quantity("number of particles N", "dimensionless count", "positive"),
    "density": Quantity("number density N / V (N / A in 2D)", "L^-d", "positive"),
    "radius": Quantity("particle radius", "L", "positive"),
    "volume": Quantity("volume (area in 2D) of the box", "L^d", "positive"),
    "mass": Quantity("particle mass", "m", "positive"),
    "dim": Quantity("dimension, 2 or 3", "dimensionless", "dim"),
    "restitution": Quantity(
        "constant coefficient of restitution xi", "dimensionless", "restitution"
    ),
    "temperature": Quantity("granular temperature T (k_B = 1)", "eps", "positive"),
    "temperature0": Quantity("temperature T0 at t = 0", "eps", "positive"),
    "critical": Quantity("critical box size L_c of the shear instability", "L", "positive_or_inf"),
    "a_kappa": Quantity(
        "viscoelastic material number A kappa^(2/5), or a restitution.Viscoelastic law",
        "(time/L)^(1/5)",
    ),
    "tracer_radius": Quantity("radius R of a heavy tracer", "L", "positive"),
    "peak_velocity": Quantity(
        "a vibrating wall's peak speed V (A omega for a sine)", "sqrt(eps/m)", "nonnegative"
    ),
    "wall_restitution": Quantity(
        "a wall's coefficient of restitution e", "dimensionless", "positive"
    ),
    "waveform": Quantity('a vibrating wall\'s motion, "sine" or "triangle"', "-"),
    "wall_distance": Quantity(
        "distance between a vibrating wall and the opposite one", "L", "positive"
    ),
    "tracer_mass": Quantity("mass M of a heavy tracer", "m", "positive"),
    "chi": Quantity("gas density at the tracer's surface over n", "dimensionless", "positive"),
    "diffusion": Quantity(
        "self-diffusion coefficient per dimension, <dx^2> = 2 D t", "L^2 / time", "positive"
    ),
    "viscosity": Quantity("shear viscosity", "m / (L^(d-2) time)", "positive"),
    "area": Quantity(
        "cross-section the centres spread over (a length in 2D)", "L^(d-1)", "positive"
    ),
    "bottom": Quantity("height from which particles are counted", "L"),
    "top": Quantity("height up to which particles are counted", "L"),
    "shear_rate": Quantity(
        "shear rate d u_x / d y of a uniform shear flow", "1 / time", "positive"
    ),
    # the models' coefficients
    "D0": Quantity("diffusivity per dimension at t = 0", "L^2 / time", "positive"),
    "gamma0": Quantity("friction rate at t = 0", "1 / time", "positive"),
    "tau0": Quantity("cooling time scale (Haff's tau0; inf: no cooling)", TIME, "positive_or_inf"),
    "exponent": Quantity(
        "exponent a of the power-law coefficients (1 + t/tau0)^-a", "dimensionless", "positive"
    ),
    "v0_sq": Quantity("initial mean squared velocity per component", "eps/m", "nonnegative"),
    # external forces in the Langevin model (theory.trap)
    "stiffness": Quantity("stiffness k of a harmonic trap, per axis", "eps/L^2", "positive"),
    "gravity": Quantity("acceleration g of a uniform force (a component or magnitude)", "L/time^2"),
    "height": Quantity("height z above a wall", "L"),
    "order": Quantity("order of the restitution series, 1 or 2", "dimensionless"),
    "points": Quantity("quadrature nodes", "dimensionless count"),
    "strength": Quantity(
        "white-noise strength xi0^2 (velocity variance per component per time)",
        "eps/(m time)",
        "positive",
    ),
    "approximation": Quantity("which approximation of a theory (its docstring lists them)", "-"),
    "kick": Quantity(
        "one random kick's velocity variance per component over T/m (0: white noise)",
        "dimensionless",
        "nonnegative",
    ),
    # data drawn by plot
    "times": Quantity("sample times of the data drawn", TIME),
    "lags": Quantity("lags of the time-averaged MSD drawn", TIME),
    "kinetic_energy": Quantity("total kinetic energy at each sample", "eps"),
    "collisions": Quantity("mean collisions per particle at each sample", "dimensionless count"),
    "velocities": Quantity("particle velocities, (..., N, d)", "sqrt(eps/m)"),
    "positions": Quantity("particle positions, (N, 2)", "L"),
    "radii": Quantity("particle radii, one or (N,)", "L"),
    "lower": Quantity("lower corner of the box", "L"),
    "upper": Quantity("upper corner of the box", "L"),
    "values": Quantity("the measured quantity at each sample (MSD or diffusivity)", "its unit"),
    "msd_values": Quantity("ensemble MSD at each sample time", "L^2"),
    "tamsd_values": Quantity("time-averaged MSD at each lag", "L^2"),
    "theory_values": Quantity("the theory's curve at each sample", "the unit of values"),
    "error": Quantity("standard error of the data at each sample", "the data's unit"),
    "result": Quantity("a granular.clustering result to draw", "-"),
    "transverse": Quantity("a clustering.current_correlations result (optional)", "-"),
    "threshold": Quantity("onset threshold above the noise level", "dimensionless"),
    # how plot draws
    "ax": Quantity("matplotlib axes to draw on (default: new ones)", "-"),
    "label": Quantity("legend label of the data", "-"),
    "theory_label": Quantity("legend label of the theory curve", "-"),
    "theory_style": Quantity("matplotlib format string of the theory curve", "-"),
    "relative": Quantity("draw E(t)/E(0) - 1 instead of E", "-"),
    "loglog": Quantity("logarithmic axes", "-"),
    "bins": Quantity("histogram bins", "dimensionless count"),
    "shells": Quantity("number of wave-number shells drawn, smallest first", "dimensionless count"),
    "color": Quantity("matplotlib colour", "-"),
    # rough particles (granular.theory.rough)
    "tangential_restitution": Quantity(
        "tangential restitution beta (-1 smooth, 1 perfectly rough)", "dimensionless", "beta"
    ),
    "inertia_factor": Quantity(
        "q in the moment of inertia I = q m r^2 (None: 1/2 in 2D, 2/5 in 3D)",
        "dimensionless",
        "inertia",
    ),
    "rotational_temperature0": Quantity(
        "rotational temperature T_rot = <I w^2> / d_rot at t = 0", "eps", "nonnegative"
    ),
}


_POSITIVE = "must be positive and finite"
_RULES = {
    "positive": (lambda x: (x > 0) & np.isfinite(x), _POSITIVE),
    "positive_or_inf": (lambda x: x > 0, "must be positive (inf allowed)"),
    "nonnegative": (lambda x: (x >= 0) & np.isfinite(x), "must be >= 0 and finite"),
    "restitution": (lambda x: (x >= 0) & (x <= 1), "must lie in [0, 1]"),
    "packing": (lambda x: (x >= 0) & (x < 1), "must lie in [0, 1)"),
    "beta": (lambda x: (x >= -1) & (x <= 1), "must lie in [-1, 1]"),
    "inertia": (lambda x: (x > 0) & (x <= 1), "must lie in (0, 1]"),
}


def check(name: str, value: Any) -> None:
    """Raise ValueError (TypeError for a non-number) naming the parameter, its value and what
    is allowed, if ``value`` breaks the rule of ``QUANTITIES[name]``; None passes (a default).
    Objects where a restitution or material number is expected are left to the function,
    which says what to use instead."""
    rule = QUANTITIES[name].check if name in QUANTITIES else None
    if rule is None or value is None:
        return
    if rule == "dim":
        if value not in (2, 3) or isinstance(value, bool):
            raise ValueError(f"dim must be 2 or 3, got {shown(value)}")
        return
    try:
        x = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        if name == "restitution":
            return  # a law: the function refuses it with its own advice
        raise TypeError(
            f"{name} must be a number or an array of numbers, got a {type(value).__name__} "
            f"({name}: {QUANTITIES[name].meaning})"
        ) from None
    ok, says = _RULES[rule]
    _refuse_unless(ok(x), name, x, says, QUANTITIES[name].meaning)


def _refuse_unless(
    good: np.ndarray, name: str, x: np.ndarray, says: str, meaning: str | None
) -> None:
    """Raise ValueError naming ``name``, the first value of ``x`` that is not ``good``
    (and its index in an array), what is allowed (``says``) and the meaning, if any."""
    if np.all(good):
        return
    about = f" ({name}: {meaning})" if meaning else ""
    if x.ndim == 0:
        raise ValueError(f"{name} {says}, got {shown(x[()])}{about}")
    k = tuple(int(i) for i in np.argwhere(~good)[0])
    index = k[0] if len(k) == 1 else k
    raise ValueError(f"{name} {says}, got {shown(x[k])} in the array (index {index}){about}")


def check_positive(name: str, value: Any, meaning: str | None = None) -> Any:
    """``value`` as a float (an array as a float64 array) if it is positive and finite
    (every element of an array); else ValueError naming the parameter, the value (the
    first bad element and its index) and its meaning -- ``meaning``, or that of
    ``QUANTITIES[name]`` -- and TypeError for what is not a number.

    Parameters
    ----------
    name : str
        The parameter, as the user wrote it.
    value : float or array_like
        What the user gave.
    meaning : str, optional
        What the parameter is, for the message (default: from QUANTITIES, if named there).
    """
    if meaning is None and name in QUANTITIES:
        meaning = QUANTITIES[name].meaning
    try:
        x = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        about = f" ({name}: {meaning})" if meaning else ""
        raise TypeError(f"{name} must be a number, got {shown(value)}{about}") from None
    _refuse_unless((x > 0) & np.isfinite(x), name, x, _POSITIVE, meaning)
    return float(x) if x.ndim == 0 else x


def keyword_only(
    *old_order: str, renamed: dict[str, str] | None = None, validate: bool = True
) -> Callable[[_F], _F]:
    """Decorate a function of the convention (positional independent variable, the rest
    keyword-only), keeping its old calling convention for one release.

    ``old_order`` names the parameters in the order the old signature took them by position
    (old names); ``renamed`` maps old keyword names to new ones.  A call that passes more
    positional arguments than the new signature takes, or an old keyword name, still works
    and gives the same number, with a FutureWarning (shown to users, unlike a
    DeprecationWarning) that spells out the new call and when the old one goes.  With
    ``validate`` every argument is checked by name (``check``) before the call.
    """
    renamed = dict(renamed or {})

    def decorate(func: _F) -> _F:
        sig = inspect.signature(func)
        positional = [
            p.name
            for p in sig.parameters.values()
            if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
        ]
        new_old = [renamed.get(name, name) for name in old_order]
        assert new_old[: len(positional)] == positional, (func.__name__, old_order)
        assert set(new_old) <= set(sig.parameters), (func.__name__, old_order)

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            old_keywords = renamed.keys() & kwargs.keys()
            if len(args) > len(positional) or old_keywords:
                if len(args) > len(old_order):
                    which = f"all but {', '.join(positional)}" if positional else "them"
                    raise TypeError(
                        f"{func.__name__}() takes at most {len(old_order)} positional "
                        f"arguments (deprecated: pass {which} by keyword) but {len(args)} "
                        f"were given"
                    )
                moved = dict(zip(new_old[len(positional) :], args[len(positional) :], strict=False))
                for old in old_keywords:
                    new = renamed[old]
                    if new in kwargs:
                        raise TypeError(f"{func.__name__}() got both {old}= and {new}=")
                    kwargs[new] = kwargs.pop(old)
                for name in moved.keys() & kwargs.keys():
                    raise TypeError(f"{func.__name__}() got multiple values for {name}")
                args = args[: len(positional)]
                kwargs = {**moved, **kwargs}
                _warn(wrapper, args, kwargs, moved, old_keywords, renamed)
            if validate:
                try:
                    bound = sig.bind(*args, **kwargs)
                except TypeError as exc:  # bind's message names no function
                    raise TypeError(f"{func.__name__}() {exc}") from None
                for name, value in bound.arguments.items():
                    check(name, value)
            return func(*args, **kwargs)

        wrapper.__doc__ = _with_parameters(func.__doc__, func)
        # the old convention, for tests and the tools that rewrite callers
        wrapper.old_positional = tuple(old_order)  # type: ignore[attr-defined]
        wrapper.renamed = dict(renamed)  # type: ignore[attr-defined]
        return cast(_F, wrapper)

    return decorate


def _warn(wrapper, args, kwargs, moved, old_keywords, renamed):
    name = f"{wrapper.__module__}.{wrapper.__name__}"
    written = [shown(a) if np.ndim(a) == 0 else "..." for a in args]
    written += [f"{k}={shown(v) if np.ndim(v) == 0 else '...'}" for k, v in kwargs.items()]
    what = []
    if moved:
        what.append("passing " + ", ".join(moved) + " by position")
    if old_keywords:
        what.append(
            "the keyword(s) " + ", ".join(f"{k}= (now {renamed[k]}=)" for k in old_keywords)
        )
    deprecated(f"{name}: {' and '.join(what)}", f"call {name}({', '.join(written)})", stacklevel=4)


def parameters_section(func: Callable[..., Any]) -> str:
    """A numpydoc Parameters section for ``func`` from ``QUANTITIES`` (meaning and unit)."""
    lines = ["Parameters", "----------"]
    for p in inspect.signature(func).parameters.values():
        q = QUANTITIES[p.name]
        kind = p.annotation if isinstance(p.annotation, str) else ""
        if p.default is not inspect.Parameter.empty:
            kind = f"{kind}, optional" if kind else "optional"
        unit = "" if q.unit == "-" else f" [{q.unit}]"
        default = "" if p.default is inspect.Parameter.empty else f"  Default {p.default!r}."
        lines += [
            f"{p.name} : {kind}".rstrip(" :"),
            f"    {q.meaning[0].upper()}{q.meaning[1:]}{unit}.{default}",
        ]
    return "\n".join(lines)


def _with_parameters(doc: str | None, func: Callable[..., Any]) -> str:
    """``doc`` with a generated Parameters section before its first other section, if it has
    none (hand-written sections say more about a parameter, so they are kept)."""
    doc = inspect.cleandoc(doc or "")
    lines = doc.splitlines()
    if any(
        a.strip() == "Parameters" and b.strip().startswith("---")
        for a, b in itertools.pairwise(lines)
    ):
        return doc
    section = parameters_section(func).splitlines()
    for i, (a, b) in enumerate(itertools.pairwise(lines)):
        if a.strip() and set(b.strip()) == {"-"} and len(b.strip()) >= 3:
            return "\n".join(lines[:i] + section + [""] + lines[i:])
    return "\n".join([*lines, "", *section])
