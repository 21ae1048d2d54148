"""Soft observations are mixtures over outcomes, in every scheme and on both backends.

A distribution ``w`` over the outcomes of modality ``m`` stands for "outcome ``o`` with
probability ``w(o)``": the likelihood of the states is ``L(s) = sum_o w(o) A_m[o, s]``. The tests
hold every scheme to that reading without going through our evidence code:

* ``exact`` and ``filter`` against the joint posterior over all state paths, enumerated here;
* every scheme against itself on a model where each soft entry becomes a hard observation of an
  extra modality whose outcome 0 has the likelihood row ``L`` (scaled or not);
* the mixture against pymdp 1.0.4's log-weighted reading ``sum_o w(o) log A_m[o, s]``, which is a
  different model and must give a different posterior;
* the JAX schemes and the JAX agent against the numpy schemes (float64, 1e-10).
"""

from __future__ import annotations

import itertools

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from inference_helpers import random_model

from cogmap import inference, jax_agent
from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.genmodel.jax_model import to_jax
from cogmap.inference import InferenceError, prepare
from cogmap.inference import jax_schemes as js

SCHEMES = ("exact", "filter", "fpi", "vmp", "vmp_pymdp", "mmp")
WINDOWED = ("vmp", "vmp_pymdp", "mmp")
TOL = 1e-12
JAX_TOL = 1e-10

#: sizes and modality dependencies of the random models (1 and 2 factors, 1 to 3 modalities,
#: some on two factors, one with its factors in reverse order)
CASES = {
    "1f-1m": dict(sizes=(4,), modalities=((0,),)),
    "1f-3m": dict(sizes=(3,), modalities=((0,), (0,), (0,))),
    "2f-2m": dict(sizes=(2, 3), modalities=((0, 1), (1,))),
    "2f-3m": dict(sizes=(3, 2), modalities=((0,), (1, 0), (0, 1))),
}
SEEDS = (0, 1, 2)


@pytest.fixture(autouse=True)
def x64():
    with jax.enable_x64(True):
        yield


def _model(case, seed):
    return random_model(seed, **CASES[case])


def _applies(model, scheme):
    return scheme != "filter" or len(model.factors) == 1


def _prior(model):
    return [model.live_D(f) for f in range(len(model.factors))]


