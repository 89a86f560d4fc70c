"""Ergodicity breaking of (power-law) UDSBM and the Langevin model: the variance of the
time-averaged MSD from the exact position covariance."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .._params import keyword_only
from ._numerics import _check_powerlaw, _covariance_on_grid, _powerlaw_ode


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
    Cost O(len(starts)^2) array operations (``_covariance_on_grid``): 0.3-0.6 s for 2000
    windows; memory 3-6 M^2 doubles (the covariance on up to 2 M times and C: 100-190 MB
    for 2000 windows).

    Parameters
    ----------
    lag : the lag
    starts : (M,) window starts
    D0, gamma0, tau0, exponent, v0_sq : the model (see ``powerlaw_udsbm_moments``)
    dim : dimensions summed in ``|dx|^2``

    Returns
    -------
    EB
    """
    _check_powerlaw(gamma0, D0, tau0, exponent)
    s = np.asarray(start, dtype=np.float64).reshape(-1)
    if not lag > 0 or s.size == 0 or np.any(s < 0):
        raise ValueError("need lag > 0 and at least one window start >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _powerlaw_ode(gamma0, tau0, exponent, v0 / (D0 * gamma0), gamma0 * (s.max() + lag))
    # the covariance once on the distinct window ends (at most 2 M, far fewer when the
    # windows overlap on the sample grid), then the increments' C_jk by indexing
    times = np.unique(np.concatenate([s, s + lag]))
    i0, i1 = np.searchsorted(times, s), np.searchsorted(times, s + lag)
    cov = _covariance_on_grid(times, sol, D0, gamma0, tau0, exponent)
    c = cov[np.ix_(i1, i1)]
    c -= cov[np.ix_(i1, i0)]
    c -= cov[np.ix_(i0, i1)]
    c += cov[np.ix_(i0, i0)]
    return float(2.0 * np.vdot(c, c) / (dim * np.trace(c) ** 2))
