"""Trials: learning the initial state (pD) and the habits (pE) at loop.reset, as SPM's spm_MDP_VB_X."""

from __future__ import annotations

import numpy as np
import pytest

from cogmap import loop
from cogmap.envs.jax_worlds import tmaze_model
from cogmap.planning.policies import enumerate_policies


def _obs(model, rng, location, context):
    return [int(rng.choice(n, p=model.live_A(m)[(slice(None), location, context)[: 1 + len(model.A_deps[m])]]))
            for m, n in enumerate(model.num_obs)]


def test_reset_adds_the_first_posterior_to_pD_and_the_last_policy_posterior_to_pE():
    model = tmaze_model()
    P = len(enumerate_policies(model.num_controls, 1))
    pD = [np.array([4.0, 0.0, 0.0, 1.0]), np.array([1.0, 1.0])]  # a zero count stays zero (SPM: d > 0 only)
    pE = np.linspace(1.0, 2.0, P)
    state = loop.init(model, pD=pD, pE=pE, lr_D=0.5, lr_E=2.0, sample=False)
    np.testing.assert_allclose(state.prior[0], pD[0] / 5.0)  # the trial's prior is pD normalised
    rng = np.random.default_rng(0)
    o1, o2 = _obs(model, rng, 0, 1), _obs(model, rng, 3, 1)
    state, first = loop.step(state, o1)
    state, last = loop.step(state, o2, action=(3, 0))
    nxt = loop.reset(state)
    # the belief about the first state given the whole trial, by brute force over the state paths
    prior = [d / d.sum() for d in pD]
    joint = np.zeros((4, 2))
    for l0, c0, l1, c1 in np.ndindex(4, 2, 4, 2):
        p = prior[0][l0] * prior[1][c0] * model.live_B(0)[l1, l0, first.action[0]] * (c0 == c1)
        for o, (l, c) in ((o1, (l0, c0)), (o2, (l1, c1))):
            for m, deps in enumerate(model.A_deps):
                p *= model.live_A(m)[(o[m], l, c)[: 1 + len(deps)]]
        joint[l0, c0] += p
    joint /= joint.sum()
    for f, smooth in enumerate((joint.sum(axis=1), joint.sum(axis=0))):
        want = pD[f] + np.where(pD[f] > 0, 0.5 * smooth, 0.0)
        np.testing.assert_allclose(nxt.pD[f], want, atol=1e-12)
        np.testing.assert_allclose(nxt.prior[f], want / want.sum(), atol=1e-12)
    np.testing.assert_allclose(nxt.pE, pE + 2.0 * last.q_pi, atol=1e-15)
    assert nxt.t == 0 and nxt.qs is None and nxt.trial is None
    # the new habits weigh the next policy posterior: q(pi) = softmax(ln E - gamma G)
    nxt, info = loop.step(nxt, [0, 0, 0])
    x = np.log(nxt.pE / nxt.pE.sum()) - 16.0 * info.G
    np.testing.assert_allclose(info.q_pi, np.exp(x - x.max()) / np.exp(x - x.max()).sum(), atol=1e-12)


def test_the_initial_context_is_learnt_over_trials():
    """Trials that always start in context 1 move pD (and the next trial's prior) towards it."""
    model = tmaze_model()
    state = loop.init(model, pD=[np.array([1.0, 1e-3, 1e-3, 1e-3]), np.ones(2)], sample=False)
    rng = np.random.default_rng(1)
    for _ in range(6):
        state, _ = loop.step(state, _obs(model, rng, 0, 1))
        state, _ = loop.step(state, _obs(model, rng, 3, 1), action=(3, 0))  # visit the cue
        state, _ = loop.step(state, _obs(model, rng, 2, 1), action=(2, 0))
        state = loop.reset(state)
    assert state.prior[1][1] > 0.75  # it started at 0.5: the cue, seen later, tells the first context
    assert state.pD[1].sum() == pytest.approx(2.0 + 6.0)


def test_a_habit_forms_for_the_policy_taken():
    model = tmaze_model()
    P = len(enumerate_policies(model.num_controls, 1))
    state = loop.init(model, pE=np.ones(P), gamma=1.0, sample=False, lr_E=5.0)
    rng = np.random.default_rng(2)
    for _ in range(5):
        state, info = loop.step(state, _obs(model, rng, 0, 0))
        state = loop.reset(state)
    favourite = int(np.argmax(state.pE))
    assert state.pE[favourite] > 5.0 and favourite == info.action[0]


@pytest.mark.parametrize("kwargs, message", [
    (dict(pD=[np.ones(4)]), "one count vector per factor"),
    (dict(pD=[np.ones(3), np.ones(2)]), "pD for factor 'location' must be 4"),
    (dict(pD=[np.zeros(4), np.ones(2)]), "positive sum"),
    (dict(pD=[-np.ones(4), np.ones(2)]), "non-negative"),
    (dict(pE=np.ones(4), E=np.ones(4)), "not both"),
    (dict(pE=np.ones(5)), "must be a vector of 4"),
    (dict(lr_D=-1.0), "lr_D"),
    (dict(lr_E=float("nan")), "lr_E"),
    (dict(pE=np.ones(4), planner="mcts"), "needs planner 'enumerate'"),
    (dict(pD=[np.ones(4), np.ones(2)], backend="jax"), "not available on the jax backend"),
])
def test_bad_trial_settings_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        loop.init(tmaze_model(), **kwargs)


def test_reset_refuses_a_jax_agent():
    pytest.importorskip("jax")
    with pytest.raises(TypeError, match="numpy-backend LoopState"):
        loop.reset(loop.init(tmaze_model(), backend="jax"))
