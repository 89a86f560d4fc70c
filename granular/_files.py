"""Writing files atomically, and telling granular's files apart by their first bytes.

``atomic_target`` is used for GSD files (granular/gsd_io.py) and, through ``write_atomic``,
for checkpoints (granular/checkpoint.py) and an ensemble's run files
(granular/ensemble_store.py); ``kind_of`` lets a reader that was handed the wrong
kind of file say what the file is and which function reads it.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator
from typing import IO

# The first bytes of each kind of file: a zip archive (an .npz, and so a checkpoint or an
# ensemble's run file), a single .npy array, a GSD file (its magic number 0x65DF65DF65DF65DF,
# little-endian).
_MAGIC = (
    (b"PK\x03\x04", "npz"),
    (b"PK\x05\x06", "npz"),  # a zip archive with no members
    (b"\x93NUMPY", "npy"),
    (b"\xdf\x65\xdf\x65\xdf\x65\xdf\x65", "gsd"),
)
# What each kind is, and what reads it, for the messages of a reader given another kind.
WHAT_READS = {
    "npz": "a NumPy .npz archive (a checkpoint written by Simulation.save is one: read it "
    "with granular.Simulation.load)",
    "npy": "a single NumPy .npy array (read it with numpy.load)",
    "gsd": "a GSD trajectory file (read it with granular.read, or take one frame as a scene "
    "with granular.Scene.from_gsd)",
}


def kind_of(head: bytes) -> str | None:
    """The kind of file whose first bytes are ``head`` ("npz", "npy", "gsd"), or None.

    Parameters
    ----------
    head : bytes
        The file's first 8 bytes (or more).
    """
    for magic, kind in _MAGIC:
        if head.startswith(magic):
            return kind
    return None


def check_kind(
    source: str | os.PathLike | IO[bytes],
    want: str,
    error: type[Exception] = ValueError,
    where: str | None = None,
) -> str | None:
    """Raise ``error`` if the file ``source`` starts as another kind of file than ``want``
    ("npz", "gsd"), saying what it is and which function reads it; return its kind
    (``want``), or None for a file that cannot be read or is of no kind known here, which
    is left to the reader's own checks.

    Parameters
    ----------
    source : str, os.PathLike or binary file
        The file a reader was given: a path, or a file open at its start (left there).
    want : str
        The kind that reader reads.
    error : type of Exception
        What to raise: the reader's own error class (GSDFileError, CheckpointError).
    where : str, optional
        How the message names the file (default: the path's repr).
    """
    if isinstance(source, (str, os.PathLike)):
        try:
            with open(source, "rb") as f:
                head = f.read(8)
        except OSError:
            return None
        where = repr(os.fspath(source)) if where is None else where
    else:
        head = source.read(8)
        source.seek(0)
        where = repr(getattr(source, "name", "the file")) if where is None else where
    kind = kind_of(head)
    if kind is not None and kind != want:
        raise error(f"{where} is not {WHAT_READS[want].split(' (')[0]}: it is {WHAT_READS[kind]}")
    return kind


@contextlib.contextmanager
def atomic_target(path: str | os.PathLike, suffix: str = ".part") -> Iterator[str]:
    """Write a file so that a crash mid-way never leaves a half file: yield the path of a
    new empty temporary file (``.tmp-*``) in ``path``'s directory for the caller to write;
    when the ``with`` block ends without an exception it is flushed to disk and renamed
    over ``path`` (a rename within a file system is atomic); on any exception, a
    KeyboardInterrupt too, it is removed and ``path`` left as it was.

    The file gets the permissions a plain ``open(path, "w")`` would give it: those of the
    file it replaces, or for a new file 0o666 less the process' umask (the temporary file
    is created with mode 0o666 and the kernel applies the umask and any default ACL).
    A writer that truncates the temporary file keeps its mode.

    Parameters
    ----------
    path : str or os.PathLike
        Where the file goes.
    suffix : str
        The temporary file's suffix (some writers want their own, e.g. ``.gsd``).
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    try:
        mode = os.stat(path).st_mode & 0o777  # not set-id bits, which a write clears
    except FileNotFoundError:
        mode = None
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
    for _ in range(100):  # a random name taken already: draw another
        tmp = os.path.join(folder, f".tmp-{secrets.token_hex(8)}{suffix}")
        try:
            fd = os.open(tmp, flags, 0o666)
            break
        except FileExistsError:
            continue
    else:
        raise FileExistsError(f"no free temporary name in {folder!r}")
    try:
        try:
            if mode is not None and hasattr(os, "fchmod"):
                os.fchmod(fd, mode)
        finally:
            os.close(fd)
        yield tmp
        fd = os.open(tmp, os.O_RDONLY)  # the writer's own handle is closed: sync the file
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_atomic(path: str | os.PathLike, data: bytes, suffix: str = ".part") -> None:
    """Write ``data`` to ``path`` atomically (see ``atomic_target``): a crash mid-way
    leaves the old file, or none, never a half one.

    Parameters
    ----------
    path : str or os.PathLike
        Where to write.
    data : bytes
        The whole content.
    suffix : str
        The temporary file's suffix.
    """
    with atomic_target(path, suffix) as tmp, open(tmp, "wb") as f:
        f.write(data)
