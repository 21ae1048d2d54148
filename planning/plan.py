"""What a planner returns (:class:`Plan`), apart from the planner registry so every planner module can
build one without importing the registry."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Plan(NamedTuple):
    """A planner's answer.

    Attributes
    ----------
    action : tuple of int
        One control per factor, to apply now.
    G : numpy.ndarray
        Expected free energy (nats) of what was compared: per policy, per root action, ...
    q_pi : numpy.ndarray or None
        Posterior over those policies, if the planner has one.
    policies : numpy.ndarray or None
        ``(P, T, F)`` policies of ``q_pi`` and ``G`` (enumeration).
    info : object or None
        The planner's own record of the decision (the drone's ``PlanResult``).
    """

    action: tuple  # one integer control per factor, to apply now
    G: np.ndarray  # expected free energy of what was compared (per policy, per root action, ...)
    q_pi: np.ndarray | None = None  # posterior over those policies, if the planner has one
    policies: np.ndarray | None = None  # (P, T, F) policies of q_pi and G (enumeration)
    info: object = None  # the planner's own record of the decision (the drone's PlanResult)


__all__ = ["Plan"]