def mixed_sequence(model, T, seed):
    """``T`` steps of hard, soft and missing entries (at least one soft) and ``T - 1`` actions."""
    rng = np.random.default_rng(seed + 77)
    obs = []
    for _ in range(T):
        step = []
        for n in model.num_obs:
            kind = rng.choice(3, p=[0.3, 0.5, 0.2])
            if kind == 0:
                step.append(int(rng.integers(n)))
            elif kind == 1:
                w = rng.dirichlet(np.ones(n))
                if rng.random() < 0.3:  # some soft entries leave outcomes out
                    w[rng.permutation(n)[: n // 2]] = 0.0
                    w /= w.sum()
                step.append(w)
            else:
                step.append(None)
        obs.append(step)
    if not any(isinstance(e, np.ndarray) for step in obs for e in step):
        obs[-1][0] = rng.dirichlet(np.ones(model.num_obs[0]))
    actions = [tuple(int(rng.integers(u)) for u in model.num_controls) for _ in range(T - 1)]
    return obs, actions


def is_soft(entry):
    return entry is not None and np.ndim(entry) == 1


def mixture_row(model, m, w):
    """``sum_o w(o) A_m[o, ...]`` over the live states of the modality's factors."""
    A = model.live_A(m)
    return sum(w[o] * A[o] for o in range(model.num_obs[m]))


def log_weighted_row(model, m, w):
    """``exp(sum_o w(o) log A_m[o, ...])``: the likelihood pymdp 1.0.4 gives a distribution ``w``
    (``xlogy(w, clip(A, eps)).sum(0)``, :func:`pymdp.maths.compute_log_likelihood_single_modality`)."""
    A = np.maximum(model.live_A(m), np.finfo(float).eps)
    return np.exp(sum(w[o] * np.log(A[o]) for o in range(model.num_obs[m]) if w[o] > 0))


def entry_likelihood(model, m, entry):
    A = model.live_A(m)
    return mixture_row(model, m, np.asarray(entry, dtype=float)) if is_soft(entry) else A[int(entry)]


# -- brute force ---------------------------------------------------------------------------------
def brute_force(model, prior, obs, actions):
    """Smoothed marginals ``p(s_t^f | o_1:T)`` and ``log p(o_1:T)``, by summing ``p(path, o_1:T)``
    over every joint state path, each soft entry weighing the path by ``sum_o w(o) A[o, s]``."""
    F, T = len(model.factors), len(obs)
    joint = list(itertools.product(*(range(n) for n in model.num_states)))
    B = [model.live_B(f) for f in range(F)]
    liks = [[None if e is None else entry_likelihood(model, m, e) for m, e in enumerate(step)] for step in obs]
    marginals = [[np.zeros(n) for n in model.num_states] for _ in range(T)]
    total = 0.0
    for path in itertools.product(joint, repeat=T):
        p = np.prod([prior[f][path[0][f]] for f in range(F)])
        for t, s in enumerate(path):
            if t > 0:
                p *= np.prod([B[f][s[f], path[t - 1][f], actions[t - 1][f]] for f in range(F)])
            for m, L in enumerate(liks[t]):
                if L is not None:
                    p *= L[tuple(s[f] for f in model.A_deps[m])]
        total += p
        for t, s in enumerate(path):
            for f in range(F):
                marginals[t][f][s[f]] += p
    return [[x / total for x in row] for row in marginals], float(np.log(total))


def brute_force_filtered(model, prior, obs, actions):
    """Filtered marginals ``p(s_t | o_1:t)`` and ``log p(o_1:t)`` for every ``t``."""
    out = [brute_force(model, prior, obs[: t + 1], actions[:t]) for t in range(len(obs))]
    return [m[-1] for m, _ in out], [lz for _, lz in out]


# -- the hard equivalent -------------------------------------------------------------------------
def hard_equivalent(model, obs, row=mixture_row, scale=False):
    """The model with one extra two-outcome modality per soft entry, whose outcome 0 has the
    likelihood row ``row(model, m, w)`` (divided by its maximum when ``scale``) and outcome 1 the
    rest, and the observations with each soft entry replaced by outcome 0 of its own modality
    (missing at every other step). Also returns ``log c`` per step: the sum over its soft entries
    of the log of the factor their rows were divided by."""
    mods = list(model.modalities)
    A = {mod.name: model.live_A(m) for m, mod in enumerate(model.modalities)}
    where, log_c = [], np.zeros(len(obs))
    for t, step in enumerate(obs):
        for m, e in enumerate(step):
            if is_soft(e):
                L = row(model, m, np.asarray(e, dtype=float))
                c = L.max() if scale else 1.0
                name = f"soft{len(where)}"
                mods.append(Modality(name, 2, tuple(model.factors[f].name for f in model.A_deps[m])))
                A[name] = np.stack([L / c, 1.0 - L / c])
                where.append(t)
                log_c[t] += np.log(c)
    factors = list(model.factors)
    aux = compile(ModelSpec(factors=factors, modalities=mods, A=A,
                            B={fa.name: model.live_B(f) for f, fa in enumerate(factors)},
                            D={fa.name: model.live_D(f) for f, fa in enumerate(factors)}))
    hard_obs = [[None if is_soft(e) else e for e in step] + [0 if t == u else None for u in where]
                for t, step in enumerate(obs)]
    return aux, hard_obs, log_c


def assert_history_close(a, b, atol):
    assert len(a) == len(b)
    for step_a, step_b in zip(a, b, strict=True):
        for qa, qb in zip(step_a, step_b, strict=True):
            np.testing.assert_allclose(np.asarray(qa), np.asarray(qb), rtol=0, atol=atol)


# -- exact and filter against brute force ---------------------------------------------------------
@pytest.mark.parametrize("T", [1, 2, 3, 4])
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("case", CASES)
def test_exact_and_filter_equal_the_enumerated_mixture_posterior(case, seed, T):
    model = _model(case, seed)
    prior = _prior(model)
    obs, acts = mixed_sequence(model, T, seed)
    smoothed, log_z = brute_force(model, prior, obs, acts)
    filtered, log_z_t = brute_force_filtered(model, prior, obs, acts)
    last = -(log_z_t[-1] - (log_z_t[-2] if T > 1 else 0.0))  # -log p(o_T | o_<T)

    q, info = inference.exact(model, prior, obs, acts)
    assert_history_close(info.history, smoothed, TOL)
    assert_history_close([q], [filtered[-1]], TOL)
    assert info.total_free_energy == pytest.approx(-log_z, abs=TOL)
    assert info.free_energy == pytest.approx(last, abs=TOL)

    _, info = inference.exact(model, prior, obs, acts, smooth=False)
    assert_history_close(info.history, filtered, TOL)

    if len(model.factors) == 1:
        _, info = inference.bayes_filter(model, prior, obs, acts)
        assert_history_close(info.history, filtered, TOL)
        assert info.total_free_energy == pytest.approx(-log_z, abs=TOL)
        assert info.free_energy == pytest.approx(last, abs=TOL)


# -- every scheme against its hard equivalent -----------------------------------------------------
@pytest.mark.parametrize("scale", [False, True], ids=["row", "scaled-row"])
@pytest.mark.parametrize("T", [1, 2, 4])
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("case", CASES)
def test_every_scheme_reads_a_soft_entry_as_a_hard_observation_of_its_mixture_row(case, seed, T, scale):
    """Posteriors equal; free energies differ exactly by the log of the factor each row was
    divided by (the model's evidence of outcome 0 is ``L / c``): none when unscaled."""
    model = _model(case, seed)
    prior = _prior(model)
    obs, acts = mixed_sequence(model, T, seed)
    aux, hard_obs, log_c = hard_equivalent(model, obs, scale=scale)
    assert scale or not log_c.any()
    for scheme in SCHEMES:
        if not _applies(model, scheme):
            continue
        run = inference.get(scheme)
        q, info = run(model, prior, obs, acts)
        q_h, info_h = run(aux, prior, hard_obs, acts)
        assert_history_close([q], [q_h], TOL)
        assert_history_close(info.history, info_h.history, TOL)
        # dividing a likelihood row by c adds log c to -log p(o) and to every free energy
        assert info_h.free_energy - info.free_energy == pytest.approx(log_c[-1], abs=1e-10), scheme
        assert info_h.total_free_energy - info.total_free_energy == pytest.approx(log_c.sum(), abs=1e-10), scheme


@pytest.mark.parametrize("scheme", WINDOWED)
@pytest.mark.parametrize("case", ["1f-3m", "2f-3m"])
def test_windows_shorter_than_the_sequence_read_soft_entries_as_mixtures(case, scheme):
    """With ``window=2`` the steps before the window are filtered by fpi: both parts agree too."""
    model = _model(case, 4)
    prior = _prior(model)
    obs, acts = mixed_sequence(model, 4, 4)
    aux, hard_obs, log_c = hard_equivalent(model, obs, scale=True)
    _, info = inference.get(scheme)(model, prior, obs, acts, window=2)
    _, info_h = inference.get(scheme)(aux, prior, hard_obs, acts, window=2)
    assert_history_close(info.history, info_h.history, TOL)
    assert info_h.total_free_energy - info.total_free_energy == pytest.approx(log_c[2:].sum(), abs=1e-10)


# -- one-hot soft entries are hard entries --------------------------------------------------------
@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("case", CASES)
def test_a_one_hot_soft_entry_is_the_hard_index(case, seed):
    model = _model(case, seed)
    prior = _prior(model)
    obs, acts = mixed_sequence(model, 3, seed)
    hard = [[int(np.argmax(e)) if is_soft(e) else e for e in step] for step in obs]
    one_hot = [[np.eye(n)[e] if isinstance(e, int) else e for e, n in zip(step, model.num_obs, strict=True)]
               for step in hard]
    for scheme in SCHEMES:
        if not _applies(model, scheme):
            continue
        q, info = inference.get(scheme)(model, prior, hard, acts)
        q_s, info_s = inference.get(scheme)(model, prior, one_hot, acts)
        assert_history_close([q], [q_s], 1e-14)
        assert_history_close(info.history, info_s.history, 1e-14)
        assert info.free_energy == pytest.approx(info_s.free_energy, abs=1e-14)
        assert info.total_free_energy == pytest.approx(info_s.total_free_energy, abs=1e-14)
    layout, _ = to_jax(model)  # the JAX backend gets the same observation vectors
    for step_h, step_s in zip(hard, one_hot, strict=True):
        for a, b in zip(jax_agent.observation(layout, step_h), jax_agent.observation(layout, step_s), strict=True):
            assert np.array_equal(np.asarray(a), np.asarray(b))


# -- the mixture, not pymdp's log-weighted likelihood ----------------------------------------------
def _two_outcome_model(two_factors=False):
    """One factor (or two) with a two-outcome modality ``o`` whose columns differ (and a second,
    hard, modality ``c``). An even soft entry ``(0.5, 0.5)`` on ``o`` has the flat mixture
    likelihood 0.5 (no information) but the log-weighted likelihood ``sqrt(A[0, s] A[1, s])``,
    which is not flat: (0.3, 0.4) with one factor."""
    A = np.array([[0.9, 0.2], [0.1, 0.8]])
    factors = [Factor("s", 2, 2)]
    deps = ("s",)
    if two_factors:
        factors.append(Factor("r", 3, 2))
        deps = ("s", "r")
        A = np.repeat(A[:, :, None], 3, axis=2) * np.array([1.0, 0.9, 0.8])  # r changes the evidence too
        A[1] = 1.0 - A[0]
    B = {f.name: np.stack([np.eye(f.size), 0.7 * np.roll(np.eye(f.size), 1, axis=0) + 0.3 / f.size], -1)
         for f in factors}
    return compile(ModelSpec(factors, [Modality("o", 2, deps), Modality("c", 2, ("s",))], A={
        "o": A, "c": np.array([[0.7, 0.4], [0.3, 0.6]])}, B=B))


@pytest.mark.parametrize("two_factors", [False, True], ids=["1f", "2f"])
def test_soft_entries_are_mixtures_not_log_weighted(two_factors):
    model = _two_outcome_model(two_factors)
    prior = [np.full(n, 1.0 / n) for n in model.num_states]
    w = np.array([0.5, 0.5])
    obs = [[w, 1], [None, 0], [w, None]]
    acts = [(1,) * len(model.factors)] * 2
    if not two_factors:  # by hand
        np.testing.assert_allclose(mixture_row(model, 0, w), [0.5, 0.5], atol=1e-15)
        np.testing.assert_allclose(log_weighted_row(model, 0, w), [0.3, 0.4], atol=1e-15)
    mixture, mixture_obs, _ = hard_equivalent(model, obs, mixture_row)
    log_weighted, log_weighted_obs, _ = hard_equivalent(model, obs, log_weighted_row)
    for scheme in SCHEMES:
        if not _applies(model, scheme):
            continue
        run = inference.get(scheme)
        _, info = run(model, prior, obs, acts)
        _, info_mix = run(mixture, prior, mixture_obs, acts)
        _, info_log = run(log_weighted, prior, log_weighted_obs, acts)
        assert_history_close(info.history, info_mix.history, TOL)
        gap = max(float(np.abs(a - b).max()) for sa, sb in zip(info.history, info_log.history, strict=True)
                  for a, b in zip(sa, sb, strict=True))
        assert gap > 1e-3, f"{scheme}: the mixture and the log-weighted posteriors should differ"


def test_a_flat_mixture_leaves_the_prior_unchanged_unlike_the_log_weighted_likelihood():
    A = np.array([[0.9, 0.2], [0.1, 0.8]])
    model = compile(ModelSpec([Factor("s", 2)], [Modality("o", 2, ("s",))], A={"o": A},
                              B={"s": np.eye(2)[:, :, None]}))
    w = np.array([0.5, 0.5])
    # mixture: L = (0.5 * 0.9 + 0.5 * 0.1, 0.5 * 0.2 + 0.5 * 0.8) = (0.5, 0.5): no information
    # log-weighted: exp(0.5 log 0.9 + 0.5 log 0.1), exp(0.5 log 0.2 + 0.5 log 0.8) = (0.3, 0.4)
    assert np.allclose(mixture_row(model, 0, w), 0.5)
    np.testing.assert_allclose(log_weighted_row(model, 0, w), [0.3, 0.4], atol=1e-15)
    for scheme in SCHEMES:
        q, info = inference.get(scheme)(model, [np.array([0.5, 0.5])], [[w]])
        np.testing.assert_allclose(q[0], [0.5, 0.5], atol=TOL, err_msg=scheme)
        assert abs(q[0][0] - 3 / 7) > 1e-3  # pymdp 1.0.4's reading gives (3/7, 4/7)
        if scheme in ("exact", "filter"):
            assert info.free_energy == pytest.approx(-np.log(0.5), abs=TOL)
    layout, arrays = to_jax(model)
    for scheme in SCHEMES:
        ev = js.evidence(layout, arrays, jax_agent.observation(layout, [w]))
        q, _ = js.SCHEMES[scheme](layout, arrays, (jnp.asarray([0.5, 0.5]),), ev)
        np.testing.assert_allclose(np.asarray(q[0]), [0.5, 0.5], atol=JAX_TOL, err_msg=scheme)


def test_pymdp_reads_a_distribution_as_log_weighted():
    """What the docs say of pymdp 1.0.4: ``compute_log_likelihood_single_modality`` with
    ``distr_obs=True`` returns ``sum_o w(o) log max(A[o, s], eps)``, not ``log sum_o w(o) A[o, s]``."""
    pytest.importorskip("pymdp")
    from pymdp.maths import compute_log_likelihood_single_modality

    model = _model("2f-3m", 0)
    w = np.random.default_rng(0).dirichlet(np.ones(model.num_obs[1]))
    got = np.asarray(compute_log_likelihood_single_modality(jnp.asarray(w), jnp.asarray(model.live_A(1)),
                                                            distr_obs=True))
    np.testing.assert_allclose(got, np.log(log_weighted_row(model, 1, w)), atol=1e-12)
    assert np.abs(got - np.log(mixture_row(model, 1, w))).max() > 1e-3


# -- the JAX backend ------------------------------------------------------------------------------
def _jax_evidence(layout, arrays, step):
    return js.evidence(layout, arrays, jax_agent.observation(layout, step))


@pytest.mark.parametrize("case", CASES)
def test_jax_one_step_schemes_match_numpy_on_soft_entries(case):
    model = _model(case, 1)
    layout, arrays = to_jax(model)
    obs, _ = mixed_sequence(model, 4, 1)
    rng = np.random.default_rng(3)
    for scheme in SCHEMES:
        if not _applies(model, scheme):
            continue
        for step in obs:
            prior = [rng.dirichlet(np.ones(n)) for n in model.num_states]
            q_np, info = inference.get(scheme)(model, prior, [step])
            q_j, F = js.SCHEMES[scheme](layout, arrays, tuple(jnp.asarray(p) for p in prior),
                                        _jax_evidence(layout, arrays, step))
            assert_history_close([q_j], [q_np], JAX_TOL)
            assert abs(float(F) - info.free_energy) < JAX_TOL, scheme


@pytest.mark.parametrize("kind", WINDOWED)
@pytest.mark.parametrize("case", CASES)
def test_jax_windows_match_numpy_on_soft_entries(case, kind):
    model = _model(case, 2)
    layout, arrays = to_jax(model)
    obs, acts = mixed_sequence(model, 4, 2)
    prior = _prior(model)
    _, info = inference.get(kind)(model, prior, obs, acts)
    evs = [_jax_evidence(layout, arrays, step) for step in obs]
    stacked = js.Evidence(tuple(jnp.stack([e.lik[m] for e in evs]) for m in range(layout.num_modalities)),
                          jnp.stack([e.present for e in evs]))
    qs, terms = js.window(kind, layout, arrays, tuple(jnp.asarray(p) for p in prior), stacked, jnp.asarray(acts))
    assert_history_close([[q[t] for q in qs] for t in range(len(obs))], info.history, JAX_TOL)
    assert abs(float(terms.sum()) - info.total_free_energy) < JAX_TOL
    assert abs(float(terms[-1]) - info.free_energy) < JAX_TOL


@pytest.mark.parametrize(("case", "scheme"), [(c, s) for c in ("1f-3m", "2f-3m") for s in SCHEMES
                                               if not (s == "filter" and c.startswith("2f"))])
def test_jax_agent_steps_match_numpy_on_soft_entries(case, scheme):
    """The agent's step (given actions) against the numpy scheme, one step at a time from the
    predicted prior, as the loop runs it."""
    model = _model(case, 0)
    agent = jax_agent.build(model, scheme=scheme, sample=False)
    state = agent.init(jax.random.key(0))
    obs, acts = mixed_sequence(model, 4, 5)
    prior = _prior(model)
    for t, step in enumerate(obs):
        action = acts[t] if t < len(acts) else (0,) * len(model.factors)
        q_np, info_np = inference.get(scheme)(model, prior, [step])
        state, info = jax_agent.jitted_step(agent.config, state, jax_agent.observation(agent.config.layout, step),
                                            jnp.asarray(action, dtype=jnp.int32))
        assert_history_close([info.qs], [q_np], JAX_TOL)
        assert abs(float(info.free_energy) - info_np.free_energy) < JAX_TOL
        prior = [model.predict(f, q, a) for f, (q, a) in enumerate(zip(q_np, action, strict=True))]


# -- bad soft entries ----------------------------------------------------------------------------
BAD = [
    (np.array([0.5, 0.7, -0.2]), "entries must be finite and non-negative"),
    (np.array([np.nan, 0.5, 0.5]), "entries must be finite and non-negative"),
    (np.array([np.inf, 0.0, 0.0]), "entries must be finite and non-negative"),
    (np.array([0.2, 0.2, 0.2]), "sums to 0.6, expected 1 (normalise it)"),
    (np.zeros(3), "sums to 0, expected 1"),
    (np.array([0.5, 0.5]), "expected a vector of length 3 (live) or 3 (capacity), got shape (2,)"),
    (np.full(4, 0.25), "expected a vector of length 3 (live) or 3 (capacity), got shape (4,)"),
    (np.full((1, 3), 1 / 3), "expected a vector of length 3 (live) or 3 (capacity), got shape (1, 3)"),
    (np.array([0.5, 0.5, 0.0]) + 0j, "complex entries"),
    (["0.5", "0.5", "0"], "not a numeric array (got strings)"),
]


@pytest.fixture(scope="module")
def three_outcomes():
    return random_model(0, sizes=(2,), modalities=((0,),), obs_sizes=(3,))


@pytest.mark.parametrize(("entry", "message"), BAD)
def test_bad_soft_entries_are_refused_by_prepare(three_outcomes, entry, message):
    model = three_outcomes
    with pytest.raises(InferenceError) as err:
        prepare(model, _prior(model), [[0], [entry]], [(0,)])
    assert str(err.value).startswith("observations[1] for modality 'm0': ")
    assert message in str(err.value)
    with pytest.raises(InferenceError, match="observations\\[0\\] for modality 'm0'"):
        prepare(model, _prior(model), [{"m0": entry}])


@pytest.mark.parametrize("scheme", SCHEMES)
def test_every_scheme_refuses_a_bad_soft_entry(three_outcomes, scheme):
    model = three_outcomes
    for entry, message in BAD[:4]:
        with pytest.raises(InferenceError, match="observations\\[0\\] for modality 'm0'") as err:
            inference.get(scheme)(model, _prior(model), [[entry]])
        assert message in str(err.value)


def test_mass_beyond_the_live_outcomes_is_refused_and_capacity_length_accepted():
    A = np.array([[0.9, 0.2], [0.1, 0.8]])
    model = compile(ModelSpec([Factor("s", 2)], [Modality("o", 2, ("s",), growable=True, capacity=4)],
                              A={"o": A}, B={"s": np.eye(2)[:, :, None]}))
    prior = [np.array([0.3, 0.7])]
    w = np.array([0.25, 0.75])
    q, _ = inference.exact(model, prior, [[np.concatenate([w, [0.0, 0.0]])]])
    np.testing.assert_allclose(q[0], inference.exact(model, prior, [[w]])[0][0], atol=1e-15)
    with pytest.raises(InferenceError, match="puts mass on entries beyond the 2 live ones"):
        inference.exact(model, prior, [[np.array([0.25, 0.5, 0.25, 0.0])]])
    layout, arrays = to_jax(model)
    q_j, _ = js.exact(layout, arrays, (jnp.asarray(prior[0]),), _jax_evidence(layout, arrays, [w]))
    np.testing.assert_allclose(np.asarray(q_j[0]), q[0], atol=JAX_TOL)


@pytest.mark.parametrize(("entry", "message"), [
    (np.array([0.5, 0.7, -0.2]), "modality 0: distribution entries must be finite and non-negative"),
    (np.array([np.nan, 0.5, 0.5]), "modality 0: distribution entries must be finite and non-negative"),
    (np.array([0.2, 0.2, 0.2]), "modality 0: distribution sums to 0.6, expected 1 (normalise it)"),
    (np.full(4, 0.25), "modality 0: a distribution over outcomes is a vector of at most 3 entries, got shape (4,)"),
    (np.full((1, 3), 1 / 3), "at most 3 entries, got shape (1, 3)"),
    (["0.5", "0.5", "0"], "modality 0: not a numeric array (got strings)"),
])
def test_the_jax_backend_refuses_bad_soft_entries(three_outcomes, entry, message):
    layout, _ = to_jax(three_outcomes)
    with pytest.raises(ValueError) as err:
        jax_agent.observation(layout, [entry])
    assert message in str(err.value)
