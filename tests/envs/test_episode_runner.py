"""The one episode runner: the order of its calls, its stopping reasons, and the three systems'
episodes and policies conforming to its contracts."""

import pytest

from cogmap.envs.episode import run
from cogmap.genmodel.contracts import Episode, EpisodePolicy


class Counter(Episode):
    """Counts to ``until`` (then stops before the next decision); logs every call."""

    def __init__(self, until=None, end_on=None):
        self.sensors, self.until, self.end_on, self.log, self.n = "sim", until, end_on, [], 0

    def stop(self):
        self.log.append("stop")
        return "reached" if self.until is not None and self.n >= self.until else None

    def decided(self, action, ms):
        self.log.append(("decided", action))
        assert ms >= 0.0
        return "decided" if self.end_on == ("decided", action) else None

    def act(self, action):
        self.log.append(("act", action))
        self.n += 1
        return self.n

    def acted(self, action, outcome):
        self.log.append(("acted", outcome))
        return "acted" if self.end_on == ("acted", outcome) else None

    def end(self):
        self.log.append("end")


class Echo(EpisodePolicy):
    """Senses the last outcome and returns it plus 10."""

    label = "echo"

    def __init__(self):
        self.seen = []

    def sense(self, sim, outcome):
        assert sim == "sim"
        self.seen.append(outcome)
        return outcome

    def step(self, sensed):
        return (sensed or 0) + 10


def test_the_runner_senses_decides_records_and_acts_in_order():
    episode, policy = Counter(), Echo()
    assert run(episode, policy, 2, outcome=None) == "steps"
    assert policy.seen == [None, 1]
    assert episode.log == ["stop", ("decided", 10), ("act", 10), ("acted", 1),
                           "stop", ("decided", 11), ("act", 11), ("acted", 2), "end"]


@pytest.mark.parametrize(("end_on", "reason", "acts"), [(("decided", 11), "decided", 1), (("acted", 1), "acted", 1)])
def test_a_reason_from_the_episode_ends_the_run(end_on, reason, acts):
    episode = Counter(end_on=end_on)
    assert run(episode, Echo(), 5) == reason
    assert sum(1 for e in episode.log if isinstance(e, tuple) and e[0] == "act") == acts
    assert episode.log[-1] == "end"


def test_without_a_budget_only_the_episode_stops_the_run():
    episode = Counter(until=7)
    assert run(episode, Echo(), None) == "reached"
    assert episode.n == 7


def test_zero_steps_runs_nothing_and_negative_steps_are_refused():
    episode = Counter()
    assert run(episode, Echo(), 0) == "steps"
    assert episode.log == ["end"]
    with pytest.raises(ValueError, match="steps must be >= 0"):
        run(Counter(), Echo(), -1)


def test_the_defaults_of_the_episode_contract():
    class Bare(Episode):
        sensors = None

    bare = Bare()
    assert bare.stop() is None and bare.decided(1, 0.0) is None and bare.acted(1, 2) is None
    assert bare.status() == {}
    with pytest.raises(NotImplementedError):
        bare.act(1)


def _arity(func) -> int:
    import inspect

    return len(inspect.signature(func).parameters)


def test_every_system_episode_and_policy_conforms():
    from cogmap.envs.drone_episode import DroneEpisode, DronePilot
    from cogmap.envs.maze_episode import MazeEpisode, MazePilot
    from cogmap.envs.maze_traversal import MazeRun, Operator
    from cogmap.harness import RoomEpisode

    methods = ("stop", "decided", "act", "acted", "status", "end")
    for cls in (RoomEpisode, DroneEpisode, MazeEpisode, MazeRun):
        assert Episode in cls.__mro__ and "act" in vars(cls), cls
        assert "sensors" in cls.__init__.__code__.co_names, cls
        for name in methods:
            assert _arity(getattr(cls, name)) == _arity(getattr(Episode, name)), (cls, name)
    for cls in (DronePilot, MazePilot, Operator):
        assert EpisodePolicy in cls.__mro__ and isinstance(cls.label, str), cls
        for name in ("sense", "step"):
            assert name in vars(cls) and _arity(getattr(cls, name)) == _arity(getattr(EpisodePolicy, name)), (cls, name)
