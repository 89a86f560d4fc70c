"""Ergodicity breaking of (power-law) UDSBM and the Langevin model: the variance of the
time-averaged MSD from the exact position covariance."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._params import keyword_only
from ._numerics import (
    _check_powerlaw,
    _covariance_on_grid,
    _powerlaw_gamma_integral,
    _powerlaw_ode,
    _powerlaw_propagator_integral,
)


@keyword_only("lag", renamed={"starts": "start"})
def udsbm_ergodicity_breaking(
    lag: float,
    *,
    start: ArrayLike,
    D0: float,
    gamma0: float,
    tau0: float = math.inf,
    exponent: float = 1.0,
    dim: int = 3,
    v0_sq: float | None = None,
) -> float:
    """Ergodicity-breaking parameter EB = Var(TAMSD) / <TAMSD>^2 of the time-averaged MSD
    over windows [s_j, s_j + lag] (the engine's, or a fine grid for the continuous-time
    average of the thesis' 2.115), for UDSBM with power-law coefficients (a = 1 the
    thesis' UDSBM, tau0 = inf the Langevin model).

    The process is Gaussian with zero mean, so with C_jk the covariance per dimension of
    the increments of windows j and k (from ``<x(t1) x(t2)>``, see
    ``powerlaw_udsbm_increment_msd``) and d independent dimensions, Isserlis' theorem gives
    ``Cov(|dx_j|^2, |dx_k|^2) = 2 d C_jk^2`` and

        EB = 2 sum_jk C_jk^2 / (d (sum_j C_jj)^2).

    EB -> 0 for an ergodic process as t_stop / lag grows (Brownian motion: 4 lag / (3 d
    t_stop), He, Burov, Metzler & Barkai, PRL 101, 058101 (2008)); UDSBM's stays finite
    (Bodrova et al., PCCP 17, 21791 (2015); Safdari, Cherstvy, Chechkin, Bodrova & Metzler,
    "Ageing underdamped scaled Brownian motion", arXiv:1609.07246).

    The sum splits by whether two windows overlap.  Overlapping pairs (window k starts
    before window j ends, at most the windows within one lag of each other) take the
    covariance on their window ends (``_covariance_on_grid``), block by block.  For
    disjoint windows, s_j + lag <= s_k, the four covariances reduce to one product,
    ``C_jk = alpha_j P(s_j + lag, s_k) K(s_k, lag)``, with P(t, u) = exp(-int_t^u gamma)
    the velocity propagator, K the integral of P over a window (the TAMSD's cross term)
    and ``alpha_j = <xv>(s_j + lag) - <xv>(s_j) P(s_j, s_j + lag)``; so their squares sum
    over k by one backward recursion (every factor <= 1, no overflow).  Cost O(M W)
    array operations and memory O(W^2) for M windows of which W overlap one window.

    Parameters
    ----------
    lag : float
        The lag [L sqrt(m/eps)] (> 0).
    start : array_like, (M,)
        Window starts [L sqrt(m/eps)] (>= 0; any order).
    D0, gamma0, tau0, exponent, v0_sq : float
        The model (see ``powerlaw_udsbm_moments``): D0 [L^2 / time], gamma0 [1 / time],
        tau0 [time], exponent (dimensionless), v0_sq [eps/m].
    dim : int
        Dimensions summed in ``|dx|^2``.

    Returns
    -------
    float
        EB (dimensionless).
    """
    _check_powerlaw(gamma0, D0, tau0, exponent)
    s = np.sort(np.asarray(start, dtype=np.float64).reshape(-1))
    if not lag > 0 or s.size == 0 or np.any(s < 0):
        raise ValueError("need lag > 0 and at least one window start >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _powerlaw_ode(gamma0, tau0, exponent, v0 / (D0 * gamma0), gamma0 * (s[-1] + lag))
    model = (D0, gamma0, tau0, exponent)
    e = s + lag
    m = s.size
    first_disjoint = np.searchsorted(s, e, side="left")  # the first k with s_k >= e_j
    overlapping = int(np.max(first_disjoint - np.arange(m)))
    squares, trace = _overlapping_pairs(s, e, first_disjoint, sol, model, max(256, overlapping))
    squares += _disjoint_pairs(s, e, first_disjoint, sol, model)
    return float(2.0 * squares / (dim * trace**2))


def _overlapping_pairs(s, e, first_disjoint, sol, model, block):
    """sum of C_jj^2 + 2 C_jk^2 over the overlapping pairs j < k < first_disjoint[j], and the
    trace sum C_jj: rows of ``block`` windows against the windows they overlap, from the
    covariance on their ends."""
    m = s.size
    squares = trace = 0.0
    for j0 in range(0, m, block):
        j1 = min(j0 + block, m)
        k1 = int(first_disjoint[j1 - 1])  # non-decreasing in j, and > j1 - 1
        times = np.unique(np.concatenate([s[j0:k1], e[j0:k1]]))
        i0, i1 = np.searchsorted(times, s[j0:k1]), np.searchsorted(times, e[j0:k1])
        cov = _covariance_on_grid(times, sol, *model)
        rows = slice(0, j1 - j0)
        c = cov[np.ix_(i1[rows], i1)]
        c -= cov[np.ix_(i1[rows], i0)]
        c -= cov[np.ix_(i0[rows], i1)]
        c += cov[np.ix_(i0[rows], i0)]
        j = np.arange(j0, j1)[:, None]
        k = np.arange(j0, k1)[None, :]
        weight = np.where(k == j, 1.0, 2.0 * ((k > j) & (k < first_disjoint[j0:j1, None])))
        squares += float(np.sum(weight * c * c))
        trace += float(np.trace(c[:, : j1 - j0]))
    return squares, trace


def _disjoint_pairs(s, e, first_disjoint, sol, model):
    """2 sum over the disjoint pairs j < k (s_k >= e_j) of C_jk^2, C_jk = alpha_j P(e_j, s_k)
    kappa_k, by the recursion T_k = kappa_k^2 + P(s_k, s_k+1)^2 T_k+1 = sum over k' >= k of
    (P(s_k, s_k') kappa_k')^2."""
    D0, gamma0, tau0, exponent = model
    far = np.nonzero(first_disjoint < s.size)[0]
    if far.size == 0:
        return 0.0
    xv_s = sol(gamma0 * s)[1] * D0
    xv_e = sol(gamma0 * e)[1] * D0
    alpha = xv_e - xv_s * np.exp(-_powerlaw_gamma_integral(s, e, gamma0, tau0, exponent))
    kappa = _powerlaw_propagator_integral(s, e - s, gamma0, tau0, exponent)
    decay = np.exp(-2.0 * _powerlaw_gamma_integral(s[:-1], s[1:], gamma0, tau0, exponent))
    tail = np.empty(s.size)
    tail[-1] = kappa[-1] ** 2
    for k in range(s.size - 2, -1, -1):
        tail[k] = kappa[k] ** 2 + decay[k] * tail[k + 1]
    k = first_disjoint[far]
    gap = np.exp(-_powerlaw_gamma_integral(e[far], s[k], gamma0, tau0, exponent))
    return 2.0 * float(np.sum((alpha[far] * gap) ** 2 * tail[k]))
