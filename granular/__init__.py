"""granular: molecular and granular gases of hard disks and spheres.

Event-driven molecular dynamics and Langevin models with a C core, and the analysis
that checks them against theory.
"""
from . import errors

__version__ = "0.1.0"
