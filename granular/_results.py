"""What the result types (``Trajectory``, ``LangevinResult``, ``EnsembleResult``) share:
read-only arrays (deprecation notices: ``granular._deprecation``)."""

from __future__ import annotations

from typing import Any

import numpy as np


def readonly(value: Any) -> Any:
    """A read-only view of an array (no copy), so that a caller writing into an array a
    result handed out gets a ValueError instead of changing the result unseen; None and
    anything not an array pass through."""
    if not isinstance(value, np.ndarray):
        return value
    view = value.view(np.ndarray)
    view.flags.writeable = False
    return view
