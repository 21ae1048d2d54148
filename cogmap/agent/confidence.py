"""Is the agent sure where it is? (Appendix A.1.2, made independent of the number of states.)

The published test z-scores the posterior vector, which is bounded by ``sqrt(n - 1)`` and so
can never reach the threshold 4 with fewer than 17 states. Here two scores in nats are used,
neither of which depends on how many states exist:

* ``dominance``: log-odds of the most likely state against the runner-up;
* ``conflict``: how much better the current observation would be explained by the state that
  explains it best anywhere than by the best state around where the agent believes it is,
  ``ln max_s A[o, s] - ln max_s w(s) A[o, s]``, with ``w`` a kernel of one influence radius
  around the believed pose (1 at the nearest state; so a view that also belongs to a
  neighbouring node, perceptual aliasing, is not a conflict). It is large when a familiar
  observation turns up far from where the agent believes it is (kidnapping, large drift), and
  near zero for new observations or expected ones.

Conflict is a log-likelihood ratio ("the observation comes from somewhere else" against "it
comes from where I believe I am"), so the agent declares itself *lost* with a CUSUM test on it:
``S_t = max(0, S_t-1 + conflict_t - slack)`` fires when ``S_t >= threshold``. A single odd
view (aliasing, a changed scene) does not fire it; a run of them (kidnapping, severe drift)
does. The agent is *confident* when dominance >= threshold and it is not lost.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

TINY = 1e-300


class Confidence(NamedTuple):
    dominance: float  # nats by which the most likely state beats the runner-up
    conflict: float  # nats by which the observation is better explained elsewhere
    lost_evidence: float  # CUSUM of conflict after this step
    confident: bool

    def lost(self, threshold: float) -> bool:
        return self.lost_evidence >= threshold


def dominance(q: np.ndarray) -> float:
    q = np.asarray(q, dtype=float)
    if q.size < 2:
        return np.inf
    i = int(np.argmax(q))  # two passes of max: np.partition is slow on long runs of equal values
    second = max(q[:i].max(initial=0.0), q[i + 1:].max(initial=0.0))
    return float(np.log(max(q[i], TINY)) - np.log(max(second, TINY)))


def conflict(A_row: np.ndarray, nearby: np.ndarray) -> float:
    """``A_row[s] = A[o, s]`` for the observed outcome; ``nearby[s]`` in [0, 1] weights how
    plausible state ``s`` is given the believed pose."""
    A_row = np.asarray(A_row, dtype=float)
    local = float(np.max(A_row * np.asarray(nearby, dtype=float)))
    return float(np.log(max(A_row.max(), TINY)) - np.log(max(local, TINY)))


def cusum(previous: float, conflict_value: float, slack: float = 1.0) -> float:
    """One step of the CUSUM statistic on conflict (nats)."""
    return max(0.0, previous + conflict_value - slack)


def assess(q_post: np.ndarray, nearby: np.ndarray, A_row: np.ndarray | None, threshold: float,
           evidence: float = 0.0, slack: float = 1.0) -> Confidence:
    """Scores for one step; ``nearby`` weights the states the believed pose allows (see
    :func:`conflict`), ``evidence`` is the CUSUM statistic before this step."""
    dom = dominance(q_post)
    con = 0.0 if A_row is None else conflict(A_row, nearby)
    lost = cusum(evidence, con, slack)
    return Confidence(dom, con, lost, dom >= threshold and lost < threshold)
