"""The first check of every file reader: the path names an existing regular file of bounded size."""

from __future__ import annotations

import os
import stat
from pathlib import Path


def regular_file_size(path: Path, error: type[Exception], limit: int | None = None, limit_name: str = "") -> int:
    """Size of ``path`` in bytes; refuses anything but an existing regular file (symlinks are
    followed, so a link to a directory or a device is refused too) and, with ``limit``, a larger one.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    error : type of Exception
        What to raise (the reader's own error type), with the path in the message.
    limit : int, optional
        Largest size accepted, bytes.
    limit_name : str, optional
        How the message names the limit (e.g. ``"MAX_FILE_BYTES"``).

    Returns
    -------
    int

    Raises
    ------
    Exception
        ``error``: the file is missing or unreadable, not a regular file, or above ``limit``.
    """
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise error(f"{path}: file not found") from None
    except OSError as err:
        raise error(f"{path}: cannot be read ({err.strerror})") from None
    if not stat.S_ISREG(st.st_mode):
        kind = "a directory" if stat.S_ISDIR(st.st_mode) else "a device, pipe or socket"
        raise error(f"{path}: not a regular file ({kind})")
    if limit is not None and st.st_size > limit:
        named = f" ({limit_name})" if limit_name else ""
        raise error(f"{path}: {st.st_size} bytes, above the limit of {limit}{named}")
    return st.st_size
