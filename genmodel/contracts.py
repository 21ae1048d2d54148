"""The contracts of the toolkit in one place: what an inference scheme, a planner, an EFE term, a
factor representation (likelihood or transitions, dense or sparse), an observation encoder, a
room, a world, an agent and a study provide.

Each contract is a :class:`typing.Protocol`. The registries (``inference.register``,
``planning.register_planner``, ``planning.efe.register_term``, ``envs.register_layout``,
``cogmap.agent.register_encoder``, ``cogmap.agents.register_agent``,
``cogmap.study.register_study``) call :func:`check_conforms` on what they are given, so a
missing method or a signature that cannot take the contract's arguments is refused when it is
registered, with the contract named, not at the first step of a run.

The shapes follow the functional libraries of the field: an agent is a pair of functions
``init(model, config, key) -> state`` and ``step(state, observation) -> (state, info)`` over an
immutable state (BlackJAX's ``(init, step)``); a scheme and a planner are plain callables.
"""

from __future__ import annotations

import inspect
from collections.abc import Sequence
from typing import Any, Protocol, runtime_checkable


class InferenceScheme(Protocol):
    """``posterior, info = scheme(model, prior, observations, actions=None, **options)``: the
    state posterior at the last step (one array per factor, or the scheme's own belief type) and
    an :class:`~cogmap.inference.InferenceInfo`-like record with ``free_energy``."""

    def __call__(self, model, prior, observations, actions=None) -> tuple[Any, Any]: ...


class Planner(Protocol):
    """``plan = planner(model, qs, objective, settings)``: the next control from a belief, the
    per-step EFE ``objective`` and the loop's ``PlanSettings``; returns a ``planning.Plan``."""

    def __call__(self, model, qs, objective, settings) -> Any: ...


class EFETerm(Protocol):
    """``G_part = term(ctx)``: one additive part of the per-step expected free energy, ``(K,)``
    nats for the ``K`` candidates of the step context ``ctx`` (lower is preferred)."""

    def __call__(self, ctx) -> Any: ...


class LayoutFactory(Protocol):
    """``layout = factory(seed)``: a room (an ``envs.Layout``) for a seed."""

    def __call__(self, seed) -> Any: ...


class EncoderFactory(Protocol):
    """``encoder = factory(config)``: an observation :class:`Encoder` from an agent's config."""

    def __call__(self, config) -> Any: ...


@runtime_checkable
class Encoder(Protocol):
    """What the agent and its run directory use of an encoder, and nothing more.

    ``images`` are the stored observations in id order (a run directory saves them as image
    files; an encoder that keeps no images gives an empty sequence). ``last_scores`` are the
    similarities of the latest query to the stored observations it was compared with (empty
    when nothing was compared); the agent uses their maximum to judge how familiar a view is.

    Attributes
    ----------
    images : sequence of numpy.ndarray
        Stored observations in id order (e.g. ``(H, W, 3)`` uint8 RGB panoramas); may be empty.
    last_scores : numpy.ndarray
        ``(k,)`` float similarities of the latest query to the ``k`` stored observations it was
        compared with (higher is more similar).
    """

    images: Sequence[Any]
    last_scores: Any

    def __call__(self, image: Any) -> tuple[int, bool]:
        """Return (observation id, whether the id is new); a new id stores the image."""

    def match(self, image: Any) -> tuple[int, float]:
        """Best stored id and its similarity score, storing nothing.

        Parameters
        ----------
        image : numpy.ndarray
            The query image (as the encoder takes it, e.g. an ``(H, W, 3)`` RGB panorama).

        Returns
        -------
        id : int
            Best stored observation id; -1 when nothing is stored.
        score : float
            Its similarity score (0.0 when nothing is stored).
        """


class LikelihoodRepresentation(Protocol):
    """A factor's likelihood ``A`` (outcomes given states), dense or sparse: ``genmodel``'s
    ``DenseLikelihood`` and ``SparseLikelihood`` both conform, so every scheme and EFE term reads
    either through these members."""

    def to_dense(self) -> Any: ...

    def counts_dense(self) -> Any: ...

    def row(self, o) -> Any: ...

    def column(self, s) -> Any: ...

    def column_stats(self, states, novelty=True) -> Any: ...

    def most_likely(self) -> Any: ...

    def learn(self, obs, qs, lr=1.0) -> None: ...

    def add_state(self, axis, count) -> Any: ...

    def add_observation(self, count) -> Any: ...


