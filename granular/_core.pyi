"""Types of the C extension (csrc/_core.c), for mypy; make lint checks them against the
built module (mypy.stubtest).  Internal: granular.Simulation, granular.langevin and the
Scene use it.  Output arrays are C-contiguous, native-order, of the dtype named."""

from typing import Any, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

BIG_MAX: int
BIG_RATIO: float
CHECKPOINT_LAYOUT: int
DRIVE_THERMOSTAT: int
DRIVE_WHITE_NOISE: int
EDMD_KEYWORDS: tuple[str, ...]
HEADS_CACHED: int
LAW_CONSTANT: int
LAW_TABLE: int
LAW_TABLE_MAX: int
LAW_VISCOELASTIC: int
RNG_KERNEL: str
SCAN_KERNEL: str
SDE_BLOCK: int
SDE_MAX_STEPS: int
STOP_BUDGET: int
STOP_COLLISIONS: int
STOP_ENERGY: int
STOP_IDLE: int
STOP_TIME: int
VISCO_C1: float
VISCO_C2: float
VISCO_DELTA_MAX: float

@final
class EDMD:
    # every argument a keyword (so are advance's and edmd_check's); the scene's are
    # EDMD_KEYWORDS, made by granular/_scene_params.py (Scene._engine_keywords)
    def __init__(
        self,
        *,
        cell_factor: float = ...,
        big_ratio: float = ...,
        shell: float = ...,
        stress: bool = ...,
        **scene: Any,
    ) -> None: ...
    # Returns (the STOP_* reason, the next sample's index).  stop_kinetic_energy < 0: no
    # energy criterion; a buffer left None is not sampled.
    def advance(
        self,
        *,
        t_stop: float,
        collisions_per_particle: float,
        stop_kinetic_energy: float,
        max_events: int,
        sample_times: ArrayLike,
        next: int,
        positions: NDArray[np.float64] | None = ...,
        velocities: NDArray[np.float64] | None = ...,
        kinetic_energy: NDArray[np.float64] | None = ...,
        momentum: NDArray[np.float64] | None = ...,
        pair_collisions: NDArray[np.int64] | None = ...,
        wall_collisions: NDArray[np.int64] | None = ...,
        virial: NDArray[np.float64] | None = ...,
        wall_impulse: NDArray[np.float64] | None = ...,
        stress_collisional: NDArray[np.float64] | None = ...,
        kinetic_time_tensor: NDArray[np.float64] | None = ...,
        kinetic_tensor: NDArray[np.float64] | None = ...,
        angular_velocities: NDArray[np.float64] | None = ...,
        wall_work: NDArray[np.float64] | None = ...,
        collision_loss: NDArray[np.float64] | None = ...,
    ) -> tuple[int, int]: ...
    def state(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]: ...
    # rough particles' spins now ((N,) in 2D, (N, 3) in 3D); None for smooth ones
    def angular_velocities(self) -> NDArray[np.float64] | None: ...
    def counters(self) -> dict[str, Any]: ...
    def save_state(self) -> bytes: ...
    def restore_state(
        self, state: bytes | bytearray | memoryview | NDArray[np.uint8], /
    ) -> None: ...

def edmd_check(
    *, cell_factor: float = ..., big_ratio: float = ..., shell: float = ..., **scene: Any
) -> None: ...
def big_cut(radii: ArrayLike, big_ratio: float, /) -> float: ...
def big_particles(
    radii: ArrayLike, lengths: ArrayLike, big_ratio: float, cell_factor: float, /
) -> NDArray[np.bool_]: ...
def edmd_bytes_per_particle(dim: int, lists: bool, /) -> int: ...
def sde_run(
    *,
    dim: int,
    model: int,
    scheme: int,
    gamma0: float,
    D0: float,
    tau0: float,
    dt: float,
    key: int,
    n: int,
    first: int,
    step_from: int,
    step_to: int,
    n_steps: int,
    x: NDArray[np.float64],
    v: NDArray[np.float64],
    sample_steps: NDArray[np.int64],
    x2: NDArray[np.float64],
    v2: NDArray[np.float64],
    positions: NDArray[np.float64] | None,
    lags: NDArray[np.int64],
    tamsd: NDArray[np.float64],
    ring: NDArray[np.float64],
    carry: NDArray[np.float64] | None = None,
    threads: int = 1,
    tamsd_estimator: int = 0,
    exponent: float = 1.0,
    accel: NDArray[np.float64] | None = None,
    stiffness: NDArray[np.float64] | None = None,
    origin: NDArray[np.float64] | None = None,
) -> None: ...
def sde_force_step(
    gamma: float, D: float, w: float, dt: float, /
) -> tuple[float, float, float, float, float, float]: ...
def sde_lag_stride(lag: int, tamsd_estimator: int = 0, /) -> int: ...
def sde_ring_size(dim: int, lags: ArrayLike, tamsd_estimator: int = 0, /) -> int: ...
