"""The slow, obvious ergodicity-breaking theory: the position covariance evaluated per pair
of windows (the propagator integral by Gauss-Legendre for every pair, O(M^2 x nodes x
panels)), as ``theory.udsbm_ergodicity_breaking`` did before it built the covariance once
on the grid of window ends.  The reference the fast path is tested against."""

import numpy as np

from granular.theory import _numerics


def position_covariance(t1, t2, sol, D0, gamma0, tau0, exponent):
    """<x(t1) x(t2)> per dimension: <x^2>(m) + <xv>(m) K(m, |t2 - t1|), m = min(t1, t2)."""
    m = np.minimum(t1, t2)
    times, where = np.unique(m, return_inverse=True)
    y = sol(gamma0 * times)[:, where.reshape(-1)].reshape((3, *np.shape(m)))
    k = _numerics._powerlaw_propagator_integral(m, np.abs(t2 - t1), gamma0, tau0, exponent)
    return y[0] * D0 / gamma0 + y[1] * D0 * k


def ergodicity_breaking(lag, starts, D0, gamma0, tau0, exponent, dim, v0_sq=None):
    """EB = 2 sum_jk C_jk^2 / (d (sum_j C_jj)^2), C_jk from four covariances per pair."""
    s = np.asarray(starts, dtype=np.float64).reshape(-1)
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _numerics._powerlaw_ode(
        gamma0, tau0, exponent, v0 / (D0 * gamma0), gamma0 * (s.max() + lag)
    )
    a, b = s[:, None], s[None, :]

    def cov(t1, t2):
        return position_covariance(t1, t2, sol, D0, gamma0, tau0, exponent)

    c = cov(a + lag, b + lag) - cov(a + lag, b) - cov(a, b + lag) + cov(a, b)
    return float(2.0 * np.sum(c * c) / (dim * np.trace(c) ** 2))
