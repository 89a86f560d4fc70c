"""What the result types (``Trajectory``, ``LangevinResult``, ``EnsembleResult``) share:
read-only arrays and the deprecation notices of forms that are going."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

# A form deprecated in the coming release (0.2.0) works, with a FutureWarning, through that
# release and goes in the one after it
REMOVAL_VERSION = "0.3.0"


def readonly(value: Any) -> Any:
    """A read-only view of an array (no copy), so that a caller writing into an array a
    result handed out gets a ValueError instead of changing the result unseen; None and
    anything not an array pass through."""
    if not isinstance(value, np.ndarray):
        return value
    view = value.view(np.ndarray)
    view.flags.writeable = False
    return view


def deprecated(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` goes in ``REMOVAL_VERSION``, naming ``new`` to use instead."""
    warnings.warn(
        f"{old} is deprecated and goes in granular {REMOVAL_VERSION}; {new}",
        FutureWarning,
        stacklevel=stacklevel,
    )
