"""How many BLAS threads the planning kernels use.

Planning multiplies many small arrays (a few candidates by a few dozen states); handing each
product to a BLAS thread pool costs more than the product. On this project's 2-core reference
machine, dense policy evaluation ran 3-10x slower with the default threads than with one. So
the planning calls (:func:`~.decide.decide`, :func:`~.policies.evaluate_policies`,
:func:`~.policies.infer_policies`) run with BLAS limited to ``threads()`` threads, 1 unless
set otherwise by :func:`set_threads` or the environment variable ``COGMAP_PLANNING_THREADS``
(``0`` leaves BLAS alone, e.g. for very large dense models). The limit is restored when the
call returns; code outside the planning calls is not affected.
"""

from __future__ import annotations

import contextlib
import os

_threads: int | None = None  # None: read the environment
_controller = None


def threads() -> int:
    """BLAS threads inside planning calls (0: not limited)."""
    if _threads is not None:
        return _threads
    raw = os.environ.get("COGMAP_PLANNING_THREADS", "1")
    try:
        value = int(raw)
    except ValueError:
        raise ValueError(f"COGMAP_PLANNING_THREADS must be a non-negative integer, got {raw!r}") from None
    if value < 0:
        raise ValueError(f"COGMAP_PLANNING_THREADS must be a non-negative integer, got {raw!r}")
    return value


def set_threads(n: int | None) -> None:
    """Use ``n`` BLAS threads in planning calls (0: leave BLAS alone; None: back to the environment)."""
    global _threads
    if n is not None and (not isinstance(n, int) or n < 0):
        raise ValueError(f"planning threads must be a non-negative integer or None, got {n!r}")
    _threads = n


class _Limit:
    """Sets the BLAS pools above ``n`` threads to ``n`` on entry and restores them on exit (a
    direct, cheaper form of ``threadpoolctl``'s ``limit``: planning enters it once per decision)."""

    def __init__(self, libraries, n: int):
        self.libraries, self.n, self.saved = libraries, n, []

    def __enter__(self):
        self.saved = [(lib, k) for lib in self.libraries if (k := lib.get_num_threads()) is not None and k > self.n]
        for lib, _ in self.saved:
            lib.set_num_threads(self.n)
        return self

    def __exit__(self, *exc):
        for lib, k in self.saved:
            lib.set_num_threads(k)
        return False


def limited():
    """Context manager applying :func:`threads` to the BLAS libraries loaded in this process."""
    global _controller
    n = threads()
    if n == 0:
        return contextlib.nullcontext()
    if _controller is None:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController().select(user_api="blas").lib_controllers
    return _Limit(_controller, n)
