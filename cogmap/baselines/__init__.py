"""Exploration baselines driving the same ``NavSim`` (sensors, motion, metrics) as AIMAPP:
frontier exploration (explore_lite cost; goals at the nearest reachable frontier cell, or at frontier
centroids as explore_lite sends them), a random walk, and an oracle coverage tour on the
known map (the stand-in for the paper's human teleoperation)."""

from .frontier import FrontierConfig, FrontierExplorer, OdomMap
from .frontier_paper import FrontierPaperConfig, FrontierPaperExplorer
from .oracle import OracleConfig, OracleTour
from .random_walk import RandomWalk
from .runner import coverage_tracker, run_policy

__all__ = [
    "FrontierConfig", "FrontierExplorer", "FrontierPaperConfig", "FrontierPaperExplorer", "OdomMap",
    "OracleConfig", "OracleTour", "RandomWalk",
    "coverage_tracker", "run_policy",
]
