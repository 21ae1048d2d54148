"""The infer and learn stages of one AIMAPP step (sections 3.2-3.5), as functions of the agent's
records (:mod:`cogmap.agent.localisation`): each takes the model, the config and the records it
reads, returns the new records, and updates only the model's counts and states and the
containers of :class:`~cogmap.agent.localisation.Memory` in place."""

from __future__ import annotations

import numpy as np

from cogmap import inference
from cogmap.genmodel import Model
from cogmap.inference.learning import Event, learn_observation, learn_transition

from .confidence import Confidence, assess, cusum
from .config import AgentConfig
from .correction import Anchor
from .localisation import Belief, Counts, Memory, found_frame, scan_agrees, shifted
from .map_growth import expand, predicted, recognised, reverse, state_poses, visited_prior
from .sensing import Sensed


def infer(model: Model, cfg: AgentConfig, belief: Belief, last, obs: int | None,
          pose: np.ndarray) -> tuple[np.ndarray, Confidence]:
    """Posterior over states and the confidence test (section 3.3, A.1.2).

    Parameters
    ----------
    model : Model
        The map (a blocked last move is learnt first, see :func:`~cogmap.agent.map_growth.predicted`).
    cfg : AgentConfig
        ``scheme`` names the inference scheme (the paper's exact filter by default).
    belief : Belief
        The last posterior, the lost test and the outcome of the last move.
    last : Decision or None
        The last decision.
    obs : int or None
        Observation id; None while the camera is silent (the pose evidence alone then localises).
    pose : numpy.ndarray
        ``(2,)`` believed position, metres, belief frame.

    Returns
    -------
    q : numpy.ndarray
        ``(num_states,)`` posterior.
    confidence : Confidence
        The confidence test of this step.
    """
    scheme = inference.get(cfg.scheme)
    if belief.lost:  # re-localising: odometry is not trusted, only what is seen
        prior = visited_prior(model, cfg)
        q = [prior] if obs is None else scheme(model, [prior], [{"view": obs}])[0]
    else:  # B_s prediction combined with A_o and A_p evidence
        q, _ = scheme(model, [predicted(model, cfg, belief.q, last, belief.outcome)], [{"view": obs, "pose": pose}])
    q = q[0]
    d2 = np.sum((state_poses(model) - pose) ** 2, axis=1)
    near = np.exp(-(d2 - d2.min()) / (2 * cfg.influence_radius**2))  # where the pose says we are
    row = None if obs is None else model.A_row(0, obs)
    return q, assess(q, near, row, cfg.z_threshold, belief.lost_evidence, cfg.lost_slack)


def update(model: Model, cfg: AgentConfig, belief: Belief, counts: Counts, memory: Memory, last, q: np.ndarray,
           conf: Confidence, obs: int | None, sensed: Sensed, pose: np.ndarray,
           score: float) -> tuple[Belief, Counts, int]:
    """Lost/found bookkeeping and learning after inference (sections 3.3-3.5).

    Parameters
    ----------
    model : Model
        The map; learns A_o, B_s and grows when confident.
    cfg : AgentConfig
        The agent's parameters.
    belief, counts, memory : Belief, Counts, Memory
        The agent's records before this stage.
    last : Decision or None
        The last decision.
    q : numpy.ndarray
        The posterior of :func:`infer`.
    conf : Confidence
        Its confidence test.
    obs, sensed, pose, score
        The view's observation id, the reading in the belief frame, the believed position and the
        encoder's score, as :func:`learn` takes them.

    Returns
    -------
    belief : Belief
        With the posterior (live length), the lost test and a frame moved by a re-localisation.
    counts : Counts
        With the lost and found events.
    expanded : int
        States the map gained.
    """
    state = int(np.argmax(q))
    expanded = 0
    poses = state_poses(model)
    if not belief.lost and conf.conflict > cfg.lost_slack and scan_agrees(memory.anchors, poses, cfg, sensed.scan,
                                                                         pose):
        # the view points elsewhere but the LiDAR matches the place the belief is at: aliasing
        # (repeated racks, similar rooms), not a wrong position; it adds no evidence of being lost
        evidence = cusum(belief.lost_evidence, 0.0, cfg.lost_slack)
        conf = conf._replace(conflict=0.0, lost_evidence=evidence, confident=conf.dominance >= cfg.z_threshold)
    if belief.lost:
        # a familiar view singles out a place (and, with a LiDAR, the scan confirms it)
        if obs is not None and q[state] >= 0.5 and recognised(model, cfg, state, obs):
            frame = found_frame(belief.frame, memory.anchors.get(state), cfg, poses[state], sensed, pose)
            if frame is not None:
                belief = belief._replace(frame=frame, lost=False, lost_evidence=0.0)
                counts = counts._replace(relocalisations=counts.relocalisations + 1)
    elif conf.lost(cfg.z_threshold):
        belief = belief._replace(lost=True, lost_evidence=0.0)
        counts = counts._replace(lost_events=counts.lost_events + 1)
        q = visited_prior(model, cfg)
    else:
        belief = belief._replace(lost_evidence=conf.lost_evidence)
        if conf.confident:
            belief, expanded = learn(model, cfg, belief, memory, last, counts.steps, state, obs, sensed, pose, score)
        elif obs is not None:  # unsure between nearby states: learn A_o under the posterior (Eq. 8)
            learn_observation(model, 0, obs, [q], lr=cfg.obs_learning_rate)
    full = np.zeros(model.num_states[0])
    full[: q.size] = q
    return belief._replace(q=full), counts, expanded


