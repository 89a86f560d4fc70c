"""Numerical machinery shared by the theory modules: cancellation-free elementary
functions, the second-moment ODEs of power-law UDSBM, its velocity propagator integral and
the position covariance on a time grid."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

# what the formulas return: a float for scalar arguments, else an array of their shape
FloatOrArray = float | NDArray[np.float64]


def _check_dim(dim):
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim}")


def _x_plus_expm1(x):
    """``x + expm1(-x)`` without cancellation for small x (a series there)."""
    x = np.asarray(x, dtype=np.float64)
    small = np.abs(x) < 1e-3
    xs = np.where(small, x, 0.0)
    series = xs**2 / 2 - xs**3 / 6 + xs**4 / 24 - xs**5 / 120
    return np.where(small, series, x + np.expm1(-np.where(small, 1.0, x)))


def _one_minus_exp_over(x):
    """``(1 - exp(-x)) / x``, equal to 1 at x = 0."""
    x = np.asarray(x, dtype=np.float64)
    safe = np.where(x == 0, 1.0, x)
    return np.where(x == 0, 1.0, -np.expm1(-safe) / safe)


def _check_powerlaw(gamma0, D0, tau0, exponent):
    for name, value in (("gamma0", gamma0), ("D0", D0)):
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be positive and finite, got {value}")
    if not tau0 > 0:
        raise ValueError(f"tau0 must be positive (inf: constant coefficients), got {tau0}")
    if not (exponent > 0 and math.isfinite(exponent)):
        raise ValueError(f"exponent must be positive and finite, got {exponent}")


def _powerlaw_ode(gamma0, tau0, exponent, v0_sq_reduced, t_max_reduced):
    """Dense solution of the second-moment ODEs in units of 1/gamma0 (time), D0/gamma0
    (x^2), D0 (x v), D0 gamma0 (v^2): with g = w^-a, w = 1 + t/tau0,
    d<x^2> = 2 <xv>, d<xv> = <v^2> - g <xv>, d<v^2> = -2 g <v^2> + 2 g^3 (the noise
    2 D gamma^2).  DOP853 at rtol 1e-12.  Constant coefficients (tau0 = inf): the closed
    forms of the Langevin model (2.68 with the start's transient), no integration."""
    from scipy.integrate import solve_ivp

    if math.isinf(tau0):
        excess = v0_sq_reduced - 1.0

        def langevin(s):
            s = np.asarray(s, dtype=np.float64)
            omc, e = -np.expm1(-s), np.exp(-s)
            xx = 2.0 * _x_plus_expm1(s) + excess * omc**2
            return np.array([xx, omc + excess * e * omc, 1.0 + excess * e * e])

        return langevin

    c = 1.0 / (gamma0 * tau0)  # w = 1 + c s, s = gamma0 t

    def rhs(s, y):
        g = (1.0 + c * s) ** -exponent
        return [2.0 * y[1], y[2] - g * y[1], -2.0 * g * y[2] + 2.0 * g**3]

    sol = solve_ivp(
        rhs,
        (0.0, max(t_max_reduced, 1e-12)),
        [0.0, 0.0, v0_sq_reduced],
        method="DOP853",
        rtol=1e-12,
        atol=1e-15,
        dense_output=True,
    )
    if not sol.success:  # pragma: no cover - DOP853 on this smooth linear system
        raise RuntimeError(f"moment ODE failed: {sol.message}")
    return sol.sol


# Gauss-Legendre nodes for the propagator integral K: panels [0, 1/2], [1/2, 1], [1, 2], ...
_GL_X, _GL_W = np.polynomial.legendre.leggauss(20)


def _powerlaw_propagator_integral(start, gap, gamma0, tau0, exponent):
    """K(s, h) = int_s^{s+h} exp(-int_s^u gamma) du, the factor of <x(s) v(s)> in
    <x(s) x(s+h)> = <x^2>(s) + <xv>(s) K (the velocity correlation decays with the
    propagator after s).  Closed forms for tau0 = inf, (1 - exp(-gamma0 h))/gamma0, and
    a = 1, tau0 w (1 - (w/W)^(A-1))/(A - 1) (A = gamma0 tau0, w = 1 + s/tau0,
    W = 1 + (s+h)/tau0); for a < 1, in phi = int_s^u gamma, K = (w^a/gamma0) int_0^Phi
    exp(-phi) (1 + (1-a) phi / (A w^(1-a)))^(a/(1-a)) dphi by 20-point Gauss-Legendre on
    doubling panels; for a > 1 the same in z = ln(W/w) (relative error < 1e-9 against
    scipy quad, a = 1.2 to 3, tests/test_theory_viscoelastic.py)."""
    s, h = np.broadcast_arrays(
        np.asarray(start, dtype=np.float64), np.asarray(gap, dtype=np.float64)
    )
    if math.isinf(tau0):
        return -np.expm1(-gamma0 * h) / gamma0
    A = gamma0 * tau0
    w = 1.0 + s / tau0
    lr = np.log1p(h / (tau0 + s))  # ln(W / w)
    if exponent == 1.0:
        if A == 1.0:
            return tau0 * w * lr
        return tau0 * w * -np.expm1(-(A - 1) * lr) / (A - 1)
    b = 1.0 - exponent
    wb = w**b
    if exponent > 1.0:
        # gamma's integral converges: in phi the integrand has a singular end, so integrate
        # in z = ln(W/w) instead, du = (tau0 + s) e^z dz, on panels doubling from the
        # relaxation scale 1 / (A w^b) of the start
        z0 = 0.5 / (A * wb)
        total = np.zeros(np.shape(s))
        k = 0
        while True:
            a_ = np.minimum(z0 * (2.0**k - 1.0), lr)
            b_ = np.minimum(z0 * (2.0 ** (k + 1) - 1.0), lr)
            if not np.any(b_ > a_):
                break
            half = 0.5 * (b_ - a_)
            z = (a_ + half)[..., None] + half[..., None] * _GL_X
            f = np.exp(z - A * wb[..., None] * np.expm1(b * z) / b)
            total += half * (f @ _GL_W)
            k += 1
        return (tau0 + s) * total
    phi_end = A * wb * np.expm1(b * lr) / b
    scale = b / (A * wb)
    total = np.zeros(np.shape(s))
    lo = 0.0
    hi = 0.5
    top = float(np.max(phi_end, initial=0.0))
    while lo < top:
        a_ = np.minimum(lo, phi_end)
        b_ = np.minimum(hi, phi_end)
        half = 0.5 * (b_ - a_)
        if np.any(half > 0):
            phi = (a_ + half)[..., None] + half[..., None] * _GL_X
            base = np.maximum(1.0 + scale[..., None] * phi, 0.0)
            f = np.exp(-phi) * base ** (exponent / b)
            total += half * (f @ _GL_W)
        lo, hi = hi, 2 * hi
    return w**exponent / gamma0 * total


def _powerlaw_gamma_integral(t0, t1, gamma0, tau0, exponent):
    """int_{t0}^{t1} gamma, gamma = gamma0 (1 + t/tau0)^-a, accurate for short spans
    (log1p / expm1, no difference of large numbers)."""
    if math.isinf(tau0):
        return gamma0 * (t1 - t0)
    lr = np.log1p((t1 - t0) / (tau0 + t0))  # ln(W / w)
    A = gamma0 * tau0
    if exponent == 1.0:
        return A * lr
    b = 1.0 - exponent
    return A * (1.0 + t0 / tau0) ** b * np.expm1(b * lr) / b


def _covariance_on_grid(times, sol, D0, gamma0, tau0, exponent, block=512):
    """<x(T_i) x(T_j)> per dimension for all pairs of the sorted distinct ``times``, (N, N).

    For T_i <= T_j it is <x^2>(T_i) + <xv>(T_i) K(T_i, T_j - T_i), and the propagator
    integral splits over the grid's segments: K(T_i, T_j - T_i) = sum_{m=i}^{j-1}
    exp(-int_{T_i}^{T_m} gamma) kappa_m with kappa_m = K(T_m, T_{m+1} - T_m) (one call of
    ``_powerlaw_propagator_integral`` per segment, not per pair).  The exponentials are
    <= 1 (no overflow) and the sum adds positive terms (relative rounding ~N eps).  Cost
    O(N^2) in array operations, rows in blocks to bound the memory."""
    n = times.size
    y = sol(gamma0 * times)
    xx, xv = y[0] * D0 / gamma0, y[1] * D0
    if n == 1:
        return xx.reshape(1, 1).copy()
    kappa = _powerlaw_propagator_integral(times[:-1], np.diff(times), gamma0, tau0, exponent)
    # G_m = int_{T_0}^{T_m} gamma, summed from accurate per-segment integrals
    seg = _powerlaw_gamma_integral(times[:-1], times[1:], gamma0, tau0, exponent)
    g = np.concatenate([[0.0], np.cumsum(seg)])
    cov = np.empty((n, n))
    cols = np.arange(n - 1)
    for lo in range(0, n, block):
        rows = np.arange(lo, min(lo + block, n))
        # term[i, m] = exp(G_i - G_m) kappa_m for m >= i, 0 before
        term = np.exp(np.minimum(g[rows, None] - g[None, :-1], 0.0)) * kappa
        term[cols[None, :] < rows[:, None]] = 0.0
        k = np.zeros((rows.size, n))
        np.cumsum(term, axis=1, out=k[:, 1:])  # k[i, j] = sum_{m < j} term[i, m]
        cov[rows] = xx[rows, None] + xv[rows, None] * k
    # the upper triangle (T_i <= T_j) is right; mirror it block by block (no N^2 temporaries)
    for lo in range(0, n, block):
        hi = min(lo + block, n)
        cov[lo:hi, :lo] = cov[:lo, lo:hi].T
        diag = cov[lo:hi, lo:hi]
        cov[lo:hi, lo:hi] = np.triu(diag) + np.triu(diag, 1).T
    return cov
