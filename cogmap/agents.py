"""Agents by name, each one pair of functions (the :class:`cogmap.genmodel.contracts.Agent` contract)::

    state = agent.init(model, config, key)
    state, info = agent.step(state, observation)      # info carries the action

============  =====================================================  ==========================
name          state / observation                                    info
============  =====================================================  ==========================
``loop``      :class:`cogmap.loop.LoopState` / one entry per         :class:`cogmap.loop.StepInfo`
              modality (any compiled ``Model``; pure)
``aimapp``    the :class:`~cogmap.agent.aimapp.AIMAPPAgent` /         ``aimapp.Decision``
              :class:`~cogmap.agent.aimapp.Sensed` (``model`` None:
              grown from the first reading)
``drone``     the :class:`~cogmap.drone.agent.DroneAgent` /           ``drone_policies.Decision``
              :class:`DroneObservation`
============  =====================================================  ==========================

``config`` is the agent's own settings (``loop.init``'s keywords as a mapping or a
``LoopConfig``; ``AgentConfig``; ``DroneAgentConfig``), ``None`` for the defaults; ``key`` seeds
its randomness. AIMAPP and the drone keep their state in one mutable object (the state returned
is the object itself); the loop's state is an immutable tuple. :func:`register_agent` adds yours
(checked against the contract).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

from cogmap.genmodel.contracts import Agent
from cogmap.genmodel.registry import Registry


class AgentEntry(NamedTuple):
    """A registered agent.

    Attributes
    ----------
    name : str
        Its registered name.
    init : callable
        ``init(model, config, key) -> state``.
    step : callable
        ``step(state, observation) -> (state, info)``.
    """

    name: str
    init: Callable[[Any, Any, int], Any]
    step: Callable[[Any, Any], tuple]


class DroneObservation(NamedTuple):
    """What the drone agent gets at a decision.

    Attributes
    ----------
    scan : numpy.ndarray
        ``(N, 3)`` LiDAR points, world frame, metres.
    position : numpy.ndarray
        ``(3,)`` position, metres.
    target : numpy.ndarray
        ``(3,)`` target position, metres.
    contact : numpy.ndarray or None
        ``(3,)`` point touched in the last flight, if any.
    """

    scan: Any
    position: Any
    target: Any
    contact: Any = None


_AGENTS = Registry("agent", "register_agent", protocol=Agent)


def register_agent(name: str, *, init, step, overwrite: bool = False) -> AgentEntry:
    """Register an agent under ``name``.

    Parameters
    ----------
    name : str
        Non-empty name.
    init : callable
        ``init(model, config, key) -> state``.
    step : callable
        ``step(state, observation) -> (state, info)``.
    overwrite : bool, optional
        Replace an agent registered under ``name`` (built-in agents cannot be replaced).

    Returns
    -------
    AgentEntry

    Raises
    ------
    ValueError
        Empty name, a built-in name, or a taken name without ``overwrite``.
    TypeError
        ``init`` or ``step`` not callable as the contract says.
    """
    return _AGENTS.add(name, AgentEntry(name, init, step), overwrite)


#: the agent registered under a name (``KeyError`` listing the agents for an unknown one)
get_agent = _AGENTS.get
#: names of the registered agents
agents = _AGENTS.names
#: remove an agent added with :func:`register_agent`
unregister_agent = _AGENTS.remove


# -- the built-in agents ------------------------------------------------------------------------------
def _loop_init(model, config, key):
    from cogmap import loop

    if config is not None and not (hasattr(config, "_asdict") or isinstance(config, Mapping)):
        raise TypeError("loop agent: config must be a mapping of loop.init keywords or a LoopConfig")
    options = {} if config is None else dict(config._asdict() if hasattr(config, "_asdict") else config)
    options.pop("seed", None)
    extra = options.pop("scheme_options", None) or {}
    return loop.init(model, seed=int(key), **options, **extra)


def _loop_step(state, observation):
    from cogmap import loop

    return loop.step(state, observation)


def _aimapp_init(model, config, key):
    from cogmap.agent.aimapp import AIMAPPAgent

    return AIMAPPAgent(config, seed=int(key), model=model)


def _aimapp_step(agent, sensed):
    return agent, agent.step(sensed)


def _drone_init(model, config, key):
    from cogmap.drone.agent import DroneAgent

    if model is not None:
        raise ValueError("drone agent: it builds its own kernel beliefs; pass model=None")
    return DroneAgent(config, seed=int(key))


def _drone_step(agent, observation: DroneObservation):
    if observation.contact is not None:  # touched in the last flight, before this decision's scan
        agent.observe_contact(observation.contact)
    agent.observe(observation.scan, observation.position)
    return agent, agent.decide(observation.position, observation.target)


for _name, _init, _step in (("loop", _loop_init, _loop_step), ("aimapp", _aimapp_init, _aimapp_step),
                            ("drone", _drone_init, _drone_step)):
    register_agent(_name, init=_init, step=_step)
_AGENTS.seal()
