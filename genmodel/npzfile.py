"""Read an ``.npz`` archive of plain arrays with every size checked before it is allocated.

``numpy.load`` trusts each member's header: a few hundred bytes that declare a shape of 10**15
elements make it reserve that much memory before reading a byte of data. :func:`read_npz`
reads the headers first and refuses, naming the member, any array whose declared size exceeds
the bytes the archive actually holds for it, the per-file budget, or whose dtype is not a plain
number, boolean or (optionally) string type. Object arrays (which would need pickle) are
always refused.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

#: default budget for all arrays of one archive, in bytes (4 GiB)
MAX_BYTES = 4 << 30
#: default bound on the number of members of one archive
MAX_MEMBERS = 100_000


class NpzError(ValueError):
    """An archive that is not a readable ``.npz`` of plain arrays within its bounds."""


def _header(f):
    version = np.lib.format.read_magic(f)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(f, max_header_size=10_000)
    if version == (2, 0):
        return np.lib.format.read_array_header_2_0(f, max_header_size=10_000)
    raise NpzError(f"unsupported .npy format version {version}")


def read_npz(path, *, kinds: str = "biuf", max_bytes: int = MAX_BYTES,
             max_members: int = MAX_MEMBERS) -> dict[str, np.ndarray]:
    """All arrays of the archive at ``path``, keyed by name.

    Parameters
    ----------
    path : str or pathlib.Path
        An archive written by ``numpy.savez`` or ``numpy.savez_compressed``.
    kinds : str, optional
        Accepted dtype kinds (``numpy.dtype.kind``), default booleans, integers and floats; add
        ``"U"`` for unicode strings.
    max_bytes : int, optional
        Largest total size of the arrays, bytes (default :data:`MAX_BYTES`).
    max_members : int, optional
        Largest number of arrays (default :data:`MAX_MEMBERS`).

    Returns
    -------
    dict of str to numpy.ndarray

    Raises
    ------
    NpzError
        When the file is not an archive of ``.npy`` members, a member has another dtype kind, or
        a declared size exceeds the stored data, ``max_bytes`` or ``max_members``; the message
        names the file and the member.
    """
    path = Path(path)
    out: dict[str, np.ndarray] = {}
    total = 0
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
            if len(infos) > max_members:
                raise NpzError(f"{path}: {len(infos)} arrays, more than the limit of {max_members}")
            for info in infos:
                name = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
                with z.open(info) as f:
                    try:
                        shape, fortran, dtype = _header(f)
                    except ValueError as err:
                        raise NpzError(f"{path}: member {name!r} is not a .npy array ({err})") from None
                    if dtype.hasobject or dtype.kind not in kinds:
                        raise NpzError(f"{path}: array {name!r} has dtype {dtype}, not one of the kinds "
                                       f"{kinds!r} read here")
                    count = int(np.prod(shape, dtype=object))
                    nbytes = count * dtype.itemsize
                    if nbytes > info.file_size:
                        raise NpzError(f"{path}: array {name!r} declares shape {shape} ({nbytes} bytes) but the "
                                       f"archive holds {info.file_size} bytes for it")
                    total += nbytes
                    if total > max_bytes:
                        raise NpzError(f"{path}: arrays larger than the limit of {max_bytes} bytes")
                    data = f.read(nbytes)
                    if len(data) != nbytes:
                        raise NpzError(f"{path}: array {name!r} is cut short")
                    arr = np.frombuffer(data, dtype=dtype, count=count)
                    arr = arr.reshape(shape[::-1]).T if fortran else arr.reshape(shape)
                    out[name] = arr.copy()
    except (OSError, zipfile.BadZipFile, EOFError) as err:
        raise NpzError(f"{path}: unreadable archive ({err})") from None
    return out
