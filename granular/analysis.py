"""Data reduction: arrays in, arrays out, no loops over particles or samples in Python.

Shapes: ``times (T,)``, ``positions (T, N, d)`` unwrapped, ``velocities (T, N, d)`` or
``(N, d)`` for one snapshot.  MSDs are totals over the d dimensions unless asked per
dimension, as in ``granular.theory``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import shown


def _positions(positions):
    x = np.asarray(positions, dtype=np.float64)
    if x.ndim != 3:
        raise ValueError(f"positions must have shape (T, N, d), got {x.shape}")
    return x


def _times(times, count=None):
    t = np.asarray(times, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError("times must be one-dimensional")
    if count is not None and len(t) != count:
        raise ValueError(f"times has {len(t)} entries, positions {count} samples")
    if np.any(np.diff(t) <= 0):
        raise ValueError("times must be strictly increasing")
    return t


# -- mean squared displacements -------------------------------------------------------------


def _select(x, particles):
    """Positions (T, N, d) of the chosen particles: indices, or a boolean mask over all N."""
    if particles is None:
        return x
    p = np.asarray(particles)
    n = x.shape[1]
    if p.dtype == bool:
        if p.shape != (n,):
            raise ValueError(
                f"a boolean particles mask must have one entry per particle "
                f"({n}), got shape {p.shape}"
            )
        p = np.nonzero(p)[0]
    elif p.size and not np.issubdtype(p.dtype, np.integer):
        raise TypeError(f"particles must be indices (integers) or a boolean mask, got {p.dtype}")
    p = p.reshape(-1).astype(np.int64)
    if p.size == 0:
        raise ValueError("particles selects no particle")
    if np.any((p < -n) | (p >= n)):
        raise IndexError(f"particles holds indices outside 0..{n - 1}")
    return x[:, p, :]


def msd(
    positions: ArrayLike, per_dimension: bool = False, particles: ArrayLike | None = None
) -> NDArray[np.float64]:
    """Ensemble MSD ``<|x(t) - x(0)|^2>`` over particles at every sample (any spacing).

    Returns (T,) summed over dimensions, or (T, d) with ``per_dimension=True``.
    ``particles`` (indices, or a boolean mask over all N) averages over those only,
    e.g. a tracer.
    """
    x = _select(_positions(positions), particles)
    d = x - x[0]
    out = np.einsum("tna,tna->ta", d, d) / x.shape[1]
    return out if per_dimension else out.sum(axis=1)


def _uniform(times):
    dt = np.diff(times)
    return len(dt) > 0 and np.allclose(dt, dt[0], rtol=1e-9, atol=0)


def _nearest_on_grid(lag: float, spacing: float, k_max: int) -> str:
    """The one or two multiples of ``spacing`` nearest to ``lag`` (below and above it),
    from 1 to ``k_max`` of them, as text for a message."""
    steps = lag / spacing
    ks = {min(max(math.floor(steps), 1), k_max), min(max(math.ceil(steps), 1), k_max)}
    return " and ".join(shown(k * spacing) for k in sorted(ks))


def _nearest_differences(t: NDArray[np.float64], lag: float) -> list[float]:
    """The differences of sample times nearest to ``lag``: the largest below it and the
    smallest above it (either may be missing), in O(T log T) without forming all pairs."""
    out = []
    j = np.searchsorted(t, t + lag, side="right") - 1  # latest sample at or before t_i + lag
    below = t[j] - t
    below = below[(j > np.arange(len(t))) & (below < lag)]
    if below.size:
        out.append(float(below.max()))
    j = np.searchsorted(t, t + lag, side="left")  # earliest sample at or after t_i + lag
    ok = j < len(t)
    above = t[j[ok]] - t[ok]
    above = above[above > lag]
    if above.size:
        out.append(float(above.min()))
    return out


def tamsd(
    positions: ArrayLike,
    lags: ArrayLike | None = None,
    times: ArrayLike | None = None,
    *,
    lag_samples: ArrayLike | None = None,
    method: str = "auto",
    per_particle: bool = False,
    particles: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Time-averaged MSD (thesis 2.114-2.115) at the given lags, averaged over particles.

    For each particle, ``delta^2(lag) = mean_k |x(t_k + lag) - x(t_k)|^2`` over all sample
    pairs that are ``lag`` apart, summed over dimensions; then the mean over particles
    (or all of them, (N, L), with ``per_particle=True``).

    Parameters
    ----------
    lags : array_like, optional
        Without ``times``: lags in samples (integers).  With ``times``: lags in time
        units, each of which must match a difference of sample times (to 1e-9 relative;
        with uniform sampling, a multiple of the spacing).
    times : (T,) array, optional
    lag_samples : array_like of int, optional
        Lags as whole numbers of samples, instead of ``lags`` (uniform sampling).
    method : "auto", "fft" or "direct"
        "fft" (uniform sampling only): all lags at once in O(T log T) per particle, from
        the autocorrelation of positions taken relative to each particle's start (which
        keeps the rounding of the squared sums small).  "direct": pairs of samples
        ``lag`` apart, for any sampling.  "auto" picks FFT when sampling is uniform.
    particles : array_like of int or bool, optional
        Only these particles (indices, or a boolean mask over all N), e.g. a tracer.
    """
    x = _select(_positions(positions), particles)
    T = x.shape[0]
    if times is not None:
        t = _times(times, T)
    else:
        t = np.arange(T, dtype=np.float64)
    uniform = _uniform(t)
    if (lags is None) == (lag_samples is None):
        raise TypeError("give exactly one of lags (in time) and lag_samples (in samples)")
    if lag_samples is not None:
        k = np.atleast_1d(np.asarray(lag_samples))
        if k.size and not np.issubdtype(k.dtype, np.integer):
            if not np.all(np.isfinite(k)) or np.any(k != np.rint(k)):
                raise ValueError(f"lag_samples must be whole numbers of samples, got {shown(k)}")
        k = k.astype(np.int64)
        if np.any(k < 1) or np.any(k > T - 1):
            raise ValueError(
                f"lag_samples must be between 1 and {T - 1} (the trajectory "
                f"has {T} samples), got {shown(k)}"
            )
        if times is not None and not uniform:
            raise ValueError("lag_samples needs uniformly spaced samples; give lags in time")
        lags = k * (t[1] - t[0])
    lags = np.atleast_1d(np.asarray(lags, dtype=np.float64))
    if not np.all(np.isfinite(lags)) or np.any(lags <= 0) or np.any(lags > t[-1] - t[0]):
        raise ValueError(
            f"lags must be positive and no longer than the trajectory "
            f"({shown(t[-1] - t[0])}), got {shown(lags)}"
        )
    if method == "auto":
        method = "fft" if uniform else "direct"
    if method == "fft":
        if not uniform:
            raise ValueError("the FFT method needs uniformly spaced samples; use method='direct'")
        spacing = t[1] - t[0]
        steps = lags / spacing
        k = np.rint(steps).astype(np.int64)
        bad = ~np.isclose(steps, k, rtol=1e-9, atol=1e-9)
        if np.any(bad):
            lag = float(lags[bad][0])
            raise ValueError(
                f"lag {shown(lag)} is not a multiple of the sample spacing {shown(spacing)}; "
                f"the nearest lags that are: {_nearest_on_grid(lag, spacing, T - 1)} (or give "
                "lag_samples= in samples)"
            )
        out = _tamsd_fft(x, k)
    elif method == "direct":
        out = _tamsd_direct(x, t, lags)
    else:
        raise ValueError(f"method must be 'auto', 'fft' or 'direct', got {method!r}")
    return out if per_particle else out.mean(axis=0)


