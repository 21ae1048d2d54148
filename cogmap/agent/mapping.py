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


def centre_in_passage(pred_pose, heading: np.ndarray, points: np.ndarray, max_width: float,
                      length: float = 1.0, band: float = 0.15, max_shift: float | None = None) -> np.ndarray:
    """A predicted pose moved across the move to the centre line of the corridor it lies in.

    Looking across the move (``heading``, a unit vector), the LiDAR returns give the clearance on
    either side in three slices (``band`` metres thick) at ``-length / 2``, 0 and ``length / 2``
    along the move from ``pred_pose``. When all three slices are walled on both sides and
    narrower than ``max_width`` (a corridor or an aisle, not a doorway in a thin wall or a gap
    beside a table), the pose moves to the mean midpoint, so places along a corridor form one row
    on its centre line instead of rows beside its walls (which look alike and make the map
    zig-zag). Elsewhere it is returned unchanged.

    Parameters
    ----------
    pred_pose : array_like
        ``(2,)`` predicted position, metres.
    heading : array_like
        ``(2,)`` unit direction of the move that predicts it.
    points : numpy.ndarray
        ``(n, 2)`` LiDAR returns, metres, same frame.
    max_width : float
        Metres; wider passages leave the pose where it is. 0 disables.
    length : float, optional
        Metres along the move over which both walls must run.
    band : float, optional
        Half-thickness (metres) of each slice.
    max_shift : float or None, optional
        Largest shift (metres); None: no limit.

    Returns
    -------
    numpy.ndarray
        ``(2,)`` float, the centred (or unchanged) pose.
    """
    p = np.asarray(pred_pose, dtype=float)
    if max_width <= 0 or points is None or len(points) == 0:
        return p.copy()
    u = np.asarray(heading, dtype=float)
    n = np.array([-u[1], u[0]])
    rel = np.asarray(points, dtype=float).reshape(-1, 2) - p
    along, across = rel @ u, rel @ n
    mids = []
    for at in (-length / 2, 0.0, length / 2):
        side = across[np.abs(along - at) <= band]
        left, right = side[side > 0], -side[side < 0]
        if left.size == 0 or right.size == 0 or left.min() + right.min() >= max_width:
            return p.copy()
        mids.append((left.min() - right.min()) / 2)
    shift = float(np.mean(mids))
    if max_shift is not None:
        shift = float(np.clip(shift, -max_shift, max_shift))
    return p + shift * n
