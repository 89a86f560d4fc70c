"""The event-driven engine as the Python side builds and runs it: the choice of mode
(cell grid or neighbour lists), the memory check and the engine's arguments, in one
place for Simulation and for Scene.random's lattice melt.

Imports neither scene nor simulation (both import it), so the two need not import each
other.  The engine's own rules -- which particles are big, the default big_ratio, what
it allocates per particle -- are asked of the C core (_core), which owns them."""

from __future__ import annotations

import math
import os
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from . import _core


class _Scene(Protocol):
    """What the engine is built from: a Scene (named here by what it offers, so that this
    module need not import scene, which imports it)."""

    @property
    def radii(self) -> NDArray[np.float64]: ...
    @property
    def n(self) -> int: ...
    @property
    def dim(self) -> int: ...
    @property
    def packing_fraction(self) -> float: ...
    @property
    def shear_rate(self) -> float: ...
    def _engine_keywords(self) -> dict[str, Any]: ...


# shell="auto": neighbour lists with this shell (in largest diameters) for dense 3D
# scenes.  Measured (pair collisions/s, N = 1e4, melted Scene.random, cells vs lists
# with shell 0.25, two runs each): packing 0.30 0.67-0.69 vs 0.47-0.50 M; 0.35 0.46-0.67
# vs 0.53-0.54 M; 0.40 0.54-0.60 vs 0.60-0.64 M; 0.45 0.44-0.50 vs 0.68-0.73 M; shells
# 0.15 / 0.35 were slower than 0.25 at 0.45 and 0.5.  At N = 2048 lists win from 0.3 on
# (speed_accuracy.dense_cost).  2D at area fractions 0.6 and 0.68: within 5 % either way,
# so cells.
LIST_SHELL = 0.25
LIST_MIN_PACKING = 0.4
# Events per call into C: about 0.1 s of work, so Ctrl-C and the progress bar respond
# promptly while the Python overhead stays negligible.
CHUNK = 200_000


def check_memory(need, what):
    """Refuse, before allocating, anything that would take more than half of this
    machine's memory (on Linux an allocation that large may 'succeed' and end in the
    out-of-memory killer instead of an exception)."""
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return
    if need > 0.5 * total:
        raise MemoryError(
            f"{what} needs {need / 2**30:.1f} GiB, more than half of this "
            f"machine's {total / 2**30:.1f} GiB"
        )


def build(
    scene: _Scene,
    cell_factor: float = 1.0,
    big_ratio: float = _core.BIG_RATIO,
    shell: Any = "auto",
    stress: bool = False,
) -> _core.EDMD:
    """A new engine (_core.EDMD) at a Scene's state; see Simulation for the knobs."""
    big = bool(np.max(scene.radii) > _core.big_cut(scene.radii, big_ratio))
    if scene.shear_rate != 0.0:
        # Lees-Edwards: the big particles' image tables are fixed, the sliding images are
        # not (csrc/boundary.h): every particle in the cells or the lists
        big = False
    if isinstance(shell, str) and shell == "auto":
        dense = scene.dim == 3 and scene.packing_fraction >= LIST_MIN_PACKING
        shell = LIST_SHELL if dense and not big else 0.0
    elif isinstance(shell, (bool, str)) or not isinstance(shell, (int, float, np.number)):
        from .errors import shown

        raise TypeError(f"shell must be 'auto' or a number >= 0, got {shown(shell)}")
    elif shell > 0 and big:
        # the shell is a fraction of the largest diameter: every small particle's
        # list would reach as far as the big one's (thousands of entries each)
        raise ValueError(
            f"neighbour lists (shell = {shell}) with particles wider than big_ratio = "
            f"{big_ratio} times the median: every list would reach as far as the widest; "
            "use shell=0 (cells keep the big ones out) or big_ratio=math.inf to insist"
        )
    check_memory(
        _core.edmd_bytes_per_particle(scene.dim, shell > 0) * scene.n,
        "the event-driven engine's state" + (" with neighbour lists" if shell > 0 else ""),
    )
    return _core.EDMD(
        **scene._engine_keywords(),
        cell_factor=float(cell_factor),
        big_ratio=float(big_ratio),
        shell=float(shell),
        stress=stress,
    )


def run_collisions(engine, collisions_per_particle):
    """Advance until the mean collisions per particle reach the target (no samples, no
    time limit), in chunks so that Ctrl-C is seen; returns the _core.STOP_* reason."""
    no_samples = np.empty(0)
    while True:
        code, _ = engine.advance(
            t_stop=math.inf,
            collisions_per_particle=float(collisions_per_particle),
            stop_kinetic_energy=-1.0,
            max_events=CHUNK,
            sample_times=no_samples,
            next=0,
        )
        if code != _core.STOP_BUDGET:
            return code