class TransitionRepresentation(Protocol):
    """A factor's transitions ``B`` (next state given a state and a control), dense or sparse:
    ``DenseTransitions`` and ``SparseTransitions`` both conform."""

    num_controls: int

    def predict(self, q, u) -> Any: ...

    def column(self, s, u, n) -> Any: ...

    def to_dense(self, n=None) -> Any: ...

    def counts_dense(self, n=None) -> Any: ...

    def edges(self, threshold, n) -> Any: ...

    def add_state(self, s, prior_count) -> None: ...

    def learn(self, s, u, target, lr, n, floor, max_concentration) -> None: ...


class World(Protocol):
    """A Gymnasium environment: ``obs, info = reset(seed=...)``,
    ``obs, reward, terminated, truncated, info = step(action)``, with its spaces."""

    observation_space: Any
    action_space: Any

    def reset(self, *, seed=None, options=None) -> tuple[Any, dict]: ...

    def step(self, action) -> tuple[Any, float, bool, bool, dict]: ...


class Agent(Protocol):
    """An agent as two functions over an immutable state (the config is bound in ``init``):
    ``state = init(model, config, key)`` and ``state, info = step(state, observation)``, where
    ``info`` carries the ``action`` to apply."""

    def init(self, model, config, key) -> Any: ...

    def step(self, state, observation) -> tuple[Any, Any]: ...


class Study(Protocol):
    """A reproduction study, registered once by name: ``plan(scale, seeds, methods, envs) -> dict``
    (environments, methods, seeds, budgets), ``specs(plan) -> [spec]`` (one JSON-able spec per
    run, keyed by a digest), ``run(spec) -> dict`` (one run's result) and
    ``report(study_dir, plan, results) -> str`` (the markdown body; tables and figures written)."""

    name: str

    def plan(self, scale, seeds=None, methods=None, envs=None) -> dict: ...

    def specs(self, plan) -> list: ...

    def run(self, spec) -> dict: ...

    def report(self, study_dir, plan, results) -> str: ...


@runtime_checkable
class EpisodePolicy(Protocol):
    """What the episode runner (``cogmap.envs.episode.run``) needs of a policy (runtime-checkable).

    Attributes
    ----------
    label : str
        Progress-bar description.
    """

    label: str  # progress-bar description

    def sense(self, sim, moved: bool | None) -> Any:
        """What the policy senses this step (read from ``sim``, only the streams it may use).

        Parameters
        ----------
        sim : object
            The simulator (``Episode.sensors``).
        moved : object
            The outcome of the last action (in a room: whether the motion succeeded), None
            before the first.

        Returns
        -------
        object
            Whatever :meth:`step` expects.
        """

    def step(self, sensed) -> Any:
        """Decide from what was sensed.

        Parameters
        ----------
        sensed : object
            The value :meth:`sense` returned.

        Returns
        -------
        object
            The action the episode carries out (in a room a ``cogmap.harness.Command``).
        """


