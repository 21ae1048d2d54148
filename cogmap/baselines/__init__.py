"""Exploration baselines driving the same ``NavSim`` (sensors, motion, metrics) as AIMAPP:
frontier exploration (explore_lite cost; goals at the nearest reachable frontier cell, or at frontier
centroids as explore_lite sends them), a random walk, an oracle coverage tour on the
known map (the stand-in for the paper's human teleoperation), and the oracle's viewpoint rule on
the robot's own map (next-best view: how much of the oracle's efficiency is knowing the map)."""

from .frontier import FrontierConfig, FrontierExplorer, OdomMap
from .frontier_paper import FrontierPaperConfig, FrontierPaperExplorer
from .nbv import NBVConfig, NextBestView
from .oracle import OracleConfig, OracleTour
from .random_walk import RandomWalk
from .runner import coverage_tracker, run_policy

__all__ = [
    "FrontierConfig", "FrontierExplorer", "FrontierPaperConfig", "FrontierPaperExplorer", "NBVConfig",
    "NextBestView", "OdomMap",
    "OracleConfig", "OracleTour", "RandomWalk",
    "coverage_tracker", "run_policy",
]
