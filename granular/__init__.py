"""granular: molecular and granular gases of hard disks and spheres.

Event-driven molecular dynamics and Langevin models with a C core, and the analysis
that checks them against theory.

>>> import granular
>>> scene = granular.Scene.random(1000, 0.025, restitution=0.8, seed=1)
>>> traj = granular.Simulation(scene).run(t_stop=10.0, sample_times=[0, 1, 10])
"""
from . import errors
from .errors import (GranularError, InelasticCollapseError, NoProgressError, NonFiniteError,
                     OutsideBoxError, OverlapError, UnstableStepError)
from .scene import Scene
from .simulation import Simulation
from .trajectory import Trajectory
from .ensemble import EnsembleResult, ensemble
from . import analysis, langevin, theory

__version__ = "0.1.0"
__all__ = ["Scene", "Simulation", "Trajectory", "ensemble", "EnsembleResult", "analysis",
           "langevin", "theory", "errors", "GranularError", "OverlapError",
           "OutsideBoxError", "InelasticCollapseError", "NoProgressError", "NonFiniteError",
           "UnstableStepError"]
