"""What the Python side needs to know of rough particles' collisions (csrc/rule.h)."""

from __future__ import annotations

import math
from typing import Any


def rough_keeps_energy(scene: Any) -> bool:
    """Whether a scene's rough collisions keep the energy: smooth (tangential restitution
    -1), or perfectly rough (1) without a Coulomb limit (sliding dissipates).  The normal
    part is the restitution's question."""
    beta = scene.tangential_restitution
    return bool(beta == -1.0 or (beta == 1.0 and scene.friction == math.inf))
