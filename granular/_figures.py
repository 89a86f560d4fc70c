"""What granular's figures share (granular.plot's and granular._animate's): matplotlib,
imported only when a figure is drawn, and the axis labels with their units."""

from __future__ import annotations

import importlib
from typing import Any

# Axis labels with their units (mathtext).
TIME = r"time $t$ [$L\sqrt{m/\varepsilon}$]"
LAG_OR_TIME = r"time $t$ or lag $\Delta$ [$L\sqrt{m/\varepsilon}$]"
ENERGY = r"kinetic energy $E$ [$\varepsilon$]"
RELATIVE_ENERGY = r"$E(t)/E(0) - 1$ (dimensionless)"
COLLISIONS = "collisions per particle (dimensionless count)"
SPEED = r"speed $v$ [$\sqrt{\varepsilon/m}$]"
SPEED_DENSITY = r"probability density [$\sqrt{m/\varepsilon}$]"
TEMPERATURE = r"granular temperature $T$ [$\varepsilon$; $k_B = 1$]"
MSD = r"MSD $\langle |x(t) - x(0)|^2 \rangle$ [$L^2$]"
MSD_AND_TAMSD = r"MSD, time-averaged MSD [$L^2$]"
DIFFUSIVITY = r"diffusivity $D(t)$ [$L\sqrt{\varepsilon/m}$]"
POSITION = r"${}$ [$L$]"


def _matplotlib(module: str) -> Any:
    """Import a matplotlib module, or say which extra brings it (matplotlib is not a
    dependency of granular itself)."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if not (exc.name or "").startswith("matplotlib"):
            raise
        raise ModuleNotFoundError(
            "granular.plot draws with matplotlib, which is not installed: pip install "
            "matplotlib (or pip install 'granular[plot]')",
            name=exc.name,
        ) from exc
