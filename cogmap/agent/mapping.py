"""Map expansion decided by the free-energy comparison of Eq. (7).

For a predicted pose ``p*`` (one move from the believed state in a free direction) the agent
asks whether its pose likelihood A_p is better with a new state at ``p*`` (the expanded model)
or with ``p*`` explained by the nearest existing state (the current model). The predicted pose
observation is assigned softly to two pose outcomes, "the nearest stored pose" and "a new
pose", with Gaussian weights of width ``sigma`` for the distance to the nearest node and for
the influence radius. The current model's Dirichlet prior puts its concentration on the
nearest pose, the expanded model's on the new pose; Bayesian model reduction (Eq. 7) gives
the free-energy difference and the map grows exactly when it is negative, which happens when
``p*`` lies beyond the influence radius of every existing node.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from cogmap.inference.reduction import log_beta

CONCENTRATION = 4.0  # prior counts of the believed pose outcome in either model
BASE = 0.25  # prior counts of the other outcome


class Expansion(NamedTuple):
    free_energy: float  # F(expanded) - F(current); expand when negative
    nearest: int  # nearest existing state (-1 when the map is empty)
    distance: float

    @property
    def expand(self) -> bool:
        return self.free_energy < 0


def expansion_free_energy(pred_pose, poses: np.ndarray, influence_radius: float, sigma: float) -> Expansion:
    """Eq. (7) on the pose likelihood for one predicted pose against stored ``poses``."""
    poses = np.asarray(poses, dtype=float).reshape(-1, 2)
    if poses.shape[0] == 0:
        return Expansion(-np.inf, -1, np.inf)
    d = np.hypot(*(poses - np.asarray(pred_pose, dtype=float)).T)
    k = int(np.argmin(d))
    return Expansion(float(expansion_free_energies(d[k : k + 1], influence_radius, sigma)[0]), k, float(d[k]))


def expansion_free_energies(nearest_distance: np.ndarray, influence_radius: float, sigma: float) -> np.ndarray:
    """Vectorised Eq. (7): free-energy change of expanding, for candidates whose nearest stored
    pose is ``nearest_distance`` away (one BMR per candidate, columns of a 2-outcome Dirichlet)."""
    d = np.asarray(nearest_distance, dtype=float)
    w_near = np.exp(-(d**2) / (2 * sigma**2))
    w_new = np.exp(-(influence_radius**2) / (2 * sigma**2))
    counts = np.stack([w_near, np.full_like(w_near, w_new)]) / (w_near + w_new)
    current = np.array([[CONCENTRATION], [BASE]])
    expanded = np.array([[BASE], [CONCENTRATION]])
    q = current + counts
    s = q + expanded - current
    return log_beta(q) + log_beta(np.broadcast_to(expanded, q.shape)) - log_beta(
        np.broadcast_to(current, q.shape)) - log_beta(s)


def direction(heading_index: int, num_headings: int) -> np.ndarray:
    h = 2 * np.pi * heading_index / num_headings
    return np.array([np.cos(h), np.sin(h)])


def reverse_heading(a: int, num_headings: int) -> int:
    return (a + num_headings // 2) % num_headings
