"""How AIMAPP's map grows and where its moves lead (sections 3.4-3.5): neighbours by heading, the
collision test of a move, predicted (im)possible transitions and Eq. (7) expansion, the waypoint
of an action, the B_s prediction of the last move and the move while lost. Functions of the model
(whose counts and states they update), the agent's config and the moves it has driven
(``traversed``: ``(state, heading, state)`` triples, both ways)."""

from __future__ import annotations

import numpy as np

from cogmap.genmodel import Model
from cogmap.genmodel.numerics import wrap_angle
from cogmap.inference.learning import Event, learn_transition

from .config import AgentConfig
from .mapping import centre_in_passage, direction, expansion_free_energies, reverse_heading
from .sensing import blocked


def state_poses(model: Model) -> np.ndarray:
    """``(num_states, 2)`` stored positions of the live states, metres, belief frame."""
    return model.pose.poses[: model.num_states[0]]


def recognised(model: Model, cfg: AgentConfig, state: int, obs: int) -> bool:
    """``obs`` has been tied to ``state`` before and to no other state as strongly."""
    counts = model.pA_row(0, obs)
    return counts[state] > 2 * cfg.prior_count and counts.argmax() == state


def visited_prior(model: Model, cfg: AgentConfig) -> np.ndarray:
    """Uniform over the states whose observation model has been taught (uniform over all without)."""
    visited = model.A[0].taught(2 * cfg.prior_count)
    n = model.num_states[0]
    return visited / visited.sum() if visited.any() else np.full(n, 1.0 / n)

def neighbours_by_heading(model: Model, cfg: AgentConfig, state: int) -> np.ndarray:
    """For each heading, the nearest state lying in that direction (bearing within half a
    heading sector, at most 1.5 influence radii away), or -1."""
    poses = state_poses(model)
    idx, dist = model.pose_index().near(poses[state], 1.5 * cfg.influence_radius)
    keep = dist > 1e-9
    idx, dist = idx[keep], dist[keep]
    rel = poses[idx] - poses[state]
    bearing = np.arctan2(rel[:, 1], rel[:, 0])
    sector = np.pi / cfg.num_headings
    out = np.full(cfg.num_headings, -1)
    for h in range(cfg.num_headings):
        off = np.abs(wrap_angle(bearing - 2 * np.pi * h / cfg.num_headings))
        ok = off <= sector + 1e-9
        if ok.any():
            out[h] = int(idx[ok][np.argmin(dist[ok])])  # ties: the lowest index, as before
    return out


def path_blocked(model: Model, cfg: AgentConfig, traversed: set, heading: int, target: int, obstacles: np.ndarray,
                 scan: np.ndarray | None, pose: np.ndarray, state: int | None = None) -> bool:
    """Would the move toward ``target`` collide? With a scan, its corridor is checked along
    the actual bearing and length from ``pose`` to the target (what the robot will drive);
    otherwise the heading's flag is used. The corridor is the robot's width plus
    ``obstacle_margin``, except for a move from ``state`` the robot has driven before (either
    way, ``traversed``): a return within the margin alone does not block a way known
    passable (else a doorway passed near its jamb would cut the map in two), while anything
    within the robot's own width (e.g. a box moved onto the way) still does."""
    if scan is None:
        return bool(obstacles[heading])
    move = state_poses(model)[target] - pose
    if not blocked(scan, move, cfg.robot_radius + cfg.obstacle_margin)[0]:
        return False
    if state is not None and (int(state), int(heading), int(target)) in traversed:
        return bool(blocked(scan, move, cfg.robot_radius)[0])
    return True


def move_obstacles(model: Model, cfg: AgentConfig, traversed: set, state: int, obstacles: np.ndarray | None,
                   scan: np.ndarray | None, pose: np.ndarray) -> np.ndarray:
    """Collision flag per heading for the move the agent would make: toward the believed
    successor when there is one, else straight along the heading. Without the LiDAR only
    moves along known transitions are offered."""
    if obstacles is None:
        return np.array([waypoint(model, cfg, state, h)[0] == state for h in range(cfg.num_headings)])
    flags = np.asarray(obstacles, dtype=bool).copy()
    if scan is None:
        return flags
    for h in range(cfg.num_headings):
        target, _ = waypoint(model, cfg, state, h)
        if target != state:
            flags[h] = path_blocked(model, cfg, traversed, h, target, obstacles, scan, pose, state)
    return flags


