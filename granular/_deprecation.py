"""The one deprecation path of the package: a form deprecated in the coming release (0.2.0)
keeps working through that release with a FutureWarning -- shown to users, where a
DeprecationWarning is hidden outside ``__main__`` -- that names what to use instead and the
release it goes in."""

from __future__ import annotations

import warnings

REMOVAL_VERSION = "0.3.0"


def deprecated(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` is deprecated and removed in ``REMOVAL_VERSION``, naming ``new``.

    Parameters
    ----------
    old : str
        The deprecated form, as the user wrote it (``"granular.demo"``).
    new : str
        What to write instead, as a sentence (``"use granular.cli.demo"``).
    stacklevel : int
        As for `warnings.warn`: 3 points at the caller of the function that calls this.
    """
    warnings.warn(
        f"{old} is deprecated and removed in granular {REMOVAL_VERSION}; {new}",
        FutureWarning,
        stacklevel=stacklevel,
    )
