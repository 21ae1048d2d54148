"""Fixed-point iteration, VMP and MMP against pymdp 1.0 on the same random models (1e-4).

pymdp's ``vmp`` is our ``vmp_pymdp`` (simultaneous updates); our ``vmp`` is coordinate ascent
(tests/inference/test_mean_field_vmp.py)."""

import numpy as np
import pytest
from inference_helpers import random_model, random_sequence

pytest.importorskip("pymdp")
import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)  # pymdp follows JAX's default dtype
import jax.numpy as jnp  # noqa: E402
from pymdp.inference import update_posterior_states  # noqa: E402

from cogmap import inference  # noqa: E402

TOL = 1e-4
CASES = [
    ((4,), ((0,), (0,))),
    ((3, 2), ((0,), (0, 1), (1,))),
    ((2, 3, 2), ((0, 2), (1,), (0, 1, 2))),
]


def _pymdp_inputs(m, obs):
    M, F = len(m.modalities), len(m.factors)
    A = [jnp.asarray(m.live_A(k)) for k in range(M)]
    B = [jnp.asarray(m.live_B(f)) for f in range(F)]
    onehot = [jnp.asarray(np.eye(m.num_obs[k])[[o[k] for o in obs]]) for k in range(M)]
    deps = dict(A_dependencies=[list(d) for d in m.A_deps], B_dependencies=[[f] for f in range(F)])
    return A, B, onehot, deps


@pytest.mark.parametrize("seed", (0, 1, 2))
@pytest.mark.parametrize(("sizes", "mods"), CASES)
@pytest.mark.parametrize("num_iter", (2, 16))
def test_fpi_matches_pymdp(seed, sizes, mods, num_iter):
    m = random_model(seed, sizes=sizes, modalities=mods)
    obs, _ = random_sequence(m, 1, seed)
    prior = [np.random.default_rng(seed).dirichlet(np.ones(n)) for n in sizes]
    A, B, onehot, deps = _pymdp_inputs(m, obs)
    ref = update_posterior_states(
        A, B, [x[0] for x in onehot], None, prior=[jnp.asarray(p) for p in prior],
        num_iter=num_iter, method="fpi", **deps,
    )
    q, info = inference.fpi(m, prior, obs, num_iter=num_iter)
    for f in range(len(sizes)):
        np.testing.assert_allclose(q[f], np.asarray(ref[f])[0], atol=TOL)


@pytest.mark.parametrize(("seed", "sizes", "mods"), [(i, *case) for i, case in enumerate(CASES)])
@pytest.mark.parametrize(("method", "ours"), (("vmp", "vmp_pymdp"), ("mmp", "mmp")))
def test_message_passing_matches_pymdp(seed, sizes, mods, method, ours):
    m = random_model(seed, sizes=sizes, modalities=mods)
    T = 4
    obs, act = random_sequence(m, T, seed)
    prior = [m.live_D(f) for f in range(len(sizes))]
    A, B, onehot, deps = _pymdp_inputs(m, obs)
    ref = update_posterior_states(
        A, B, onehot, jnp.asarray(np.array(act)), prior=[jnp.asarray(p) for p in prior],
        num_iter=8, method=method, **deps,
    )
    q, info = inference.get(ours)(m, prior, obs, act, num_iter=8)
    for f in range(len(sizes)):
        ours = np.array([h[f] for h in info.history])
        np.testing.assert_allclose(ours, np.asarray(ref[f]), atol=TOL)
        np.testing.assert_allclose(q[f], np.asarray(ref[f])[-1], atol=TOL)


@pytest.mark.parametrize(("sizes", "mods"), CASES[1:2])
def test_to_pymdp_agent_infer_states(sizes, mods):
    m = random_model(5, sizes=sizes, modalities=mods)
    agent = inference.to_pymdp(m, num_iter=16)
    assert agent.num_factors == len(sizes) and agent.num_modalities == len(mods)
    assert [list(d) for d in agent.A_dependencies] == [list(d) for d in m.A_deps]
    obs, _ = random_sequence(m, 1, 5)
    prior = [jnp.asarray(m.live_D(f))[None] for f in range(len(sizes))]
    qs = agent.infer_states([jnp.array([o]) for o in obs[0]], prior)
    q, _ = inference.fpi(m, [m.live_D(f) for f in range(len(sizes))], obs)
    for f in range(len(sizes)):
        np.testing.assert_allclose(np.asarray(qs[f])[0, -1], q[f], atol=TOL)


def test_to_pymdp_sparse_and_counts():
    from inference_helpers import pose_model

    m = pose_model(10, 0)
    m.A[0].counts = np.where(m.A[0].prob > 0, 1.0, 0.0) + m.A[0].prob
    agent = inference.to_pymdp(m)
    np.testing.assert_allclose(np.asarray(agent.B[0])[0], m.live_B(0), atol=1e-12)
    assert agent.pA is not None
    np.testing.assert_allclose(np.asarray(agent.pA[0])[0], m.live_pA(0))
