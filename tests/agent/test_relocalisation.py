"""With perfect odometry no drift correction or relocalisation may move the believed
position by more than 1 m (seeded runs in procedural buildings, short budgets)."""

import pytest

from cogmap.study.runs import explore_episode


@pytest.mark.parametrize("env,seed", [("building:corridor:4", 0), ("building:office:5", 1), ("building:U:10", 2)])
def test_no_belief_jump_with_perfect_odometry(env, seed):
    pytest.importorskip("pybullet")
    sim, ep, agent, _ = explore_episode(env, "aimapp", seed, 20)
    try:
        truth = [(r["true_x"], r["true_y"]) for r in ep.rows]
        belief = [(r["belief_x"], r["belief_y"]) for r in ep.rows]
    finally:
        sim.close()
    assert len(ep.rows) >= 10  # the run explored (its own end may come before the budget)
    assert all(m["moved_m"] <= 1.0 for m in agent.memory.frame_moves), agent.memory.frame_moves
    # and the belief stays on the truth (perfect odometry: any gap would come from the frame moves)
    assert max(abs(b[0] - t[0]) + abs(b[1] - t[1]) for b, t in zip(belief, truth, strict=True)) <= 1.0
