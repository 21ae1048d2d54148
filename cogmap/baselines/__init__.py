"""Exploration baselines: frontier, random walk, oracle coverage."""
