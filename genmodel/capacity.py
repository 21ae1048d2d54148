"""Arrays kept at a reserved capacity grow by zero-padding along one axis (doubling keeps the
number of reallocations after ``n`` growth steps near ``log2(n)``)."""

from __future__ import annotations

import numpy as np


def pad_axis(x: np.ndarray, axis: int, size: int) -> np.ndarray:
    """Zero-pad ``x`` along ``axis`` up to ``size``."""
    shape = list(x.shape)
    shape[axis] = size
    out = np.zeros(shape, dtype=x.dtype)
    idx = [slice(None)] * x.ndim
    idx[axis] = slice(0, x.shape[axis])
    out[tuple(idx)] = x
    return out
