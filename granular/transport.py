"""Transport coefficients measured from equilibrium EDMD runs: the shear viscosity by the
Einstein-Helfand form of Green-Kubo, the self-diffusion coefficient from the MSD, each with
a block-averaged standard error.

Kept apart from ``analysis`` (which holds the MSD and other per-sample statistics): these
estimators share one scheme -- a mean squared displacement of an exactly integrated
quantity, its slope over a window of lags, and blocks of the run for the error -- and the
choice of that window and of the blocks is what a user of them has to understand
(docs/stress.md).

The Helfand moment: for a stress component P_ab (``Trajectory.pressure_tensor``), G_ab(t) =
V int_0^t P_ab dt.  EDMD's collisional stress arrives as impulses (delta functions in
time); G is built from the engine's exact integrals -- the kinetic tensor integrated in
flight through every collision, the impulses summed -- so G has no sampling error at all
(it is the cumulative ``kinetic_time_tensor + stress_collisional`` of the samples).  Then
(Helfand, Phys. Rev. 119, 1 (1960); Allen & Tildesley, 2nd ed., eq. 8.19 and section 8.5)

    < (G(t + s) - G(s))^2 > = 2 V T eta (t - tau_c)    for t >> tau_c,

equivalent to eta = V / T int_0^inf <P_ab(0) P_ab(t)> dt (Green-Kubo) for every t, with
the impulses handled exactly.  The slope over lags well past the stress correlation
time (a few collision times) gives eta; the offset tau_c drops out of the slope.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .trajectory import Trajectory, _pressure_volume

if TYPE_CHECKING:
    from .scene import Scene


@dataclass(frozen=True)
class TransportResult:
    """A transport coefficient with its standard error and the curve it was read from.

    Attributes
    ----------
    value : the coefficient (viscosity in m / (L^(d-2) time); diffusion in L^2 / time, per
        dimension: <dx^2> = 2 D t)
    error : its standard error, from the spread of the blocks' values (std / sqrt(blocks))
    lags : (K,) the lags of the curve
    curve : (K,) the mean squared displacement at those lags, divided by its theory's
        prefactor so that its slope is ``value``: <dG^2> / (2 V T) for the viscosity,
        <dx^2> / (2 d) for diffusion
    fit : (lo, hi), the lags whose slope was taken
    blocks : (B,) each block's value
    """

    value: float
    error: float
    lags: NDArray[np.float64]
    curve: NDArray[np.float64]
    fit: tuple[float, float]
    blocks: NDArray[np.float64]


def shear_moments(trajectory: Trajectory) -> NDArray[np.float64]:
    """(T, k) the Helfand moments G(t) = V int P dt of the trajectory's independent shear
    components, from the first sample on: xy, xz, yz, (xx - yy)/2 and (yy - zz)/2 in 3D;
    xy and (xx - yy)/2 in 2D.  In an isotropic fluid each has the statistics of G_xy (the
    traceless diagonal combinations through rotation by 45 degrees), so all enter one
    average.  Off-diagonal components are symmetrised, (P_ab + P_ba)/2.  Needs a run of
    ``Simulation(stress=True)``."""
    coll = trajectory._need_stress()
    kin = trajectory.kinetic_time_tensor
    assert kin is not None
    g = (kin - kin[0]) + (coll - coll[0])  # V int P dt, exact (module docstring)
    g = 0.5 * (g + np.swapaxes(g, 1, 2))
    if trajectory.dim == 3:
        parts = [g[:, 0, 1], g[:, 0, 2], g[:, 1, 2]]
        parts += [0.5 * (g[:, 0, 0] - g[:, 1, 1]), 0.5 * (g[:, 1, 1] - g[:, 2, 2])]
    else:
        parts = [g[:, 0, 1], 0.5 * (g[:, 0, 0] - g[:, 1, 1])]
    return np.stack(parts, axis=1)


def _uniform_step(times):
    t = np.asarray(times, dtype=np.float64)
    if len(t) < 3:
        raise ValueError("a transport coefficient needs at least 3 samples")
    step = np.diff(t)
    if not np.allclose(step, step[0], rtol=1e-9, atol=0.0):
        raise ValueError("the samples must be uniformly spaced in time (np.linspace)")
    return float(step[0])


def _msd_lags(x, kmax):
    """(kmax,) mean over origins and components of (x[s + k] - x[s])^2 for k = 1..kmax;
    x: (T, ...)."""
    out = np.empty(kmax)
    for k in range(1, kmax + 1):
        dx = x[k:] - x[:-k]
        out[k - 1] = np.mean(dx * dx)
    return out


def _slope(lags, y, lo, hi):
    sel = (lags >= lo) & (lags <= hi)
    if sel.sum() < 2:
        raise ValueError(f"the fit window [{lo:g}, {hi:g}] holds fewer than two lags")
    return float(np.polyfit(lags[sel], y[sel], 1)[0])


def _blocked(times, x, fit, blocks, scale):
    """The slope of the MSD of x (T, ...) over the lags in ``fit``, divided by ``scale``,
    in each of ``blocks`` consecutive blocks of the samples, and over all of them."""
    step = _uniform_step(times)
    lo, hi = (float(f) for f in fit)
    if not 0.0 <= lo < hi:
        raise ValueError(f"fit must be (lo, hi) with 0 <= lo < hi, got {fit}")
    kmax = int(np.floor(hi / step + 1e-9))
    if int(blocks) != blocks or blocks < 2:
        raise ValueError(f"blocks must be a whole number >= 2, got {blocks}")
    size = len(times) // int(blocks)
    if size < 4 * kmax:
        raise ValueError(
            f"each of the {blocks} blocks holds {size} samples, fewer than 4 times the "
            f"{kmax} samples of the longest lag {hi:g}: run longer, or use fewer blocks or "
            "a shorter fit window"
        )
    lags = step * np.arange(1, kmax + 1)
    values = np.array(
        [
            _slope(lags, _msd_lags(x[b * size : (b + 1) * size], kmax) / scale, lo, hi)
            for b in range(int(blocks))
        ]
    )
    curve = _msd_lags(x, kmax) / scale
    return TransportResult(
        value=float(values.mean()),
        error=float(values.std(ddof=1) / np.sqrt(len(values))),
        lags=lags,
        curve=curve,
        fit=(lo, hi),
        blocks=values,
    )


def einstein_helfand(
    times: NDArray[np.float64],
    moments: NDArray[np.float64],
    *,
    volume: float,
    temperature: float,
    fit: tuple[float, float],
    blocks: int = 10,
) -> TransportResult:
    """A transport coefficient from Helfand moments: the slope of <(G(t+s) - G(s))^2> /
    (2 V T) over the lags in ``fit``, averaged over origins s and the columns of
    ``moments``; the error from ``blocks`` consecutive blocks of the samples (their values'
    standard deviation over sqrt(blocks): blocks much longer than the correlation time
    are independent).

    Parameters
    ----------
    times : (T,) uniformly spaced sample times
    moments : (T,) or (T, k) Helfand moments G (``shear_moments``), each column one
        component with the same statistics
    volume : V (L^d)
    temperature : T, an energy (k_B = 1)
    fit : (lo, hi), the lags (time) whose slope is taken: lo well past the correlation
        time of the flux (a few collision times for the stress)
    blocks : int >= 2
    """
    g = np.asarray(moments, dtype=np.float64)
    if g.shape[0] != len(times):
        raise ValueError(f"moments has {g.shape[0]} rows for {len(times)} times")
    if not (volume > 0 and temperature > 0):
        raise ValueError(f"volume and temperature must be > 0, got {volume}, {temperature}")
    return _blocked(times, g, fit, blocks, 2.0 * volume * temperature)


def shear_viscosity(
    trajectory: Trajectory, *, fit: tuple[float, float], blocks: int = 10
) -> TransportResult:
    """The shear viscosity of an equilibrium run by Einstein-Helfand (Green-Kubo, module
    docstring), averaged over the shear components of ``shear_moments``.  T = 2 <E_kin> /
    (d (N - 1)) (the total momentum is conserved: d (N - 1) degrees of freedom), V the box.
    In 2D the stress autocorrelation's t^-1 tail makes the Green-Kubo integral grow like
    ln t (Alder & Wainwright): a 2D value depends on the fit window and the box.

    Parameters
    ----------
    trajectory : a run of ``Simulation(stress=True)`` sampled uniformly in time
    fit : (lo, hi) lags (time) whose slope gives eta; see ``einstein_helfand``
    blocks : int >= 2, blocks for the standard error
    """
    if trajectory.boundary != "periodic":
        raise ValueError("shear_viscosity needs a periodic box (walls shear the flow)")
    temperature = float(
        2.0 * np.mean(trajectory.kinetic_energy) / (trajectory.dim * (trajectory.n - 1))
    )
    volume = _pressure_volume(
        trajectory.lower, trajectory.upper, trajectory.radii, trajectory.boundary
    )
    return einstein_helfand(
        trajectory.times,
        shear_moments(trajectory),
        volume=volume,
        temperature=temperature,
        fit=fit,
        blocks=blocks,
    )


def self_diffusion(
    trajectory: Trajectory, *, fit: tuple[float, float], blocks: int = 10
) -> TransportResult:
    """The self-diffusion coefficient per dimension, D = slope of <dx^2> / (2 d) over the
    lags in ``fit`` (all particles, all origins; the centre of mass, which a periodic
    elastic gas keeps at rest, subtracted), with a block-averaged standard error.

    This is D in the box simulated; ``theory.diffusion_infinite_system`` corrects a 3D
    cubic box to infinite size (Yeh & Hummer 2004).

    Parameters
    ----------
    trajectory : a run sampled uniformly in time with positions stored
    fit : (lo, hi) lags (time) past the velocity correlation time (a few collision times)
    blocks : int >= 2
    """
    x = trajectory._need("positions")
    x = x - np.average(x, axis=1, weights=trajectory.masses)[:, None, :]
    return _blocked(trajectory.times, x, fit, blocks, 2.0)  # mean over d gives /(2 d) per axis


# -- the viscosity from a sheared run (non-equilibrium MD) ----------------------------------


@dataclass(frozen=True)
class ShearWindows:
    """A sheared run's stress and temperature window by window (between its samples),
    reduced by the particle diameter sigma, mass m and the window's temperature T.

    Attributes
    ----------
    times : (W,) the windows' middle times
    temperature : (W,) T over the window, exact: trace(int K dt) / (d (N - 1) dt) with K
        the peculiar kinetic tensor (the peculiar momentum is conserved: d (N - 1) degrees
        of freedom when it is zero, as ``with_shear_profile`` makes it)
    shear_rate : (W,) the reduced shear rate gamma* = gamma sigma / sqrt(T / m)
    viscosity : (W,) the reduced viscosity eta* = -P_xy / gamma sigma^(d-1) / sqrt(m T),
        P_xy symmetrised, over the window
    span : (W,) the windows' lengths in the time unit sigma / sqrt(T / m)
    """

    times: NDArray[np.float64]
    temperature: NDArray[np.float64]
    shear_rate: NDArray[np.float64]
    viscosity: NDArray[np.float64]
    span: NDArray[np.float64]


@dataclass(frozen=True)
class NemdResult:
    """The zero-shear viscosity extrapolated from sheared runs.

    Attributes
    ----------
    value : eta*_0, the reduced viscosity at gamma* -> 0 (mean over the runs)
    error : its standard error, the runs' spread / sqrt(runs)
    slope : the fitted coefficient c of eta* = eta*_0 + c gamma*^power (mean over runs)
    power : the power of the leading correction fitted
    runs : (R,) each run's eta*_0
    """

    value: float
    error: float
    slope: float
    power: float
    runs: NDArray[np.float64]


def with_shear_profile(scene: Scene, shear_rate: float) -> Scene:
    """The scene sheared at ``shear_rate`` (1 / time) with its velocities made peculiar
    ones (zero total momentum, the temperature kept) plus the flow shear_rate (y - y_c)
    along x: a uniform shear flow from the start, so that only the stress, not the flow
    profile, has to develop.  Returns a new Scene (shear_offset 0)."""
    v = np.array(scene.velocities, dtype=np.float64)
    m = np.asarray(scene.masses, dtype=np.float64)
    v -= np.average(v, axis=0, weights=m)
    before = float(np.sum(m[:, None] * np.asarray(scene.velocities) ** 2))
    after = float(np.sum(m[:, None] * v * v))
    if after > 0:
        v *= np.sqrt(before / after)
    y_c = 0.5 * (float(scene.lower[1]) + float(scene.upper[1]))
    v[:, 0] += shear_rate * (np.asarray(scene.positions)[:, 1] - y_c)
    return scene.replace(velocities=v, shear_rate=float(shear_rate), shear_offset=0.0)


def shear_windows(trajectory: Trajectory) -> ShearWindows:
    """The reduced shear rate, viscosity and temperature of a sheared run (docs/shear.md)
    in each window between consecutive samples, from the exact integrals of the stress
    tensor (``Simulation(stress=True)`` in a box with ``shear_rate`` != 0; equal radii and
    masses).

    An elastic gas heats under shear (the viscous heating -gamma V P_xy), so its reduced
    shear rate falls as 1 / sqrt(T): one run sweeps gamma* towards 0
    (``nemd_viscosity`` extrapolates).

    Parameters
    ----------
    trajectory : a sheared run of ``Simulation(stress=True)``, from a scene whose
        peculiar momentum is zero (``with_shear_profile``)
    """
    coll = trajectory._need_stress()
    kin = trajectory.kinetic_time_tensor
    assert kin is not None
    rate = float(trajectory.scene_parameters.get("shear_rate", 0.0))
    if rate == 0.0:
        raise ValueError("shear_windows needs a sheared run (shear_rate != 0)")
    radii, masses = np.asarray(trajectory.radii), np.asarray(trajectory.masses)
    if np.ptp(radii) != 0.0 or np.ptp(masses) != 0.0:
        raise ValueError("shear_windows needs equal radii and equal masses (one sigma, one m)")
    if len(trajectory.times) < 2:
        raise ValueError("shear_windows needs at least 2 samples")
    sigma, m = 2.0 * float(radii[0]), float(masses[0])
    d, n = trajectory.dim, trajectory.n
    dt = np.diff(trajectory.times)
    if not np.all(dt > 0):
        raise ValueError("the samples must be at increasing times")
    volume = _pressure_volume(trajectory.lower, trajectory.upper, radii, "periodic")
    dk, dw = np.diff(kin, axis=0), np.diff(coll, axis=0)
    temp = np.trace(dk, axis1=1, axis2=2) / (d * (n - 1) * dt)
    pxy = 0.5 * ((dk + dw)[:, 0, 1] + (dk + dw)[:, 1, 0]) / (volume * dt)
    thermal = np.sqrt(temp / m)
    return ShearWindows(
        times=0.5 * (trajectory.times[1:] + trajectory.times[:-1]),
        temperature=temp,
        shear_rate=np.abs(rate) * sigma / thermal,
        viscosity=-pxy / rate * sigma ** (d - 1) / np.sqrt(m * temp),
        span=dt * thermal / sigma,
    )


def nemd_viscosity(runs: list[ShearWindows], *, max_rate: float, power: float = 2.0) -> NemdResult:
    """The zero-shear reduced viscosity from independent sheared runs: in each, the
    windows with gamma* <= max_rate fitted by eta* = eta*_0 + c gamma*^power (least
    squares weighted by each window's information, gamma*^2 times its reduced length: the
    noise of a window's -P_xy is that of equilibrium, sqrt(2 T eta / (V dt)), so its
    eta* has variance proportional to 1 / (gamma*^2 dt)); eta*_0 and c averaged over the
    runs, the error from their spread.

    The leading correction: analytic, gamma*^2 (power=2), in a dilute gas (the Burnett
    order of the Chapman-Enskog expansion; the temperature's own rise under shear enters
    at the same order) and, within the precision of simulations, in simple liquids
    (Ferrario, Ciccotti, Holian & Ryckaert, Phys. Rev. A 44, 6936 (1991)); mode coupling
    predicts sqrt(gamma*) (power=0.5) asymptotically in a dense fluid (Kawasaki & Gunton,
    Phys. Rev. A 8, 2048 (1973); Evans & Morriss, Statistical Mechanics of Nonequilibrium
    Liquids, 2nd ed., ch. 9).  Fitting both and comparing says how much the choice matters.

    Parameters
    ----------
    runs : the ``shear_windows`` of two or more independent runs
    max_rate : the largest gamma* fitted (dimensionless)
    power : the power of the leading correction, > 0
    """
    if len(runs) < 2:
        raise ValueError(f"nemd_viscosity needs at least 2 independent runs, got {len(runs)}")
    if not (max_rate > 0 and power > 0):
        raise ValueError(f"max_rate and power must be > 0, got {max_rate}, {power}")
    fits = []
    for w in runs:
        sel = w.shear_rate <= max_rate
        if sel.sum() < 3:
            raise ValueError(
                f"a run has {int(sel.sum())} windows with gamma* <= {max_rate:g}: needs 3"
            )
        g, e = w.shear_rate[sel], w.viscosity[sel]
        weight = np.sqrt(g**2 * w.span[sel])
        a = np.stack([np.ones_like(g), g**power], axis=1) * weight[:, None]
        coef = np.linalg.lstsq(a, e * weight, rcond=None)[0]
        fits.append(coef)
    f = np.array(fits)
    return NemdResult(
        value=float(f[:, 0].mean()),
        error=float(f[:, 0].std(ddof=1) / np.sqrt(len(f))),
        slope=float(f[:, 1].mean()),
        power=float(power),
        runs=f[:, 0],
    )
