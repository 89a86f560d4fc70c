"""Reading NumPy ``.npz`` archives that nobody vouches for: a checkpoint
(granular/checkpoint.py) and an ensemble's run files (granular/ensemble_store.py), by one
set of rules, so that a damaged or crafted file costs at most its own size in memory and
runs no code:

- the file must be a regular file: a device or a FIFO could be read forever
  (``open_regular``, ``read_regular``);
- each zip member stored (``np.savez`` does not compress; a compressed member could
  inflate to any size), not encrypted, its stored size its size and lying inside the file,
  the members together no larger than the file, each named once (``check_members``);
- each member a ``.npy`` array of the format versions ``np.save`` writes for plain arrays,
  of numbers or text (never objects or structured types), whose header describes exactly
  the member's bytes, read to its end so that zipfile checks its CRC-32 (``read_member``).

Each function raises ValueError (EOFError for a member cut short) saying what is wrong;
the readers turn it into their own error, naming the file.
"""

from __future__ import annotations

import math
import os
import stat
import zipfile
from collections.abc import Callable
from typing import IO, Any, BinaryIO

import numpy as np

# np.save writes 1.0, or 2.0 for a header past 64 KiB; 3.0 only for structured types with
# field names outside Latin-1, which no reader here accepts.
_HEADERS = {
    (1, 0): np.lib.format.read_array_header_1_0,
    (2, 0): np.lib.format.read_array_header_2_0,
}


def open_regular(path: str | os.PathLike, limit: int | None = None) -> BinaryIO:
    """``path`` open for binary reading, refused (ValueError) unless it is a regular file
    of at most ``limit`` bytes; OSError (FileNotFoundError, PermissionError) as ``open``.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    limit : int, optional
        The most bytes it may have.
    """
    # non-blocking, so that opening a FIFO does not wait for a writer
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise ValueError("not a regular file (a directory, a device, a pipe or a socket)")
        if limit is not None and info.st_size > limit:
            raise ValueError(f"{info.st_size} bytes, more than the {limit} it can be")
        return open(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path: str | os.PathLike, limit: int | None = None) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes (``open_regular``).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    limit : int, optional
        The most bytes it may have.
    """
    with open_regular(path, limit) as f:
        size = os.fstat(f.fileno()).st_size
        data = f.read(size + 1)
    if len(data) != size:
        raise ValueError("its size changed while it was read")
    return data


def check_members(zf: zipfile.ZipFile, file_size: int) -> dict[str, zipfile.ZipInfo]:
    """The members of ``zf`` by name, refused unless each is stored, unencrypted, of its
    stated size and inside the archive's ``file_size`` bytes, together no more than those,
    and each named once.

    Parameters
    ----------
    zf : zipfile.ZipFile
        The archive.
    file_size : int
        The size of the archive's file in bytes.
    """
    infos = zf.infolist()
    names = {info.filename: info for info in infos}
    if len(names) != len(infos):
        raise ValueError("a member is named twice")
    for info in infos:
        if info.compress_type != zipfile.ZIP_STORED or info.flag_bits & 0x1:
            raise ValueError(
                f"its member {info.filename!r} is compressed or encrypted, which granular "
                "never writes (np.savez stores its members)"
            )
        if info.compress_size != info.file_size or info.header_offset + info.file_size > file_size:
            raise ValueError(f"its member {info.filename!r} claims more bytes than the file has")
    if sum(info.file_size for info in infos) > file_size:
        raise ValueError("its members claim more bytes than the file has")
    return names


def read_header(fp: IO[bytes], name: str, fortran_ok: bool = False) -> tuple[tuple, bool, np.dtype]:
    """(shape, fortran order, dtype) from the .npy header at the start of ``fp`` (member
    ``name``), refused unless of a version ``np.save`` writes, C-ordered (or Fortran-,
    with ``fortran_ok``) and of a plain type (no objects, fields or sub-arrays).

    Parameters
    ----------
    fp : binary file
        The member, at its start.
    name : str
        The member's name, for messages.
    fortran_ok : bool
        Accept a Fortran-ordered array (see ``read_member``).
    """
    version = np.lib.format.read_magic(fp)
    reader = _HEADERS.get(version)
    if reader is None:
        raise ValueError(f"{name}: .npy version {version}, not one of {sorted(_HEADERS)}")
    shape, fortran, dtype = reader(fp)
    if fortran and not fortran_ok:
        raise ValueError(f"{name}: a Fortran-ordered array, not a C-ordered one")
    if dtype.hasobject or dtype.names is not None or dtype.subdtype is not None:
        raise ValueError(f"{name}: an array of {dtype}, not of plain numbers or text")
    return shape, bool(fortran), dtype


def read_member(
    zf: zipfile.ZipFile,
    info: zipfile.ZipInfo,
    dtype: np.dtype | str,
    shape: tuple | None = None,
    max_bytes: int | None = None,
    fortran_ok: bool = False,
    check_head: Callable[[bytes, int], Any] | None = None,
) -> np.ndarray:
    """The .npy member ``info`` of ``zf`` as a read-only array, refused unless it holds
    an array of ``dtype`` (a dtype exactly, or a string of the dtype kinds allowed, e.g.
    "U" text of any length) and ``shape`` (None: any; an entry None: any extent there),
    its data fills the rest of the member exactly, and that is at most ``max_bytes``.
    Nothing beyond the header is read before its size is known to be right;
    ``check_head(head, nbytes)``, if given, checks the data's first 64 bytes before the
    rest is read.

    Parameters
    ----------
    zf : zipfile.ZipFile
        The archive (its members checked by ``check_members``).
    info : zipfile.ZipInfo
        The member.
    dtype : numpy.dtype or str
        The dtype it must have, or the dtype kinds it may have.
    shape : tuple, optional
        The shape it must have.
    max_bytes : int, optional
        The most bytes of data it may hold (default: its member's size bounds it).
    fortran_ok : bool
        Accept a Fortran-ordered array (what ``np.save`` writes for an array that is
        Fortran- but not C-contiguous).
    check_head : callable, optional
        Called as ``check_head(head, nbytes)`` before the rest is read.
    """
    name = info.filename
    with zf.open(info) as fp:
        got_shape, fortran, got = read_header(fp, name, fortran_ok)
        if got.kind not in dtype if isinstance(dtype, str) else got != dtype:
            raise ValueError(f"{name}: an array of {got}, not of {dtype}")
        if shape is not None and (
            len(got_shape) != len(shape)
            or any(w is not None and w != g for w, g in zip(shape, got_shape, strict=True))
        ):
            raise ValueError(f"{name}: an array of shape {got_shape}, not {shape}")
        nbytes = got.itemsize * math.prod(got_shape)
        left = info.file_size - fp.tell()
        if (max_bytes is not None and nbytes > max_bytes) or left != nbytes:
            at_most = "" if max_bytes is None else f" (at most {max_bytes})"
            raise ValueError(
                f"{name}: {left} bytes of data for an array of {nbytes} bytes{at_most}"
            )
        data = fp.read(min(nbytes, 64))
        if check_head is not None:
            check_head(data, nbytes)
        data += fp.read(nbytes - len(data))
        if len(data) != nbytes:
            raise EOFError(f"{name} is truncated")
        if fp.read(1):  # at the member's end: zipfile checks its CRC-32 on the way
            raise ValueError(f"{name} is longer than its header says")
    return np.frombuffer(data, dtype=got).reshape(got_shape, order="F" if fortran else "C")
