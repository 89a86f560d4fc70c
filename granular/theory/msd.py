"""Mean squared displacements of a molecular gas (Langevin) and of a granular gas in the
homogeneous cooling state, and their short- and long-time limits."""

from __future__ import annotations

import math

import numpy as np

from .._params import keyword_only
from ._numerics import FloatOrArray, _one_minus_exp_over, _x_plus_expm1


@keyword_only("t", "D0", "gamma0", "dim", "v0_sq")
def msd_langevin(
    t: FloatOrArray, *, D0: float, gamma0: float, dim: int = 3, v0_sq: FloatOrArray | None = None
) -> FloatOrArray:
    """MSD of a molecular gas and of the underdamped Langevin equation (2.68), total over
    ``dim`` dimensions: ``d [2 D0 t + (2 D0/gamma0)(exp(-gamma0 t) - 1)]``.

    ``v0_sq`` is the initial mean squared velocity per component; by default the thermal
    ``T0/m = D0 gamma0`` of (2.68).  Otherwise the VACF gains
    ``(v0_sq - D0 gamma0) exp(-gamma0 (t1 + t2))`` (2.101) and the MSD
    ``d (v0_sq - D0 gamma0) ((1 - exp(-gamma0 t)) / gamma0)^2``.
    Limits: ballistic ``d v0_sq t^2`` for t << 1/gamma0, diffusive ``2 d D0 t`` for
    t >> 1/gamma0.
    """
    t = np.asarray(t, dtype=np.float64)
    x = gamma0 * t
    out = 2.0 * D0 / gamma0 * _x_plus_expm1(x)
    if v0_sq is not None:
        out = out + (v0_sq - D0 * gamma0) * (t * _one_minus_exp_over(x)) ** 2
    return dim * out


@keyword_only("t", "D0", "gamma0", "tau0", "dim")
def msd_granular(
    t: FloatOrArray, *, D0: float, gamma0: float, tau0: float, dim: int = 3
) -> FloatOrArray:
    """MSD of a granular gas in the homogeneous cooling state (2.79), total over ``dim``:
    ``d 2 D0 tau0 [ln(1 + t/tau0) + ((1 + t/tau0)^(-gamma0 tau0) - 1) / (gamma0 tau0)]``.

    From the VACF (2.77), Maxwellian start at T0.  Limits: ballistic ``d (T0/m) t^2`` for
    t << tau0 and 1/gamma0; ultraslow ``2 d D0 tau0 ln(t/tau0)`` for t >> tau0.  Equals
    ``msd_langevin`` for tau0 = inf.
    """
    if math.isinf(tau0):
        return msd_langevin(t, D0=D0, gamma0=gamma0, dim=dim)
    a = gamma0 * tau0
    u = np.log1p(np.asarray(t, dtype=np.float64) / tau0)
    return dim * 2.0 * D0 * tau0 * _x_plus_expm1(a * u) / a


@keyword_only("t", "temperature", "mass", "dim")
def msd_ballistic(
    t: FloatOrArray, *, temperature: float, mass: float = 1.0, dim: int = 3
) -> FloatOrArray:
    """Short-time limit of every MSD here: free flight, ``d (T/m) t^2``."""
    return dim * temperature / mass * np.asarray(t, dtype=np.float64) ** 2


@keyword_only("t", "D0", "dim", "gamma0")
def msd_diffusive(
    t: FloatOrArray, *, D0: float, dim: int = 3, gamma0: float | None = None
) -> FloatOrArray:
    """Einstein's long-time limit of a molecular gas, ``2 d D0 t`` (2.46); with gamma0 the
    exact asymptote of (2.68), ``2 d D0 (t - 1/gamma0)``."""
    shift = 0.0 if gamma0 is None else 1.0 / gamma0
    return 2.0 * dim * D0 * (np.asarray(t, dtype=np.float64) - shift)


@keyword_only("t", "D0", "tau0", "dim", "gamma0")
def msd_logarithmic(
    t: FloatOrArray, *, D0: float, tau0: float, dim: int = 3, gamma0: float | None = None
) -> FloatOrArray:
    """Long-time limit of a granular gas, ``2 d D0 tau0 ln(1 + t/tau0)`` (2.80); with gamma0
    the exact asymptote of (2.79), ``2 d D0 tau0 (ln(1 + t/tau0) - 1/(gamma0 tau0))``."""
    shift = 0.0 if gamma0 is None else 1.0 / (gamma0 * tau0)
    return 2.0 * dim * D0 * tau0 * (np.log1p(np.asarray(t, dtype=np.float64) / tau0) - shift)
