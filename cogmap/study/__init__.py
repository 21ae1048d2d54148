"""Reproduction studies of the AIMAPP paper (Tables 2-5, 8; Figures 8 and 13): runs in parallel
(local processes or Ray), resumable, with the paper's numbers beside ours."""

from .registry import get_study, register_study, run_specs, studies, study_plan, unregister_study
from .runner import run_study

__all__ = ["get_study", "register_study", "run_specs", "run_study", "studies", "study_plan",
           "unregister_study"]