def expand(model: Model, cfg: AgentConfig, traversed: set, state: int, obstacles: np.ndarray, scan: np.ndarray | None,
           pose: np.ndarray) -> int:
    """Predicted transitions from the obstacle signal, and Eq. (7) map expansion in free
    directions where no state lies yet."""
    m = model
    radius = cfg.node_spacing * cfg.influence_radius
    origin = state_poses(model)[state].copy()
    neighbours = neighbours_by_heading(model, cfg, state)
    created = 0
    B = m.B[0]
    for h in range(cfg.num_headings):
        rev = reverse_heading(h, cfg.num_headings)
        n = int(neighbours[h])
        believed = {int(t) for t, p in zip(B.succ[state, h], B.prob[state, h], strict=True) if p > 0}
        for t in sorted((believed | {n}) - {state, -1}):  # states this move is believed to reach
            free = not path_blocked(model, cfg, traversed, h, t, obstacles, scan, pose, state)
            event = Event.PREDICTED_POSSIBLE if free and t == n else Event.PREDICTED_IMPOSSIBLE
            if free and t != n:
                continue  # another state now lies in that direction: leave this link alone
            learn_transition(m, 0, state, h, t, event, reverse_control=rev, rates=cfg.learning)
        if obstacles[h] or n >= 0:
            continue
        if created >= cfg.lookahead_nodes:
            continue
        p_star = predicted_pose(cfg, origin, h, scan, pose)
        d_near = model.pose_index().nearest(p_star)[1]
        if expansion_free_energies(np.array([d_near]), radius, cfg.sigma)[0] < 0:  # Eq. (7)
            new = m.add_state(0, pose=p_star, obs_count=cfg.prior_count / m.num_obs[0])
            created += 1
            learn_transition(m, 0, state, h, new, Event.PREDICTED_POSSIBLE, reverse_control=rev,
                             rates=cfg.learning)
    return created


def predicted_pose(cfg: AgentConfig, origin: np.ndarray, heading: int, scan: np.ndarray | None,
                   pose: np.ndarray) -> np.ndarray:
    """Where a move along ``heading`` from the state at ``origin`` is predicted to lead: one
    influence radius along it, moved to the centre line of a corridor narrower than
    ``passage_width`` when the LiDAR shows one (and the move there is as free)."""
    u = direction(heading, cfg.num_headings)
    p_star = origin + cfg.influence_radius * u
    if scan is None or cfg.passage_width <= 0:
        return p_star
    centred = centre_in_passage(p_star, u, pose + scan, cfg.passage_width, max_shift=0.5 * cfg.influence_radius)
    if blocked(scan, centred - pose, cfg.robot_radius + cfg.obstacle_margin)[0]:
        return p_star
    return centred


def waypoint(model: Model, cfg: AgentConfig, state: int, action: int) -> tuple[int, np.ndarray]:
    """Where an action leads: its most probable successor other than staying (as the planner
    saw it), or, for a direction with no state yet, one step along its heading."""
    poses = state_poses(model)
    if action == cfg.stay:
        return state, poses[state].copy()
    B = model.B[0]
    prob = np.where(B.succ[state, action] != state, B.prob[state, action], 0.0)
    k = int(np.argmax(prob))
    if prob[k] > 0:
        target = int(B.succ[state, action, k])
        return target, poses[target].copy()
    return state, poses[state] + cfg.influence_radius * direction(action, cfg.num_headings)


def reverse(cfg: AgentConfig, action: int) -> int | None:
    """The heading opposite ``action`` (None for stay)."""
    return reverse_heading(action, cfg.num_headings) if action != cfg.stay else None


def predicted(model: Model, cfg: AgentConfig, q: np.ndarray, last, moved: bool | None) -> np.ndarray:
    """Predicted belief after the last decision ``last`` (Eq. 1: B_s applied to the posterior ``q``).

    A move the controller reported blocked (``moved`` False) is learnt first (experienced
    impossible, Table 7) and predicts no change of state."""
    full = np.zeros(model.num_states[0])
    full[: q.size] = q
    if last is None or last.action == cfg.stay:
        return full
    if moved is False:  # blocked: the robot stopped near where it started
        if last.target != last.state:
            learn_transition(model, 0, last.state, last.action, last.target, Event.IMPOSSIBLE,
                             reverse_control=reverse(cfg, last.action), rates=cfg.learning)
        return full
    return model.predict(0, full, last.action)


def wander(cfg: AgentConfig, rng: np.random.Generator, obstacles: np.ndarray | None,
           pose: np.ndarray) -> tuple[int, np.ndarray]:
    """While lost (the map position is unknown, so the graph cannot guide a move): a random free
    heading of the real surroundings and its waypoint one influence radius away (belief frame);
    stay while the LiDAR is silent (nothing says which way is free)."""
    if obstacles is None:
        return cfg.stay, pose
    free = np.flatnonzero(~np.asarray(obstacles, dtype=bool))
    action = int(rng.choice(free)) if free.size else cfg.stay
    return action, pose if action == cfg.stay else pose + cfg.influence_radius * direction(action, cfg.num_headings)
