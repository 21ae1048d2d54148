"""The one place a module is imported by name: the ``--plugin MODULE`` options of the command
line, in the CLI process and again in a run's time-limited child. Nothing read from a file reaches
here (checkpoints, run directories, models and buildings hold data only; names in them select
among entries already registered)."""

from __future__ import annotations

import importlib
import re

_MODULE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*")


def import_plugins(modules) -> None:
    """Import the ``--plugin`` modules given on the command line, so their registrations
    (schemes, planners, terms, rooms, encoders, agents, studies) take effect.

    Parameters
    ----------
    modules : sequence of str
        Dotted module names, as typed after ``--plugin``.

    Raises
    ------
    ValueError
        For a name that is not a dotted Python module name (a path, say).
    ImportError
        If a module cannot be imported.
    """
    for module in modules:
        if not isinstance(module, str) or not _MODULE.fullmatch(module):
            raise ValueError(f"--plugin {module!r}: expected a dotted module name such as mypackage.models")
        importlib.import_module(module)
