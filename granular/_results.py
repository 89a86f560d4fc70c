"""What the result types (``Trajectory``, ``LangevinResult``, ``EnsembleResult``) share:
read-only arrays, the choice of accumulated TAMSD lags, the measured ergodicity breaking
(deprecation notices: ``granular._deprecation``)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .errors import shown


def readonly(value: Any) -> Any:
    """A read-only view of an array (no copy), so that a caller writing into an array a
    result handed out gets a ValueError instead of changing the result unseen; None and
    anything not an array pass through."""
    if not isinstance(value, np.ndarray):
        return value
    view = value.view(np.ndarray)
    view.flags.writeable = False
    return view


def _no_lags() -> ValueError:
    """The error of a TAMSD asked of a run that accumulated none (no ``tamsd_lags``)."""
    return ValueError(
        "no time-averaged MSD was accumulated (the run had no tamsd_lags): ask for it "
        "before the run, with langevin.run(..., tamsd_lags=[...]) -- lags in time, whole "
        "steps of dt, at most t_stop (e.g. tamsd_lags=[dt, 10 * dt, 100 * dt])"
    )


def _lag_indices(
    available: NDArray[np.float64], dt: float, lags: ArrayLike | None, lag_samples: ArrayLike | None
) -> NDArray[np.intp]:
    """Indices into ``available`` (lags in time, whole multiples of ``dt``) of the lags
    asked for: all of them when neither ``lags`` (in time) nor ``lag_samples`` (in steps)
    is given.  An engine that accumulates the TAMSD on the fly has it at those lags
    only, so any other lag is refused by name, with the nearest that were accumulated."""
    if lags is not None and lag_samples is not None:
        raise TypeError("give at most one of lags (in time) and lag_samples (in steps)")
    have = np.rint(np.asarray(available, dtype=np.float64) / dt).astype(np.int64)
    if len(have) == 0:
        raise _no_lags()
    if lags is None and lag_samples is None:
        return np.arange(len(have))
    if lag_samples is not None:
        k = np.atleast_1d(np.asarray(lag_samples))
        if k.size and not np.issubdtype(k.dtype, np.integer):
            if not np.all(np.isfinite(k)) or np.any(k != np.rint(k)):
                raise ValueError(f"lag_samples must be whole numbers of steps, got {shown(k)}")
        k = k.astype(np.int64).reshape(-1)
    else:
        t = np.atleast_1d(np.asarray(lags, dtype=np.float64)).reshape(-1)
        k = np.rint(t / dt).astype(np.int64) if np.all(np.isfinite(t)) else np.full(t.shape, -1)
        off = ~np.isclose(t, k * dt, rtol=1e-9, atol=0.0)
        k[off] = -1  # not a whole number of steps: never accumulated
    pos = np.searchsorted(have, k)
    found = (pos < len(have)) & (have[np.minimum(pos, len(have) - 1)] == k)
    if not np.all(found):
        miss = int(np.argmin(found))
        asked = (np.asarray(lag_samples) if lags is None else np.asarray(lags)).reshape(-1)[miss]
        # the accumulated lags on either side of the one asked for
        at = np.searchsorted(have, (asked if lags is None else asked / dt))
        near = np.unique(have[[max(at - 1, 0), min(at, len(have) - 1)]])
        unit, scale = (" steps", 1) if lags is None else ("", dt)
        raise ValueError(
            f"lag {shown(asked)}{unit} was not accumulated: the engine keeps the TAMSD only "
            f"at the lags given to run(tamsd_lags=...); the nearest of those: "
            f"{' and '.join(shown(k * scale) for k in near)}{unit} (all: {shown(have * scale)})"
        )
    return pos


def ergodicity_breaking(
    result: Any,
    lags: ArrayLike | None,
    lag_samples: ArrayLike | None,
    particles: ArrayLike | None,
) -> NDArray[np.float64]:
    """Every result's ``ergodicity_breaking(lags, *, lag_samples, particles)``:
    ``analysis.ergodicity_breaking`` of ``result.tamsd(..., per_particle=True)``."""
    from . import analysis

    per = result.tamsd(lags, lag_samples=lag_samples, particles=particles, per_particle=True)
    return analysis.ergodicity_breaking(per)
