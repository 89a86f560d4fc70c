"""How the applications write their results: strict JSON, which any parser reads."""

from __future__ import annotations

import json
import math


def _json_safe(value):
    """``value`` with every non-finite float replaced by None, for strict JSON."""
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_safe(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path, value):
    """Write ``value`` as strict JSON (non-finite numbers as null; ``allow_nan=False`` so
    that no Infinity or NaN, which strict parsers reject, can slip through)."""
    with open(path, "w") as f:
        json.dump(_json_safe(value), f, indent=1, allow_nan=False)