def learn(model: Model, cfg: AgentConfig, belief: Belief, memory: Memory, last, step: int, state: int,
          obs: int | None, sensed: Sensed, pose: np.ndarray, score: float) -> tuple[Belief, int]:
    """Confident at ``state``: A_o ties the view to it (a first visit keeps an anchor; without a LiDAR a
    familiar, nearly identical view re-localises onto its pose), the move just driven is learnt
    possible in B_s (Table 7), and on arrival the obstacle signal adds predicted transitions and
    Eq. (7) expands the map.

    Parameters
    ----------
    model : Model
        The map.
    cfg : AgentConfig
        The agent's parameters.
    belief : Belief
        Its frame may move; the outcome of the last move is read.
    memory : Memory
        Anchors and driven moves, updated in place.
    last : Decision or None
        The last decision.
    step : int
        The step number (kept with a new anchor).
    state : int
        The state believed.
    obs : int or None
        Observation id.
    sensed : Sensed
        The reading in the belief frame.
    pose : numpy.ndarray
        ``(2,)`` believed position, metres.
    score : float
        The encoder's best similarity score.

    Returns
    -------
    belief : Belief
        With the frame moved by a view-only re-localisation.
    expanded : int
        States the map gained.
    """
    if obs is not None:
        onehot = np.zeros(model.num_states[0])
        onehot[state] = 1.0
        if sensed.scan is None and recognised(model, cfg, state, obs) and score >= cfg.relocalise_ssim:
            # no LiDAR to align: a familiar, nearly identical view re-localises onto the state's pose
            belief = belief._replace(frame=shifted(belief.frame, state_poses(model)[state] - pose))
        elif state not in memory.anchors and sensed.scan is not None and np.ndim(sensed.panorama) >= 2:
            memory.anchors[state] = Anchor(pose.copy(), np.asarray(sensed.panorama).copy(), sensed.scan.copy(), step)
        learn_observation(model, 0, obs, [onehot], lr=cfg.obs_learning_rate)
    arrived = last is None or state != last.state
    if last is not None and belief.outcome and state != last.state and last.action != cfg.stay:
        learn_transition(model, 0, last.state, last.action, state, Event.POSSIBLE,
                         reverse_control=reverse(cfg, last.action), rates=cfg.learning)
        memory.traversed.add((int(last.state), int(last.action), state))
        memory.traversed.add((state, int(reverse(cfg, last.action)), int(last.state)))
    if not arrived or sensed.obstacles is None:  # without the LiDAR, no free direction is known
        return belief, 0
    return belief, expand(model, cfg, memory.traversed, state, np.asarray(sensed.obstacles, dtype=bool),
                          sensed.scan, pose)
