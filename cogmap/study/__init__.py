"""Reproduction studies of the AIMAPP paper (Tables 2-5, 8; Figures 8 and 13): runs in parallel
(local processes or Ray), resumable, with the paper's numbers beside ours."""

from .runner import main, run_study

__all__ = ["main", "run_study"]
