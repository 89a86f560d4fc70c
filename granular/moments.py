"""Velocity-distribution moments of a sampled gas: the kurtosis <v^4>/<v^2>^2, the second
Sonine coefficient a2 = d <v^4> / ((d+2) <v^2>^2) - 1 (0 for a Maxwellian), and the
high-energy tail of the scaled speed c = v / v0, v0 = sqrt(2 T / m), against the Maxwellian.

Its own module (not analysis.py): these are statistics of the one-particle velocity
distribution, with their own error model, and the theory they are compared with is
granular.theory's sonine_a2_cooling, sonine_a2_driven and driven_temperature.

Velocities are taken relative to each sample's mean velocity (the frame where the total
momentum is 0: a periodic box keeps it), for particles of equal mass.

Error bars.  Samples of one run are correlated in time, so a run's samples are cut into
``blocks`` contiguous blocks, a2 is computed in each, and the error is the standard error of
the block values (block averaging; blocks must be longer than the correlation time, a few
collision times: ``MomentEstimate.blocks`` says how many were used).  Several independent
runs (a sequence of trajectories or arrays) give one value each, and the error is their
standard error.  Both are stated in the result's ``method``.

Finite N: a gas whose energy is exactly conserved (elastic, no driving) samples the energy
shell, whose one-particle marginal has a2 = -2 / (d (N - 1) + 2) with the momentum fixed
(a Maxwellian only as N -> infinity); ``microcanonical_a2`` gives it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class MomentEstimate:
    """Kurtosis and a2 of a sampled gas with standard errors.

    Attributes
    ----------
    kurtosis, kurtosis_error : float
        ``<|v|^4> / <|v|^2>^2`` (dimensionless; d (d+2) / d^2 for a Maxwellian) and its error.
    a2, a2_error : float
        The second Sonine coefficient and its error.
    blocks : int
        How many block (or run) values the error comes from.
    method : str
        "blocks" (one run cut into blocks in time) or "runs" (independent runs).
    dim : int
        The dimension.
    """

    kurtosis: float
    kurtosis_error: float
    a2: float
    a2_error: float
    blocks: int
    method: str
    dim: int


def _velocities(data: Any) -> NDArray[np.float64]:
    """(S, N, d) velocities of a Trajectory or an array (N, d) or (S, N, d)."""
    v = getattr(data, "velocities", data)
    if v is None:
        raise ValueError("the trajectory stored no velocities: run with store=('velocities',)")
    v = np.asarray(v, dtype=np.float64)
    if v.ndim == 2:
        v = v[None]
    if v.ndim != 3 or v.shape[2] not in (2, 3) or v.shape[1] < 2 or v.shape[0] < 1:
        raise ValueError(
            f"velocities must have shape (N, d) or (S, N, d), N >= 2, d 2 or 3; got {v.shape}"
        )
    if not np.all(np.isfinite(v)):
        raise ValueError("velocities contain NaN or infinity")
    return v


def _power_sums(v: NDArray[np.float64], each: bool = False) -> tuple[float, float, int]:
    """sum |v - u|^2, sum |v - u|^4 over samples and particles (u each sample's mean), count;
    ``each``: every sample scaled to a mean |v - u|^2 of 1 first."""
    w = v - v.mean(axis=1, keepdims=True)
    s2 = np.einsum("snd,snd->sn", w, w)
    if each:
        mean = s2.mean(axis=1, keepdims=True)
        if not np.all(mean > 0):
            raise ValueError("a sample is at rest: no velocity distribution to measure")
        s2 = s2 / mean
    return float(s2.sum()), float((s2 * s2).sum()), s2.size


def _shell_corrected(a2: float, n: int, dim: int) -> float:
    """a2 of samples each scaled to its own energy, with the energy shell's finite-N bias
    (microcanonical_a2) taken out: (1 + a2) / (1 + a2_shell) - 1."""
    return (1.0 + a2) / (1.0 + microcanonical_a2(n, dim)) - 1.0


def _from_sums(m2: float, m4: float, count: int, dim: int) -> tuple[float, float]:
    if m2 <= 0.0:
        raise ValueError("the gas is at rest: no velocity distribution to measure")
    k = (m4 / count) / (m2 / count) ** 2
    return k, dim * k / (dim + 2) - 1.0


def kurtosis(velocities: Any) -> float:
    """``<|v|^4> / <|v|^2>^2`` over all particles and samples (velocities relative to each
    sample's mean).

    Parameters
    ----------
    velocities : array_like (N, d) or (S, N, d), or a Trajectory
        Particle velocities [sqrt(eps/m)].
    """
    v = _velocities(velocities)
    return _from_sums(*_power_sums(v), v.shape[2])[0]


def sonine_a2(velocities: Any, *, each_sample: bool = False) -> float:
    """The second Sonine coefficient ``a2 = d <|v|^4> / ((d+2) <|v|^2>^2) - 1``.

    Parameters
    ----------
    velocities : array_like (N, d) or (S, N, d), or a Trajectory
        Particle velocities [sqrt(eps/m)].
    each_sample : bool
        Scale every sample to its own mean ``|v|^2`` before pooling them: for a gas whose
        temperature changes between samples (a cooling gas), where pooled samples would
        mix temperatures (a scale mixture, whose a2 is too large).  Each sample then lies
        on its own energy shell, whose finite-N bias ``microcanonical_a2`` is taken out.
    """
    v = _velocities(velocities)
    a2 = _from_sums(*_power_sums(v, each_sample), v.shape[2])[1]
    return _shell_corrected(a2, v.shape[1], v.shape[2]) if each_sample else a2


def velocity_moments(data: Any, *, blocks: int = 10, each_sample: bool = False) -> MomentEstimate:
    """Kurtosis and a2 with error bars (module docstring).

    Parameters
    ----------
    data : Trajectory, array (S, N, d), or a list or tuple of them
        One run (its samples in time order, cut into ``blocks`` blocks) or several
        independent runs (one value each).
    blocks : int
        Blocks of one run, >= 2, at most its number of samples.
    each_sample : bool
        Scale every sample to its own mean ``|v|^2`` first (a cooling gas; ``sonine_a2``).

    Returns
    -------
    MomentEstimate
    """
    if isinstance(data, list | tuple):
        runs = [_velocities(x) for x in data]
        if len(runs) < 2:
            raise ValueError("give at least 2 independent runs (or one run to cut into blocks)")
        parts, method = runs, "runs"
    else:
        v = _velocities(data)
        if not (isinstance(blocks, int) and 2 <= blocks <= v.shape[0]):
            raise ValueError(
                f"blocks must be an integer from 2 to the number of samples {v.shape[0]}, "
                f"got {blocks!r}"
            )
        parts, method = np.array_split(v, blocks, axis=0), "blocks"
    dims = {p.shape[2] for p in parts}
    if len(dims) != 1:
        raise ValueError(f"the runs have different dimensions {sorted(dims)}")
    dim = dims.pop()
    sums = [_power_sums(p, each_sample) for p in parts]
    values = np.array([_from_sums(*s, dim) for s in sums])
    total = np.array(
        [_from_sums(sum(s[0] for s in sums), sum(s[1] for s in sums), sum(s[2] for s in sums), dim)]
    )
    if each_sample:  # the shell's bias out of a2, and the kurtosis that goes with it
        n = parts[0].shape[1]
        for x in (values, total):
            x[:, 1] = [_shell_corrected(a, n, dim) for a in x[:, 1]]
            x[:, 0] = (dim + 2) / dim * (1.0 + x[:, 1])
    err = values.std(axis=0, ddof=1) / math.sqrt(len(parts))
    return MomentEstimate(
        kurtosis=float(total[0, 0]),
        kurtosis_error=float(err[0]),
        a2=float(total[0, 1]),
        a2_error=float(err[1]),
        blocks=len(parts),
        method=method,
        dim=dim,
    )


def microcanonical_a2(n: int, dim: int) -> float:
    """a2 of one particle's velocity in a gas of ``n`` equal masses with fixed total energy
    and zero momentum (uniform on the sphere of d (n - 1) dimensions): -2 / (d (n-1) + 2).

    Parameters
    ----------
    n : int
        Number of particles N, >= 2.
    dim : int
        2 or 3.
    """
    if dim not in (2, 3) or n < 2:
        raise ValueError(f"need n >= 2 and dim 2 or 3, got n={n}, dim={dim}")
    f = dim * (n - 1)
    return -2.0 / (f + 2.0)


@dataclass(frozen=True)
class TailFit:
    """The distribution of the scaled speed ``c = |v| / v0`` and a fit of its tail.

    Attributes
    ----------
    c : ndarray
        Bin centres (dimensionless).
    density : ndarray
        The measured probability density of c.
    maxwell : ndarray
        The Maxwellian density of c, ``2 c^(d-1) exp(-c^2) / Gamma(d/2)``.
    counts : ndarray
        Speeds in each bin.
    exponent : float
        b of the fitted tail ``density ~ c^(d-1) exp(-A c^b)``.
    rate, rate_error : float
        A and its standard error (weighted least squares over the bins with c >= c_min,
        Poisson counts: samples correlated in time make the true error larger).
    c_min : float
        Where the fit starts.
    """

    c: NDArray[np.float64]
    density: NDArray[np.float64]
    maxwell: NDArray[np.float64]
    counts: NDArray[np.float64]
    exponent: float
    rate: float
    rate_error: float
    c_min: float


def speed_tail(
    data: Any, *, exponent: float = 1.0, c_min: float = 2.0, c_max: float = 5.0, bins: int = 60
) -> TailFit:
    """The scaled speed's distribution against the Maxwellian, and ``A`` of the tail
    ``c^(d-1) exp(-A c^b)`` fitted over ``c_min <= c <= c_max``.  van Noije & Ernst (1998)
    predict b = 1 for the cooling state and b = 3/2 for white-noise driving (a Maxwellian
    is b = 2, A = 1).

    Parameters
    ----------
    data : Trajectory, array (N, d) or (S, N, d)
        Velocities [sqrt(eps/m)]; ``v0^2 = 2 <|v|^2> / d`` over all of them.
    exponent : float
        b > 0.
    c_min, c_max : float
        The fitted range of c.
    bins : int
        Bins of c from 0 to c_max.
    """
    v = _velocities(data)
    dim = v.shape[2]
    w = v - v.mean(axis=1, keepdims=True)
    speed2 = np.einsum("snd,snd->sn", w, w).ravel()
    v0 = math.sqrt(2.0 * speed2.mean() / dim)
    c = np.sqrt(speed2) / v0
    if not (exponent > 0 and 0 <= c_min < c_max and bins >= 4):
        raise ValueError(
            f"need exponent > 0, 0 <= c_min < c_max and bins >= 4; got exponent={exponent}, "
            f"c_min={c_min}, c_max={c_max}, bins={bins}"
        )
    edges = np.linspace(0.0, c_max, bins + 1)
    counts, _ = np.histogram(c, bins=edges)
    width = edges[1] - edges[0]
    mid = 0.5 * (edges[1:] + edges[:-1])
    density = counts / (c.size * width)
    maxwell = 2.0 * mid ** (dim - 1) * np.exp(-(mid**2)) / math.gamma(dim / 2)
    use = (mid >= c_min) & (counts >= 5)
    if use.sum() < 3:
        raise ValueError(
            f"too few speeds beyond c_min = {c_min} to fit the tail ({int(use.sum())} bins "
            "with 5 or more): sample more, or lower c_min"
        )
    y = np.log(density[use] / mid[use] ** (dim - 1))
    x = mid[use] ** exponent
    weight = counts[use].astype(float)  # var(log count) = 1 / count
    design = np.stack([np.ones_like(x), -x], axis=1)
    cov = np.linalg.inv(design.T @ (design * weight[:, None]))
    coef = cov @ design.T @ (weight * y)
    return TailFit(
        c=mid,
        density=density,
        maxwell=maxwell,
        counts=counts.astype(float),
        exponent=float(exponent),
        rate=float(coef[1]),
        rate_error=float(math.sqrt(cov[1, 1])),
        c_min=float(c_min),
    )