def _tamsd_fft(x, k, chunk_bytes=2**27):
    """(N, L) TAMSD at integer lags k by the FFT algorithm, in chunks of particles."""
    T, N, d = x.shape
    nfft = 1 << math.ceil(math.log2(2 * T))
    out = np.empty((N, len(k)))
    per_particle = 16 * (nfft // 2 + 1) * d + 8 * T * d
    step = max(1, int(chunk_bytes // per_particle))
    for lo in range(0, N, step):
        y = x[:, lo : lo + step, :] - x[0, lo : lo + step, :]  # relative to the start
        f = np.fft.rfft(y, n=nfft, axis=0)
        auto = np.fft.irfft(f * f.conj(), n=nfft, axis=0)[:T]  # sum_j y_j y_{j+m}
        sq = np.cumsum(y * y, axis=0)  # Q[m] = sum_{j<=m} y_j^2
        total = sq[-1]
        head = sq[T - 1 - k]  # sum_{j=0}^{T-1-m} y_j^2
        tail = total - np.where((k >= 1)[:, None, None], sq[np.maximum(k - 1, 0)], 0.0)
        s = (head + tail - 2.0 * auto[k]) / (T - k)[:, None, None]
        out[lo : lo + step] = s.sum(axis=2).T
    return out


def _tamsd_direct(x, t, lags):
    """(N, L) TAMSD from the pairs of samples exactly `lag` apart (any sampling)."""
    T, N, _ = x.shape
    out = np.empty((N, len(lags)))
    for m, lag in enumerate(lags):
        target = t + lag
        j = np.clip(np.searchsorted(t, target), 0, T - 1)
        j_lo = np.clip(j - 1, 0, T - 1)
        pick = np.where(np.abs(t[j_lo] - target) < np.abs(t[j] - target), j_lo, j)
        ok = np.isclose(t[pick], target, rtol=1e-9, atol=1e-12 * max(1.0, abs(t[-1])))
        i = np.nonzero(ok)[0]
        if len(i) == 0:
            near = _nearest_differences(t, lag)
            raise ValueError(
                f"no pair of sample times is {shown(lag)} apart (to 1e-9 relative): the "
                f"nearest lags these samples have are {' and '.join(map(shown, near))}.  "
                f"For a lag of {shown(lag)}, sample at uniformly spaced times (every "
                "multiple of the spacing is then a lag), or include both t and "
                f"t + {shown(lag)} among the sample times"
            )
        diff = x[pick[i]] - x[i]
        out[:, m] = np.einsum("pna,pna->n", diff, diff) / len(i)
    return out


def ergodicity_breaking(tamsd_per_particle: ArrayLike) -> NDArray[np.float64]:
    """Ergodicity-breaking parameter at each lag from the particles' time-averaged MSDs,
    ``EB = (<delta^2 ^2> - <delta^2>^2) / <delta^2>^2`` over the particles (thesis
    2.114-2.119; He, Burov, Metzler & Barkai, PRL 101, 058101 (2008)); it goes to 0 for an
    ergodic process as the run grows long against the lag.  The variance is the
    particles' own (ddof 0), as in the definition.

    Parameters
    ----------
    tamsd_per_particle : (N, L) array_like
        One row per particle, one column per lag (length^2): e.g.
        ``tamsd(..., per_particle=True)`` of any result.

    Returns
    -------
    (L,) ndarray, dimensionless.
    """
    per = np.asarray(tamsd_per_particle, dtype=np.float64)
    if per.ndim != 2:
        raise ValueError(f"tamsd_per_particle must have shape (N, L), got {per.shape}")
    if per.shape[0] < 2:
        raise ValueError(
            f"the ergodicity-breaking parameter is a variance over particles: it needs at "
            f"least 2, got {per.shape[0]}"
        )
    mean = per.mean(axis=0)
    return per.var(axis=0) / mean**2


def diffusivity(times: ArrayLike, msd_values: ArrayLike, dim: int = 3) -> NDArray[np.float64]:
    """Time-dependent diffusivity ``D(t) = (1 / 2d) d MSD / dt`` (3D form of 2.64), with
    the derivative taken as the mean of the forward and backward differences (4.1, 4.2)
    on any grid; one-sided at the two ends."""
    t = _times(times)
    m = np.asarray(msd_values, dtype=np.float64)
    if m.shape[0] != len(t) or len(t) < 2:
        raise ValueError("msd must have one value per time, at least two")
    slope = np.diff(m, axis=0) / np.diff(t).reshape((-1,) + (1,) * (m.ndim - 1))
    deriv = np.empty_like(m)
    deriv[0] = slope[0]
    deriv[-1] = slope[-1]
    deriv[1:-1] = 0.5 * (slope[:-1] + slope[1:])
    return deriv / (2.0 * dim)


def _window(t, t_min, t_max, what):
    """The samples with t_min <= t <= t_max (either bound may be None), at least three."""
    sel = np.ones(len(t), dtype=bool)
    if t_min is not None:
        sel &= t >= t_min
    if t_max is not None:
        sel &= t <= t_max
    if sel.sum() < 3:
        raise ValueError(
            f"{what} needs at least three points in [t_min, t_max] = [{shown(t_min)}, "
            f"{shown(t_max)}], got {int(sel.sum())}"
        )
    return sel


def _positive_for_log(x, name, t):
    """Refuse x <= 0 (or NaN) before its logarithm: -inf would reach the least squares."""
    bad = ~(x > 0)
    if np.any(bad):
        i = int(np.argmax(bad))
        hint = "; give t_min > 0" if name == "t" else ""
        raise ValueError(
            f"a fit against ln {name} needs {name} > 0 in the window, got {name} = "
            f"{shown(x[i])} at t = {shown(t[i])}{hint}"
        )


def _line(xs, ys):
    """Ordinary least squares ys = slope * xs + intercept: (slope, intercept, standard
    error of the slope from the residuals)."""
    A = np.vstack([xs, np.ones_like(xs)]).T
    coef, *_ = np.linalg.lstsq(A, ys, rcond=None)
    dof = len(xs) - 2
    resid = ys - A @ coef
    s2 = float(resid @ resid) / dof if dof > 0 else np.nan
    cov = s2 * np.linalg.inv(A.T @ A)
    return float(coef[0]), float(coef[1]), float(math.sqrt(cov[0, 0]))


def fit_slope(
    times: ArrayLike,
    values: ArrayLike,
    t_min: float | None = None,
    t_max: float | None = None,
    log: bool = False,
) -> tuple[float, float, float]:
    """Least-squares straight line through ``values`` against ``times`` (or against
    ``ln(times)`` with ``log=True``: the long-time MSD of a granular gas grows like
    ln t) between t_min and t_max, as in the thesis' App. F.  For a power law (values
    against t on log-log axes) see ``fit_power_law``.

    Returns (slope, intercept, slope_standard_error) -- the error from the residuals
    (ordinary least squares), which understates it for correlated MSD points.
    """
    t = np.asarray(times, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    sel = _window(t, t_min, t_max, "fit_slope")
    if log:
        _positive_for_log(t[sel], "t", t[sel])
    return _line(np.log(t[sel]) if log else t[sel], v[sel])


def fit_power_law(
    times: ArrayLike,
    values: ArrayLike,
    *,
    t_min: float | None = None,
    t_max: float | None = None,
) -> tuple[float, float, float]:
    """Fit a power law ``values = prefactor * t**exponent`` between t_min and t_max: the
    least-squares straight line through ``ln(values)`` against ``ln(t)``, the slope of
    the curve on log-log axes.  Over a window short next to the curve's bends it is the
    local exponent ``d ln MSD / d ln t`` there: 2 for ballistic motion, 1 for diffusion,
    1/6 for the late MSD of a viscoelastic gas.

    Parameters
    ----------
    times : (T,) array
        Sample times (time units); those in the window must be > 0.
    values : (T,) array
        The quantity (e.g. an MSD, length^2); those in the window must be > 0.
    t_min, t_max : float, optional
        The window, inclusive (time units); by default every sample.  At least three
        samples must fall in it.

    Returns
    -------
    exponent : float
        The fitted slope of ln(values) against ln(t) (dimensionless).
    prefactor : float
        ``exp(intercept)``: the fitted value at t = 1 (units of values / time^exponent).
    exponent_standard_error : float
        From the residuals (ordinary least squares): right for independent,
        equally noisy logarithms (a relative error of the values the same at every
        time), but it understates the error of an MSD, whose points are correlated.
        For an honest error fit each run of an ensemble and take the spread of the
        exponents (``ensemble_mean``).

    Raises
    ------
    ValueError
        Fewer than three samples in the window, or a time or value <= 0 (or NaN) in it.
    """
    t = np.asarray(times, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if t.ndim != 1 or v.shape != t.shape:
        raise ValueError(
            f"times and values must be one-dimensional and of one length, got shapes "
            f"{t.shape} and {v.shape}"
        )
    sel = _window(t, t_min, t_max, "fit_power_law")
    _positive_for_log(t[sel], "t", t[sel])
    _positive_for_log(v[sel], "values", t[sel])
    exponent, intercept, err = _line(np.log(t[sel]), np.log(v[sel]))
    return exponent, math.exp(intercept), err


# -- velocities ------------------------------------------------------------------------------


def temperature(velocities: ArrayLike, masses: ArrayLike = 1.0) -> float | NDArray[np.float64]:
    """Granular temperature ``T = 2 E_kin / (d N)`` of each snapshot ((N, d) -> scalar,
    (T, N, d) -> (T,))."""
    v = np.asarray(velocities, dtype=np.float64)
    m = np.asarray(masses, dtype=np.float64)
    e = 0.5 * np.sum(m[..., None] * v * v if m.ndim else m * v * v, axis=(-2, -1))
    return 2.0 * e / (v.shape[-1] * v.shape[-2])


_snapshot_temperature = temperature  # speed_statistics has an argument of that name


def _speeds(velocities):
    v = np.asarray(velocities, dtype=np.float64)
    if v.ndim < 2 or v.shape[-1] not in (2, 3):
        raise ValueError("velocities must have shape (..., N, d) with d = 2 or 3")
    return np.linalg.norm(v, axis=-1).ravel(), v.shape[-1]


def speed_histogram(
    velocities: ArrayLike,
    bins: int | ArrayLike = 50,
    range: tuple[float, float] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Normalised histogram of the speeds in one or more snapshots.

    Returns (bin centres, density, standard error of the density) -- the error from the
    Poisson count of each bin, ``sqrt(count) / (total * width)``.
    """
    speed, _ = _speeds(velocities)
    counts, edges = np.histogram(speed, bins=bins, range=range)
    width = np.diff(edges)
    total = counts.sum()
    return (
        0.5 * (edges[1:] + edges[:-1]),
        counts / (total * width),
        np.sqrt(counts) / (total * width),
    )


def speed_statistics(
    velocities: ArrayLike, temperature: float | None = None, masses: ArrayLike = 1.0
) -> dict[str, dict[str, float]]:
    """Mean speed, mean squared speed and standard deviation of the speed (Table 4.1),
    with the Maxwell-Boltzmann values at ``temperature`` (default: the snapshots' own
    temperature) and the relative errors ``ours / theory - 1``.  As in the thesis, the
    mean squared speed then agrees by construction."""
    from . import theory

    v = np.asarray(velocities, dtype=np.float64)
    speed, dim = _speeds(v)
    mass = float(np.mean(np.asarray(masses, dtype=np.float64)))
    T = float(np.mean(_snapshot_temperature(v, masses))) if temperature is None else temperature
    mb = theory.maxwell_boltzmann_moments(temperature=T, mass=mass, dim=dim)
    ours = {"mean": speed.mean(), "mean_sq": np.mean(speed**2), "std": speed.std()}
    return {
        k: {"ours": float(ours[k]), "theory": mb[k], "relative_error": float(ours[k] / mb[k] - 1)}
        for k in ours
    }


def fit_haff_tau0(
    times: ArrayLike, temperature_values: ArrayLike, t_max: float | None = None
) -> tuple[float, float]:
    """Fit Haff's tau0 to a cooling curve: Haff's law makes ``sqrt(T0 / T(t)) - 1 = t/tau0``
    a straight line through the origin; least squares with T0 the first sample.

    Returns (tau0, standard error from the residuals).
    """
    t = np.asarray(times, dtype=np.float64)
    T = np.asarray(temperature_values, dtype=np.float64)
    sel = t > t[0] if t_max is None else (t > t[0]) & (t <= t_max)
    y = np.sqrt(T[0] / T[sel]) - 1.0
    x = t[sel] - t[0]
    if len(x) < 2:
        raise ValueError("fit_haff_tau0 needs at least two samples after the first")
    k = float(x @ y / (x @ x))  # 1 / tau0
    resid = y - k * x
    err_k = math.sqrt(float(resid @ resid) / (len(x) - 1) / float(x @ x))
    return 1.0 / k, err_k / k**2


def ensemble_mean(
    values: ArrayLike, axis: int = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Mean over runs and its central-limit standard error ``std(ddof=1) / sqrt(M)``
    (thesis 2.120-2.122)."""
    # C order: NumPy's pairwise sums follow the memory layout, so a Fortran-order input
    # would give other roundings
    a = np.ascontiguousarray(values, dtype=np.float64)
    m = a.shape[axis]
    if m < 2:
        raise ValueError("ensemble_mean needs at least two runs for an error")
    return a.mean(axis=axis), a.std(axis=axis, ddof=1) / math.sqrt(m)


# -- profiles along an axis ------------------------------------------------------------------


class Profile:
    """Profiles of a gas along one axis, from ``profile``: each quantity in bins, with the
    standard error of its mean over blocks of samples.

    Attributes
    ----------
    axis : int
        The axis along which the bins lie.
    edges : ndarray (B + 1,)
        Bin edges [L]; ``centres`` (B,) their midpoints.
    density, density_error : ndarray (B,)
        Number density of centres in each bin (count over the bin's volume: its width
        times the cross-section of ``within``) [L^-d].
    temperature, temperature_error : ndarray (B, d)
        Temperature per velocity component, ``T_a = sum m (v_a - u_a)^2 / count`` with
        u the bin's mass-weighted mean velocity [eps]; NaN where a block has no particle
        in the bin.
    velocity, velocity_error : ndarray (B, d)
        The mass-weighted mean velocity u in each bin [sqrt(eps/m)].
    count : ndarray (B,)
        Mean number of centres in each bin per sample.
    blocks : int
        The number of blocks the errors come from.
    """

    def __init__(self, **fields: Any) -> None:
        self.__dict__.update(fields)

    axis: int
    edges: NDArray[np.float64]
    centres: NDArray[np.float64]
    density: NDArray[np.float64]
    density_error: NDArray[np.float64]
    temperature: NDArray[np.float64]
    temperature_error: NDArray[np.float64]
    velocity: NDArray[np.float64]
    velocity_error: NDArray[np.float64]
    count: NDArray[np.float64]
    blocks: int


def profile(
    trajectory: Any,
    axis: int = -1,
    *,
    bins: int | ArrayLike = 20,
    within: tuple[ArrayLike, ArrayLike] | None = None,
    blocks: int = 10,
) -> Profile:
    """Number density, temperature per component and mean velocity along ``axis``, in bins.

    Each of the ``blocks`` consecutive blocks of samples gives its own profile (the sums
    of its samples); the result is their mean, its error the standard error of that mean,
    ``std(block values, ddof=1) / sqrt(blocks)``.  Block averaging: samples closer in time
    than a correlation time are not independent, and whole blocks much longer than it
    are; so choose samples spread over many correlation times (a block of a few, its
    errors are then honest; with blocks shorter than the correlation time they are too
    small).  With one sample per block (blocks = samples) the samples are taken as
    independent.

    Parameters
    ----------
    trajectory : Trajectory
        A run with positions and velocities stored (``store=("positions", "velocities")``).
    axis : int
        The axis of the profile (default the last: z in 3D, y in 2D).
    bins : int or array_like
        Number of equal bins across the box along ``axis`` (or across ``within``), or
        the bin edges [L].
    within : (lower, upper), optional
        Count only the centres inside this box (length-d corners) [L]; the density is per
        its cross-section.  Default: the trajectory's box.  Keep away from side walls,
        where a dense gas layers, with a narrower box.
    blocks : int
        Blocks of consecutive samples for the error bars (>= 2, at most the samples).

    Returns
    -------
    Profile
    """
    x = trajectory._need("positions")
    v = trajectory._need("velocities")
    samples, n, d = x.shape
    if not -d <= axis < d:
        raise ValueError(f"axis must be one of the {d} axes, got {axis}")
    axis %= d
    if not (isinstance(blocks, (int, np.integer)) and 2 <= blocks <= samples):
        raise ValueError(
            f"blocks must be an integer from 2 to the number of samples ({samples}), got "
            f"{shown(blocks)}"
        )
    lower = np.asarray(trajectory.lower, dtype=np.float64)
    upper = np.asarray(trajectory.upper, dtype=np.float64)
    if within is not None:
        lower = np.broadcast_to(np.asarray(within[0], dtype=np.float64), (d,)).copy()
        upper = np.broadcast_to(np.asarray(within[1], dtype=np.float64), (d,)).copy()
        if not (
            np.all(np.isfinite(lower)) and np.all(np.isfinite(upper)) and np.all(upper > lower)
        ):
            raise ValueError(f"within needs finite lower < upper, got {lower} and {upper}")
    if np.ndim(bins) == 0:
        if not (isinstance(bins, (int, np.integer)) and bins >= 1):
            raise ValueError(f"bins must be a positive integer or the edges, got {shown(bins)}")
        edges = np.linspace(lower[axis], upper[axis], int(bins) + 1)
    else:
        edges = np.asarray(bins, dtype=np.float64)
        if edges.ndim != 1 or len(edges) < 2 or np.any(np.diff(edges) <= 0):
            raise ValueError("bins as edges must be increasing, at least two of them")
        if not np.all(np.isfinite(edges)):
            raise ValueError("bins as edges must be finite")
    # positions inside the box (a periodic box's images wrapped back)
    if trajectory.boundary == "periodic":
        length = trajectory.upper - trajectory.lower
        x = trajectory.lower + np.mod(x - trajectory.lower, length)
    m = np.asarray(trajectory.masses, dtype=np.float64)
    cross = float(np.prod(np.delete(upper - lower, axis)))
    nb = len(edges) - 1
    inside = np.all((x >= lower) & (x < upper), axis=-1) & (x[..., axis] >= edges[0])
    inside &= x[..., axis] < edges[-1]
    which = np.clip(np.searchsorted(edges, x[..., axis], side="right") - 1, 0, nb - 1)
    dens, temp, vel = [], [], []
    for part in np.array_split(np.arange(samples), blocks):
        sel = inside[part]
        b = which[part][sel]
        mm = np.broadcast_to(m, (len(part), n))[sel]
        vv = v[part][sel]
        count = np.bincount(b, minlength=nb).astype(np.float64)
        msum = np.bincount(b, weights=mm, minlength=nb)
        p = np.stack([np.bincount(b, weights=mm * vv[:, a], minlength=nb) for a in range(d)], 1)
        e2 = np.stack(
            [np.bincount(b, weights=mm * vv[:, a] ** 2, minlength=nb) for a in range(d)], 1
        )
        with np.errstate(invalid="ignore", divide="ignore"):
            u = p / msum[:, None]
            temp.append((e2 - p * u) / count[:, None])
        vel.append(u)
        dens.append(count / (len(part) * cross * np.diff(edges)))
    dens_a, temp_a, vel_a = np.array(dens), np.array(temp), np.array(vel)
    root = math.sqrt(blocks)
    return Profile(
        axis=axis,
        edges=edges,
        centres=0.5 * (edges[1:] + edges[:-1]),
        density=dens_a.mean(0),
        density_error=dens_a.std(0, ddof=1) / root,
        temperature=temp_a.mean(0),
        temperature_error=temp_a.std(0, ddof=1) / root,
        velocity=vel_a.mean(0),
        velocity_error=vel_a.std(0, ddof=1) / root,
        count=dens_a.mean(0) * cross * np.diff(edges),
        blocks=blocks,
    )
