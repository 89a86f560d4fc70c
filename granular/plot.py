"""Figures: each function draws onto the given axes (or new ones) and returns them.

matplotlib (the ``plot`` extra) is imported only when a function is called.  Each function
takes the data it draws by position, x then y as ``ax.plot(x, y)`` does, and everything else
by keyword (``plot.haff(times, temperature, tau0=...)``); the names are the package's (the
table in docs/conventions.md).  Animations of a trajectory:
``animate`` (its own page in the API reference, ``granular.plot.animate``).

Units follow the package's conventions (docs/conventions.md) and every axis says which it
shows:

- ``L``: the length unit of the scene's coordinates -- the box edge in the thesis' unit
  box;
- ``m``: the particle mass (1 unless given);
- ``epsilon``: the energy unit; k_B = 1, so a temperature is an energy in the same unit
  (``T = 2 <E_kin> / d``);
- time in the unit those imply, ``L sqrt(m / epsilon)``; speeds in ``sqrt(epsilon / m)``;
  MSDs in ``L^2``; diffusivities in ``L^2`` per time unit, ``L sqrt(epsilon / m)``.

Ratios and counts are marked dimensionless.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ._animate import animate  # noqa: F401 (public here; animations have their own module)
from ._figures import (
    COLLISIONS,
    DIFFUSIVITY,
    ENERGY,
    LAG_OR_TIME,
    MSD,
    MSD_AND_TAMSD,
    POSITION,
    RELATIVE_ENERGY,
    SPEED,
    SPEED_DENSITY,
    TEMPERATURE,
    TIME,
    _matplotlib,
)
from ._params import keyword_only as _keyword_only

if TYPE_CHECKING:  # matplotlib is an extra, imported only when a figure is drawn
    from matplotlib.axes import Axes

    from .clustering import CurrentCorrelations, FlowEnergy, StructureFactor


def _axes(ax: Axes | None) -> Axes:
    if ax is None:
        plt = _matplotlib("matplotlib.pyplot")
        _, ax = plt.subplots(figsize=(5.5, 4.0), layout="constrained")
    return ax


@_keyword_only("times", "kinetic_energy", "ax", "label", "relative", validate=False)
def energy(
    times: ArrayLike,
    kinetic_energy: ArrayLike,
    *,
    ax: Axes | None = None,
    label: str | None = None,
    relative: bool = True,
) -> Axes:
    """Kinetic energy against time; with ``relative`` the deviation E(t)/E(0) - 1 (thesis
    Fig 4.2: rounding-level for a molecular gas)."""
    ax = _axes(ax)
    e = np.asarray(kinetic_energy, dtype=np.float64)
    y = e / e[0] - 1 if relative else e
    ax.plot(times, y, label=label)
    ax.set_xlabel(TIME)
    ax.set_ylabel(RELATIVE_ENERGY if relative else ENERGY)
    if label:
        ax.legend()
    return ax


@_keyword_only("times", "collisions", "ax", "label", validate=False)
def collisions_per_particle(
    times: ArrayLike, collisions: ArrayLike, *, ax: Axes | None = None, label: str | None = None
) -> Axes:
    """Mean collisions per particle against time (thesis Figs 4.3-4.4)."""
    ax = _axes(ax)
    ax.plot(times, collisions, label=label)
    ax.set_xlabel(TIME)
    ax.set_ylabel(COLLISIONS)
    if label:
        ax.legend()
    return ax


@_keyword_only("velocities", "temperature", "mass", "bins", "ax", "label", validate=False)
def speed_distribution(
    velocities: ArrayLike,
    *,
    temperature: float | None = None,
    mass: float = 1.0,
    bins: int = 40,
    ax: Axes | None = None,
    label: str = "simulation",
) -> Axes:
    """Histogram of speeds with Poisson error bars against Maxwell-Boltzmann (Figs 4.5-4.6)."""
    from . import analysis, theory

    ax = _axes(ax)
    v = np.asarray(velocities, dtype=np.float64)
    dim = v.shape[-1]
    T = float(np.mean(analysis.temperature(v, mass))) if temperature is None else temperature
    # up to the fastest particle, so that the panel is not empty beyond the data
    top = float(np.max(np.linalg.norm(v, axis=-1))) * 1.02
    centres, dens, err = analysis.speed_histogram(v, bins=bins, range=(0.0, top))
    width = centres[1] - centres[0]
    ax.bar(centres, dens, width=width, alpha=0.5, label=label, yerr=err, ecolor="0.4")
    s = np.linspace(0.0, top, 300)
    ax.plot(
        s,
        theory.maxwell_boltzmann_pdf(s, temperature=T, mass=mass, dim=dim),
        "k--",
        label=f"Maxwell-Boltzmann ({dim}D)",
    )
    ax.set_xlabel(SPEED)
    ax.set_ylabel(SPEED_DENSITY)
    ax.legend()
    return ax


@_keyword_only(
    "times", "temperature", "tau0", "temperature0", "ax", "label", "error", validate=False
)
def haff(
    times: ArrayLike,
    temperature: ArrayLike,
    *,
    tau0: float,
    temperature0: float | None = None,
    ax: Axes | None = None,
    label: str = "simulation",
    error: ArrayLike | None = None,
) -> Axes:
    """Granular temperature against Haff's law T0 / (1 + t/tau0)^2 on log-log axes
    (Figs 4.8, 4.10)."""
    from . import theory

    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    T = np.asarray(temperature, dtype=np.float64)
    T0 = T[0] if temperature0 is None else temperature0
    keep = t > 0
    if error is not None:
        ax.errorbar(t[keep], T[keep], yerr=np.asarray(error)[keep], fmt=".", label=label)
    else:
        ax.plot(t[keep], T[keep], ".", label=label)
    ax.plot(
        t[keep],
        theory.haff_temperature(t[keep], temperature0=T0, tau0=tau0),
        "k--",
        label=rf"Haff, $\tau_0$ = {tau0:.3g}",
    )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(TIME)
    ax.set_ylabel(TEMPERATURE)
    ax.legend()
    return ax


@_keyword_only(
    "times",
    "values",
    "error",
    "theory_values",
    "ax",
    "label",
    "theory_label",
    "loglog",
    "theory_style",
    validate=False,
)
def msd(
    times: ArrayLike,
    values: ArrayLike,
    *,
    error: ArrayLike | None = None,
    theory_values: ArrayLike | None = None,
    ax: Axes | None = None,
    label: str = "simulation",
    theory_label: str = "theory",
    loglog: bool = True,
    theory_style: str = "k--",
) -> Axes:
    """MSD against time with error bars and a theory curve (Figs 4.11-4.13, 4.17-4.20);
    ``theory_style`` is its matplotlib format string, to tell several theories apart."""
    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    keep = t > 0 if loglog else np.ones(len(t), dtype=bool)
    y = np.asarray(values)[keep]
    if error is not None:
        ax.errorbar(t[keep], y, yerr=np.asarray(error)[keep], fmt="o", ms=3, label=label)
    else:
        ax.plot(t[keep], y, "o", ms=3, label=label)
    if theory_values is not None:
        ax.plot(t[keep], np.asarray(theory_values)[keep], theory_style, label=theory_label)
    if loglog:
        ax.set_xscale("log")
        ax.set_yscale("log")
    ax.set_xlabel(TIME)
    ax.set_ylabel(MSD)
    ax.legend()
    return ax


@_keyword_only("times", "values", "theory_values", "ax", "label", validate=False)
def diffusivity(
    times: ArrayLike,
    values: ArrayLike,
    *,
    theory_values: ArrayLike | None = None,
    ax: Axes | None = None,
    label: str = "simulation",
) -> Axes:
    """Time-dependent diffusivity (Figs 4.14-4.16)."""
    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    keep = t > 0
    ax.plot(t[keep], np.asarray(values)[keep], "o", ms=3, label=label)
    if theory_values is not None:
        ax.plot(t[keep], np.asarray(theory_values)[keep], "k--", label="theory")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(TIME)
    ax.set_ylabel(DIFFUSIVITY)
    ax.legend()
    return ax


@_keyword_only("times", "msd_values", "lags", "tamsd_values", "ax", "label", validate=False)
def msd_vs_tamsd(
    times: ArrayLike,
    msd_values: ArrayLike,
    *,
    lags: ArrayLike,
    tamsd_values: ArrayLike,
    ax: Axes | None = None,
    label: str = "",
) -> Axes:
    """Ensemble MSD and time-averaged MSD on one log-log plot (Figs 4.21-4.23): equal for an
    ergodic process, apart for a non-ergodic one."""
    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    keep = t > 0
    ax.plot(t[keep], np.asarray(msd_values)[keep], "-", label=f"ensemble MSD {label}".strip())
    ax.plot(lags, tamsd_values, "o", ms=3, label=f"time-averaged MSD {label}".strip())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(LAG_OR_TIME)
    ax.set_ylabel(MSD_AND_TAMSD)
    ax.legend()
    return ax


@_keyword_only("positions", "radii", "lower", "upper", "ax", "color", validate=False)
def snapshot(
    positions: ArrayLike,
    *,
    radii: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    ax: Axes | None = None,
    color: str = "C0",
) -> Axes:
    """Disks of a 2D configuration drawn to scale (Fig 4.9)."""
    EllipseCollection = _matplotlib("matplotlib.collections").EllipseCollection

    ax = _axes(ax)
    x = np.asarray(positions, dtype=np.float64)
    if x.shape[1] != 2:
        raise ValueError("snapshot draws 2D scenes")
    d = 2 * np.broadcast_to(radii, (len(x),))
    ax.add_collection(
        EllipseCollection(
            d,
            d,
            np.zeros(len(x)),
            units="xy",
            offsets=x,
            offset_transform=ax.transData,
            facecolors=color,
        )
    )
    lo, hi = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    ax.set_xlim(float(lo[0]), float(hi[0]))
    ax.set_ylim(float(lo[1]), float(hi[1]))
    ax.set_aspect("equal")
    ax.set_xlabel(POSITION.format("x"))
    ax.set_ylabel(POSITION.format("y"))
    return ax


# -- clustering: where homogeneous cooling ends (granular.clustering) -----------------------

STRUCTURE_FACTOR = r"$S(k, t)$ (dimensionless; 1 for an ideal gas)"
FLOW_RATIO = r"$E_{flow} / E_{thermal}$ (dimensionless)"


@_keyword_only("times", "result", "ax", "shells", "transverse", validate=False)
def structure_factor(
    times: ArrayLike,
    result: StructureFactor,
    *,
    ax: Axes | None = None,
    shells: int = 2,
    transverse: CurrentCorrelations | None = None,
) -> Axes:
    """S(k, t) of the smallest ``|k|`` shells against time (a ``clustering.structure_factor``
    result), and, if given, the transverse current correlation of a
    ``clustering.current_correlations`` result (vortices) dashed in the same colours; both
    are 1 for a homogeneous gas without correlations."""
    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    keep = t > 0
    for s in range(min(shells, len(result.k))):
        (line,) = ax.plot(t[keep], result.values[keep, s], label=rf"$S$, $|n| = {result.n[s]:.3g}$")
        if transverse is not None:
            ax.plot(
                t[keep],
                transverse.transverse[keep, s],
                "--",
                color=line.get_color(),
                label=rf"transverse current, $|n| = {result.n[s]:.3g}$",
            )
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(TIME)
    ax.set_ylabel(STRUCTURE_FACTOR if transverse is None else "correlation (dimensionless)")
    ax.legend(fontsize="small")
    return ax


@_keyword_only("times", "result", "ax", "label", "threshold", validate=False)
def flow_energy(
    times: ArrayLike,
    result: FlowEnergy,
    *,
    ax: Axes | None = None,
    label: str | None = None,
    threshold: float | None = None,
) -> Axes:
    """The coarse-grained flow's energy over the thermal energy against time (a
    ``clustering.flow_energy`` result, or a mean of them), with the level pure noise gives
    (dotted, shaded by its standard deviation) and an optional onset threshold above it."""
    ax = _axes(ax)
    t = np.asarray(times, dtype=np.float64)
    keep = t > 0
    (line,) = ax.plot(t[keep], result.ratio[keep], label=label)
    noise = np.asarray(result.noise)[keep]
    std = np.asarray(result.noise_std)[keep]
    ax.plot(t[keep], noise, ":", color=line.get_color())
    ax.fill_between(t[keep], noise - std, noise + std, color=line.get_color(), alpha=0.15)
    if threshold is not None:
        ax.plot(t[keep], noise + threshold, "--", color=line.get_color(), lw=0.8)
    ax.set_xscale("log")
    ax.set_xlabel(TIME)
    ax.set_ylabel(FLOW_RATIO)
    if label:
        ax.legend(fontsize="small")
    return ax
