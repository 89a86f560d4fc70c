"""granular: molecular and granular gases of hard disks and spheres.

Event-driven molecular dynamics and Langevin models with a C core, and the analysis
that checks them against theory.

>>> import granular
>>> scene = granular.Scene.random(1000, 0.025, restitution=0.8, seed=1)
>>> traj = granular.Simulation(scene).run(t_stop=10.0, sample_times=[0, 1, 10])
"""

from . import (
    analysis,
    clustering,
    driving,
    errors,
    langevin,
    moments,
    restitution,
    theory,
    transport,
)
from .driving import PairThermostat, WhiteNoise
from .ensemble import EnsembleResult, ensemble
from .errors import (
    CheckpointError,
    ClusteringWarning,
    FrozenGasError,
    GranularError,
    GSDFileError,
    HeatedWallsError,
    InelasticCollapseError,
    NonFiniteError,
    NoProgressError,
    OutsideBoxError,
    OverlapError,
    ProcessBackendError,
    UnstableStepError,
)
from .restitution import ConstantRestitution, TabulatedRestitution, Viscoelastic
from .scene import Scene
from .simulation import Simulation
from .trajectory import Trajectory, read
from .walls import VibratingWall

__version__ = "0.1.0"

# imported on first use (PEP 562): they pull in matplotlib and MDAnalysis, which
# `import granular` must not
_LAZY = ("plot", "interop")


# the applications moved to granular.cli; the old names work with a FutureWarning
# (granular._deprecation) for one release
_MOVED = ("demo", "reproduce", "speed_accuracy", "bench", "bench_langevin")


def __getattr__(name):
    import importlib

    if name in _LAZY:
        return importlib.import_module(f".{name}", __name__)
    if name in _MOVED:
        from ._deprecation import deprecated

        deprecated(f"granular.{name}", f"it moved to granular.cli.{name}")
        return importlib.import_module(f".cli.{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))


__all__ = [
    "CheckpointError",
    "ClusteringWarning",
    "ConstantRestitution",
    "EnsembleResult",
    "FrozenGasError",
    "GSDFileError",
    "GranularError",
    "HeatedWallsError",
    "InelasticCollapseError",
    "NoProgressError",
    "NonFiniteError",
    "OutsideBoxError",
    "OverlapError",
    "PairThermostat",
    "ProcessBackendError",
    "Scene",
    "Simulation",
    "TabulatedRestitution",
    "Trajectory",
    "UnstableStepError",
    "VibratingWall",
    "Viscoelastic",
    "WhiteNoise",
    "analysis",
    "clustering",
    "driving",
    "ensemble",
    "errors",
    "langevin",
    "moments",
    "read",
    "restitution",
    "theory",
    "transport",
]
