"""Exceptions raised by granular.

The C core returns status codes; the binding (``granular._core``) turns each into one of
these classes, with the particles and the time involved as attributes so that a script can
react to, say, an inelastic collapse without parsing the message.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np


class GranularError(Exception):
    """Base class of every error granular raises on its own account."""

    def __init__(
        self,
        message: str,
        *,
        particles: Iterable[int] = (),
        time: float | None = None,
        value: float | None = None,
    ) -> None:
        super().__init__(message)
        self.particles: tuple[int, ...] = tuple(int(p) for p in particles)
        self.time = time
        self.value = value


class OverlapError(GranularError, ValueError):
    """Two particles overlap (``.particles`` names the pair, ``.value`` the depth)."""


class OutsideBoxError(GranularError, ValueError):
    """A particle lies outside the box (``.particles`` names it)."""


class InelasticCollapseError(GranularError, RuntimeError):
    """Inelastic collapse: collisions pile up at one instant.

    ``.particles`` names the particles involved and ``.time`` when it was detected.  Turn on
    the TC model (``Scene(..., contact_duration=t_c)``) to let such a run continue.
    """


class HeatedWallsError(GranularError, RuntimeError):
    """Heated walls (``wall_restitution > 1``) pumped so much energy into the gas that the
    event times can no longer be resolved in float64.  ``.time`` is when it was detected
    and ``.value`` the kinetic energy over its initial value."""


class FrozenGasError(GranularError, RuntimeError):
    """The gas is so slow (it cooled, or started so) that its speeds times the smallest
    diameter fall below 1e-140: float64 can no longer resolve when two particles touch.
    ``.time`` is when it was detected and ``.value`` the kinetic energy then."""


class NonFiniteError(GranularError, FloatingPointError):
    """A NaN or infinity appeared in the state."""


class UnstableStepError(GranularError, ValueError):
    """An integrator step is at or past its stability limit (``.value`` is gamma*dt)."""


class ProcessBackendError(GranularError, RuntimeError):
    """The process backend cannot run this ensemble: the script calls ``ensemble`` outside
    an ``if __name__ == "__main__":`` block, which the worker processes re-run as they start
    (found before any run starts), or a worker process died (``BrokenProcessPool``)."""


class NoProgressError(GranularError, RuntimeError):
    """A run without a time limit made no progress towards its stop criterion (no
    collision in a great many events), so it would never end."""


class ClusteringWarning(UserWarning):
    """A granular gas in a periodic box beyond the critical size of the shear instability
    (``granular.theory.critical_box_size``): its homogeneous cooling will end (vortices,
    then clusters) and Haff's law will fail.  Issued once per Simulation, by the first
    ``run`` that can reach the onset t* (``granular.clustering.unstable_box``); for a
    ``Viscoelastic`` law, judged at its effective restitution, by the first run."""


class CheckpointError(GranularError, ValueError):
    """A checkpoint (``Simulation.load``, an ensemble's ``save_to`` directory) cannot be
    used: not a checkpoint, truncated or corrupt, written by another version of granular,
    or made for another model."""


class GSDFileError(GranularError, ValueError):
    """A GSD file cannot be read (``granular.read``, ``Scene.from_gsd``): not a GSD file,
    truncated or corrupt, not written by granular, or holding a field that is missing, of the
    wrong shape or an impossible value.  The message names the file, the frame and the
    field."""


def shown(value: object, limit: int = 8) -> str:
    """``value`` as a message shows it: numbers plainly (``0.5``, not ``np.float64(0.5)``,
    to 12 significant digits, which hides float64's last-bit noise such as 0.1 * 3),
    sequences and arrays as ``[a, b, ...]`` (at most ``limit`` entries, the rest counted),
    strings quoted, anything else as its repr.  NumPy 2 writes a scalar's repr with its
    type, which a user reading "got np.float64(-1.0)" should not have to decode."""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, np.floating) and value.itemsize < 8:
        return f"{float(value):.7g}"  # float32 and float16 hold no more digits
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.12g}"
    if isinstance(value, (complex, np.complexfloating)):
        return repr(complex(value))
    if isinstance(value, np.generic):  # np.str_, np.bytes_, ...
        return repr(value.item())
    if isinstance(value, dict):
        return "{" + ", ".join(f"{shown(k)}: {shown(v, limit)}" for k, v in value.items()) + "}"
    if isinstance(value, np.ndarray) and value.ndim == 0:
        return shown(value[()], limit)
    if isinstance(value, (list, tuple, np.ndarray)):
        items = list(np.asarray(value).reshape(-1)) if isinstance(value, np.ndarray) else value
        head = [shown(v, limit) for v in items[:limit]]
        if len(items) > limit:
            head.append(f"... ({len(items)} in all)")
        if isinstance(value, tuple):
            return "(" + ", ".join(head) + ("," if len(items) == 1 else "") + ")"
        return "[" + ", ".join(head) + "]"
    return repr(value)