class Episode(Protocol):
    """One run of a policy in a simulator, as the runner (``cogmap.envs.episode.run``) drives it.

    Subclass it to inherit the defaults (no stopping rule, nothing recorded) and these docstrings;
    ``act`` is each episode's own.

    Attributes
    ----------
    sensors : object
        What the policy reads its sensors from (the simulator).
    """

    sensors: Any

    def stop(self) -> str | None:
        """Why the episode ends before the next decision.

        Returns
        -------
        str or None
            The reason, or None to go on (the default).
        """
        return None

    def decided(self, action, ms: float) -> str | None:
        """Record a decision before it is carried out.

        Parameters
        ----------
        action : object
            What the policy decided.
        ms : float
            Wall-clock time of the decision, milliseconds.

        Returns
        -------
        str or None
            A reason to end the episode without carrying it out, or None (the default).
        """
        return None

    def act(self, action) -> Any:
        """Carry out an action.

        Parameters
        ----------
        action : object
            What the policy decided.

        Returns
        -------
        object
            Its outcome, which the policy's next ``sense`` receives.
        """
        raise NotImplementedError

    def acted(self, action, outcome) -> str | None:
        """Record what an action did.

        Parameters
        ----------
        action : object
            The action carried out.
        outcome : object
            What :meth:`act` returned.

        Returns
        -------
        str or None
            A reason to end the episode, or None (the default).
        """
        return None

    def status(self) -> dict:
        """Fields for the progress bar.

        Returns
        -------
        dict
            Name -> printable value (none by default).
        """
        return {}

    def end(self) -> None:
        """Close the record after the last step (nothing by default)."""


def _members(protocol) -> dict[str, object]:
    """The protocol's own methods and data members (its bases' included), name -> declaration."""
    out: dict[str, object] = {}
    for klass in reversed(protocol.__mro__):
        if klass in (object, Protocol) or klass.__module__ == "typing":
            continue
        for name in getattr(klass, "__annotations__", {}):
            out[name] = None
        for name, value in vars(klass).items():
            if callable(value) and (not name.startswith("_") or name == "__call__"):
                out[name] = value
    return out


def _required(declared) -> tuple[int, tuple[str, ...]]:
    """How many positional arguments and which keyword-only ones a call of ``declared`` passes."""
    params = list(inspect.signature(declared).parameters.values())[1:]  # without self
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
                  and p.default is p.empty]
    keywords = tuple(p.name for p in params if p.kind is p.KEYWORD_ONLY)
    return len(positional), keywords


def _can_take(fn, n_positional: int, keywords: Sequence[str]) -> bool:
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # a builtin without a readable signature: accept it
        return True
    try:
        sig.bind(*([None] * n_positional), **dict.fromkeys(keywords))
    except TypeError:
        return False
    return True


def conformance_errors(obj, protocol) -> list[str]:
    """What ``obj`` lacks of ``protocol``: missing members, and methods whose signature cannot
    take the contract's arguments (its required positional ones and its keyword-only ones).

    Parameters
    ----------
    obj : object
        The candidate (a function for a callable contract, an object for the others).
    protocol : type
        One of the protocols of this module (or any ``typing.Protocol``).

    Returns
    -------
    list of str
        One line per problem; empty when ``obj`` conforms.
    """
    errors = []
    for name, declared in _members(protocol).items():
        target = obj if name == "__call__" else getattr(obj, name, None)
        if name != "__call__" and not hasattr(obj, name):
            errors.append(f"has no '{name}'")
        elif declared is None:  # a data member: being there is enough
            continue
        elif not callable(target):
            errors.append(f"is not callable (got {type(obj).__name__})" if name == "__call__"
                          else f"'{name}' is not callable")
        else:
            params = list(inspect.signature(declared).parameters.values())[1:]  # without self
            if any(p.kind is p.VAR_POSITIONAL for p in params):
                continue  # the contract fixes no arity for this member
            n, kws = _required(declared)
            if not _can_take(target, n, kws):
                shown = name if name != "__call__" else "it"
                errors.append(f"{shown} cannot be called as ({', '.join(p.name for p in params)})")
    return errors


def check_conforms(func: str, kind: str, name: str, obj, protocol) -> None:
    """Refuse registering ``obj`` under ``name`` when it does not conform to ``protocol``.

    Parameters
    ----------
    func : str
        The registering function's name, for the message (e.g. ``"register_planner"``).
    kind : str
        What is registered (``"planner"``), for the message.
    name : str
        The name asked for.
    obj : object
        What is registered.
    protocol : type
        The contract it must meet.

    Raises
    ------
    TypeError
        Naming the contract and every member ``obj`` lacks or cannot call as the contract does.
    """
    errors = conformance_errors(obj, protocol)
    if errors:
        raise TypeError(f"{func}('{name}'): the {kind} does not meet the {protocol.__name__} contract: "
                        + "; ".join(errors))
