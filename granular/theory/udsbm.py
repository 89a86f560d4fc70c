"""Underdamped scaled Brownian motion (UDSBM): the thesis' model of a granular gas
(friction and diffusivity decaying like Haff's law), and its power-law generalisation;
ensemble MSDs and the MSD of increments that a time average collects."""

from __future__ import annotations

import numpy as np

from .._params import keyword_only
from ._numerics import (
    FloatOrArray,
    _check_powerlaw,
    _one_minus_exp_over,
    _powerlaw_ode,
    _powerlaw_propagator_integral,
    _x_plus_expm1,
)


@keyword_only("D0", "gamma0", "tau0")
def udsbm_v0_sq(*, D0: float, gamma0: float, tau0: float) -> float:
    """The "correct" initial mean squared velocity per component of UDSBM (App. C):
    ``(T0/m) gamma0 tau0 / (gamma0 tau0 - 1)``, the value for which the VACF is (2.111)
    from t = 0 on and the MSD is (2.113).  Needs gamma0 tau0 > 1."""
    a = gamma0 * tau0
    if not a > 1:
        raise ValueError("UDSBM needs gamma0 * tau0 > 1")
    return D0 * gamma0 * a / (a - 1)


@keyword_only("t", "D0", "gamma0", "tau0", "dim", "v0_sq")
def msd_udsbm(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    tau0: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """MSD of underdamped scaled Brownian motion, total over ``dim`` dimensions.

    With ``v0_sq = None`` (default) the particles start with App. C's initial speed
    (``udsbm_v0_sq``) and the result is (2.113):
    ``2 D0 a^2 / (a - 1)^2 [tau0 ln(1 + t/tau0) + tau0 ((1 + t/tau0)^(1-a) - 1) / (a - 1)]``
    per dimension, a = gamma0 tau0 > 1.  Another initial mean squared velocity per
    component adds ``(v0_sq - udsbm_v0_sq) (int_0^t (1 + s/tau0)^-a ds)^2`` (the
    transient of the UDSBM solution, see ``granular.langevin``).
    """
    a = gamma0 * tau0
    if not a > 1:
        raise ValueError("UDSBM needs gamma0 * tau0 > 1")
    t = np.asarray(t, dtype=np.float64)
    u = np.log1p(t / tau0)
    out = 2.0 * D0 * a**2 * tau0 / (a - 1) ** 3 * _x_plus_expm1((a - 1) * u)
    if v0_sq is not None:
        # int_0^t (1 + s/tau0)^-a ds = tau0 (1 - exp(-(a - 1) u)) / (a - 1)
        integral = tau0 * u * _one_minus_exp_over((a - 1) * u)
        out = out + (v0_sq - udsbm_v0_sq(D0=D0, gamma0=gamma0, tau0=tau0)) * integral**2
    return dim * out


@keyword_only("lag", "start", "D0", "gamma0", "tau0", "dim", "v0_sq")
def udsbm_increment_msd(
    lag: FloatOrArray,
    *,
    start: FloatOrArray,
    D0: float,
    gamma0: float,
    tau0: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Mean squared displacement of UDSBM over [start, start + lag], total over ``dim``
    dimensions -- the quantity a time average over windows starting at ``start`` collects
    (thesis 2.114-2.119).  At start = 0 it is ``msd_udsbm``.

    Per dimension, with w = 1 + start/tau0, W = 1 + (start + lag)/tau0, a = gamma0 tau0 and
    vc = ``udsbm_v0_sq``: the mean squared velocity is ``vc / w^2 + (v0_sq - vc) / w^(2a)``
    and ``<v(s) v(s')> = <v^2>(s) (w / w')^a`` (VACF 2.111 plus the start's transient);
    integrated twice, with u = ln(W/w) and b = a - 1, ``2 tau0^2 vc (b u + exp(-b u) - 1)
    / b^2 + (v0_sq - vc) (tau0 w^-b (1 - exp(-b u)) / b)^2``, evaluated without the
    cancellation of W^x - w^x at lags short against tau0 + start (u = log1p(lag / (tau0 +
    start))).  ``v0_sq = None``: App. C's start (vc), whose increments scale:
    ``msd_udsbm(lag / w)``.
    """
    b = gamma0 * tau0 - 1.0
    vc = udsbm_v0_sq(D0=D0, gamma0=gamma0, tau0=tau0)
    v0_sq = vc if v0_sq is None else v0_sq
    start = np.asarray(start, dtype=np.float64)
    w = 1.0 + start / tau0
    u = np.log1p(np.asarray(lag, dtype=np.float64) / (tau0 + start))
    stationary = 2.0 * tau0**2 * vc * _x_plus_expm1(b * u) / b**2
    transient = (v0_sq - vc) * (tau0 * w ** (-b) * u * _one_minus_exp_over(b * u)) ** 2
    return dim * (stationary + transient)


@keyword_only("t")
def powerlaw_udsbm_moments(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    v0_sq: float | None = None,
) -> tuple[FloatOrArray, FloatOrArray, FloatOrArray]:
    """<x^2>, <x v>, <v^2> per dimension of UDSBM with power-law coefficients,
    dv = -gamma(t) v dt + sqrt(2 D(t)) gamma(t) dW, gamma = gamma0 w^-a, D = D0 w^-a,
    w = 1 + t/tau0, from x = 0 and <v^2> = v0_sq (default D0 gamma0, thermal).

    The exact moment equations d<x^2>/dt = 2<xv>, d<xv>/dt = <v^2> - gamma <xv>,
    d<v^2>/dt = -2 gamma <v^2> + 2 D gamma^2 (Ito) integrated numerically (relative
    error ~1e-11): for a != 1 they have no elementary closed form (the velocity
    propagator exp(-gamma0 tau0 (w^(1-a) - 1)/(1 - a)) leads to incomplete gamma
    functions).  For a = 1 this is the thesis' (2.113) / ``msd_udsbm`` (tested), for
    tau0 = inf the Langevin (2.68).

    References
    ----------
    Bodrova, Chechkin, Cherstvy, Safdari, Sokolov & Metzler, "Underdamped scaled Brownian
    motion: (non-)existence of the overdamped limit in anomalous diffusion", Sci. Rep. 6,
    30520 (2016) (UDSBM with power-law coefficients); thesis App. C and (2.111)-(2.113) for a = 1.
    """
    _check_powerlaw(gamma0, D0, tau0, exponent)
    t = np.asarray(t, dtype=np.float64)
    if np.any(t < 0) or not np.all(np.isfinite(t)):
        raise ValueError("t must be finite and >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    s = gamma0 * t
    sol = _powerlaw_ode(gamma0, tau0, exponent, v0 / (D0 * gamma0), float(np.max(s, initial=0.0)))
    y = sol(s.reshape(-1)).reshape((3, *t.shape))
    xx, xv, vv = y[0] * D0 / gamma0, y[1] * D0, y[2] * D0 * gamma0
    if t.ndim == 0:
        return float(xx), float(xv), float(vv)
    return xx, xv, vv


@keyword_only("t")
def msd_powerlaw_udsbm(
    t: FloatOrArray,
    *,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Ensemble MSD of UDSBM with power-law coefficients, total over ``dim``:
    ``dim <x^2>`` of ``powerlaw_udsbm_moments`` (see there).  Late times, for a < 1:
    ``msd_powerlaw_udsbm_asymptote``."""
    xx, _, _ = powerlaw_udsbm_moments(
        t, D0=D0, gamma0=gamma0, tau0=tau0, exponent=exponent, v0_sq=v0_sq
    )
    return dim * np.asarray(xx) if np.ndim(xx) else dim * xx


@keyword_only("t")
def msd_powerlaw_udsbm_asymptote(
    t: FloatOrArray, *, D0: float, tau0: float, exponent: float, dim: int = 3
) -> FloatOrArray:
    """Overdamped limit of the power-law UDSBM MSD for a < 1, total over ``dim``:
    ``2 d int_0^t D = 2 d D0 tau0 ((1 + t/tau0)^(1-a) - 1) / (1 - a)``, ~ t^(1-a) (t^(1/6)
    for the viscoelastic a = 5/6).

    Why it holds for a < 1 only: gamma(t) t ~ t^(1-a) grows, so the velocity relaxes ever
    faster against the age and the overdamped limit exists; the underdamped MSD exceeds
    this by a term that grows more slowly (relative O(1/(gamma(t) t))).  For a = 1 the
    ratio gamma t stays gamma0 tau0 and the MSD is larger by (gamma0 tau0 / (gamma0 tau0 -
    1))^2 (thesis 2.113; Bodrova et al., Sci. Rep. 6, 30520 (2016): the overdamped limit does
    not exist); for a > 1 the motion ends ballistic.

    Raises
    ------
    ValueError
        For exponent outside (0, 1).
    """
    if not 0 < exponent < 1:
        raise ValueError(f"the overdamped asymptote needs 0 < exponent < 1, got {exponent}")
    u = np.log1p(np.asarray(t, dtype=np.float64) / tau0)
    b = 1.0 - exponent
    return 2.0 * dim * D0 * tau0 * np.expm1(b * u) / b


@keyword_only("lag")
def powerlaw_udsbm_increment_msd(
    lag: FloatOrArray,
    *,
    start: FloatOrArray,
    D0: float,
    gamma0: float,
    tau0: float,
    exponent: float,
    dim: int = 3,
    v0_sq: float | None = None,
) -> FloatOrArray:
    """Mean squared displacement over [start, start + lag] of UDSBM with power-law
    coefficients, total over ``dim``: ``<x^2>(s+lag) - <x^2>(s) - 2 <xv>(s) K(s, lag)``
    per dimension, with K the integral of the velocity propagator over the lag (the
    thesis' 2.116-2.118: the cross term <x(s) x(s+lag)> = <x^2>(s) + <xv>(s) K).  Moments
    from ``powerlaw_udsbm_moments``; their difference loses digits when the increment is
    small against <x^2>(s) (relative error ~1e-11 <x^2>(s) / increment).  Equals
    ``udsbm_increment_msd`` for a = 1 (tested)."""
    _check_powerlaw(gamma0, D0, tau0, exponent)
    lag, start = np.broadcast_arrays(
        np.asarray(lag, dtype=np.float64), np.asarray(start, dtype=np.float64)
    )
    if np.any(lag < 0) or np.any(start < 0):
        raise ValueError("lag and start must be >= 0")
    v0 = D0 * gamma0 if v0_sq is None else float(v0_sq)
    sol = _powerlaw_ode(
        gamma0, tau0, exponent, v0 / (D0 * gamma0), float(gamma0 * np.max(start + lag, initial=0))
    )
    y0 = sol((gamma0 * start).reshape(-1)).reshape((3, *start.shape))
    y1 = sol((gamma0 * (start + lag)).reshape(-1)).reshape((3, *start.shape))
    k = _powerlaw_propagator_integral(start, lag, gamma0, tau0, exponent)
    out = dim * ((y1[0] - y0[0]) * D0 / gamma0 - 2.0 * y0[1] * D0 * k)
    return out[()] if out.ndim == 0 else out
