"""The explore_lite-like frontier explorer in a pybullet room: centroid goals cost failed moves."""

from cogmap.baselines import run_policy
from cogmap.explore import default_config, episode_metrics
from cogmap.study.runs import make_policy, study_sim


def _run(method, env="large_warehouse", seed=0, steps=300):
    cfg = default_config(env)
    sim = study_sim(env, cfg, seed)
    try:
        pol = make_policy(method, sim, cfg.influence_radius, seed)
        ep = run_policy(sim, pol, steps)
        return episode_metrics(sim, ep), pol
    finally:
        sim.close()


def test_centroid_goals_fail_and_get_blacklisted_where_nearest_cells_do_not():
    paper, pol = _run("frontier_paper")
    ours, ref = _run("frontier")
    assert pol.done and ref.done  # both finish (no frontier left) within the budget
    assert paper["coverage"] >= 0.95 and ours["coverage"] >= 0.95
    # centroids inside shelves: the controller drives at them, the moves fail, the goals are blacklisted
    assert paper["failed_moves"] >= 1 and pol.stats["pushes"] >= 1 and pol.blacklisted >= 1
    assert ours["failed_moves"] == 0
    assert paper["distance_m"] > ours["distance_m"]
