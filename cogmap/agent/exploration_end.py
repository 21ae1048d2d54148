"""The agent's own end of exploration: when AIMAPP declares the map finished, from nothing but
its own map and sensed grid."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .aimapp import AIMAPPAgent


class Done:
    """The agent's own end of exploration (no ground truth involved). Decisions taken while a sensor
    stream is silent do not count: the map cannot grow without the LiDAR, nor can a view be tied to a
    new state without the camera.

    With ``rule="liveness"`` (default) the exploration ends when

    * for ``SEEN_ALL`` decisions its sensed map shows no state whose view would reveal unseen area
      (:data:`NOTHING_LEFT`), or
    * for ``patience`` decisions the map has not grown and no state has been visited for the first
      time, while no informative state is pursued (either none is left or no believed-possible
      path reaches one), or
    * for ``loop_factor * patience`` decisions the map has not grown although an informative state
      is pursued (a loop that the objective did not break).

    States that promise unseen area but that no believed path reaches do not count as "nothing
    left": they give the paper's objective (information gain on transitions) ``patience`` decisions
    to find a way. ``rule="seen-all"`` is the earlier rule (any decision without a reachable
    informative state counts toward ``SEEN_ALL``, and ``patience`` quiet decisions end it even while
    a target is pursued), kept to measure the change.

    Parameters
    ----------
    agent : AIMAPPAgent
        The exploring agent (read, never changed).
    patience : int
        Quiet decisions before the end (0: never end early).
    rule : str, optional
        ``"liveness"`` (default) or ``"seen-all"``.
    loop_factor : int, optional
        While a target is pursued the patience is ``loop_factor * patience``.
    """

    #: consecutive exploring decisions in which the agent's own sensed map shows nothing left to see
    #: (no state whose view would reveal unseen area) before it declares itself done, as a frontier
    #: explorer does when no frontier is left
    SEEN_ALL = 3
    RULES = ("liveness", "seen-all")
    #: end reasons (``reason``); ``BUDGET`` when the run ran out of decisions before the agent ended it
    NOTHING_LEFT = "nothing reachable left unseen"
    BUDGET = "budget"

    def __init__(self, agent: AIMAPPAgent, patience: int, rule: str = "liveness", loop_factor: int = 3):
        if rule not in self.RULES:
            raise ValueError(f"unknown end rule {rule!r}; choose from {list(self.RULES)}")
        self.agent, self.patience, self.quiet, self.seen = agent, patience, 0, (0, 0)
        self.seen_all = 0
        self.rule, self.loop_factor, self.pursuing = rule, loop_factor, False

    def __call__(self, decision) -> bool:
        a = self.agent
        seen = (a.num_states, int(a.visited().sum())) if a.model is not None else (0, 0)
        if decision.missing:
            self.seen = seen
            return False
        self.quiet = self.quiet + 1 if seen == self.seen else 0
        self.seen = seen
        sensing = decision.mode == "explore" and a.cfg.view_weighting and a.memory.views.grid is not None
        nothing_left = sensing and a.memory.views.pursuit.target < 0
        if getattr(self, "rule", "seen-all") == "liveness":
            nothing_left = nothing_left and a.memory.views.pursuit.unreached == 0
        self.pursuing = bool(sensing and a.memory.views.pursuit.target >= 0)
        self.seen_all = self.seen_all + 1 if nothing_left else 0
        return self.finished

    @property
    def _quiet_limit(self) -> int:
        if getattr(self, "rule", "seen-all") == "liveness" and getattr(self, "pursuing", False):
            return self.loop_factor * self.patience
        return self.patience

    @property
    def finished(self) -> bool:
        """The agent has declared its exploration over."""
        return self.patience > 0 and (self.quiet >= self._quiet_limit or self.seen_all >= self.SEEN_ALL)

    @property
    def reason(self) -> str:
        """Why the exploration ended (or would end now): :data:`NOTHING_LEFT`, ``"no map growth for
        N decisions"`` (``"... while pursuing a target (loop)"``) or :data:`BUDGET`."""
        if self.patience > 0 and self.seen_all >= self.SEEN_ALL:
            return self.NOTHING_LEFT
        if self.patience > 0 and self.quiet >= self._quiet_limit:
            loop = " while pursuing a target (loop)" if self._quiet_limit > self.patience else ""
            return f"no map growth for {self._quiet_limit} decisions{loop}"
        return self.BUDGET

    def summary(self) -> dict:
        """The end of exploration for ``metrics.json`` and the study rows: ``ended_by_agent``,
        ``end_reason`` and ``unvisited_reachable`` (states the agent predicts and believes reachable
        but never visited, :func:`cogmap.agent.liveness.unvisited_reachable`).

        Returns
        -------
        dict
            ``{"ended_by_agent": bool, "end_reason": str, "unvisited_reachable": int}``.
        """
        from cogmap.agent.liveness import unvisited_reachable

        return {"ended_by_agent": self.finished, "end_reason": self.reason,
                "unvisited_reachable": unvisited_reachable(self.agent)}
