"""``vmp``: coordinate ascent on the mean-field free energy of a window, against independent references.

* an update-by-update reimplementation on joint tensors (the schedule: Gauss-Seidel over
  ``t = 0..T-1``, ``f = 0..F-1``, floored logarithms);
* exact Bayes (``-log p(o_1:T)``, checked against path enumeration where that is cheap): the free
  energy never increases from one sweep to the next and never falls below it;
* models whose exact posterior factorises, where the mean field is exact;
* the aliased 3 x 3 room, where pymdp 1.0's simultaneous updates (``vmp_pymdp``) stay far from
  the mean-field optimum.
"""

import numpy as np
import pytest
from inference_helpers import brute_force_log_evidence, dirichlet, random_model, random_sequence

from cogmap import inference, loop
from cogmap.genmodel import Factor, Modality, ModelSpec, compile
from cogmap.inference import InferenceError, window_free_energy

EPS = np.finfo(float).eps


def priors(model):
    return [model.live_D(f) for f in range(len(model.factors))]


def _log(x):
    return np.log(np.maximum(x, EPS))


def random_case(seed):
    """1 to 3 factors of 2 or 3 states, 2 or 3 modalities on one or two factors, T in 2..6."""
    rng = np.random.default_rng(seed)
    F = int(rng.integers(1, 4))
    sizes = tuple(int(n) for n in rng.integers(2, 4, size=F))
    mods = []
    for _ in range(int(rng.integers(2, 4))):
        k = int(rng.integers(1, min(F, 2) + 1))
        mods.append(tuple(sorted(int(f) for f in rng.choice(F, size=k, replace=False))))
    model = random_model(seed, sizes=sizes, modalities=tuple(mods))
    T = int(rng.integers(2, 7))
    obs, acts = random_sequence(model, T, seed, missing=0.2)
    return model, obs, acts


def reference_sweeps(model, prior, obs, acts, sweeps):
    """The coordinate updates written on joint tensors: for ``q_t^f``, the expected floored
    log-likelihood of step ``t`` over the other factors' current marginals (a contraction of the
    joint log-likelihood tensor), plus the floored transition terms of its two neighbours."""
    F, T = len(model.factors), len(obs)
    sizes = model.num_states
    letters = "abcdefghij"[:F]
    joint_ll = []
    for o_t in obs:
        ll = np.zeros(sizes)
        for m, o in enumerate(o_t):
            if o is None:
                continue
            deps = model.A_deps[m]
            term = _log(model.live_A(m)[o])  # axes: deps, in order
            shape = [sizes[f] if f in deps else 1 for f in range(F)]
            perm = np.argsort(deps)
            ll = ll + np.transpose(term, perm).reshape(shape)
        joint_ll.append(ll)
    logB = [[_log(model.live_B(f)[:, :, acts[t][f]]) for f in range(F)] for t in range(T - 1)]
    qs = [[np.full(n, 1.0 / n) for n in sizes] for _ in range(T)]
    for _ in range(sweeps):
        for t in range(T):
            for f in range(F):
                others = [g for g in range(F) if g != f]
                spec = f"{letters},{','.join(letters[g] for g in others)}->{letters[f]}" if others else \
                    f"{letters}->{letters[f]}"
                x = np.einsum(spec, joint_ll[t], *[qs[t][g] for g in others])
                x = x + (_log(prior[f]) if t == 0 else logB[t - 1][f] @ qs[t - 1][f])
                if t < T - 1:
                    x = x + qs[t + 1][f] @ logB[t][f]
                e = np.exp(x - x.max())
                qs[t][f] = e / e.sum()
    return qs


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("sweeps", [1, 2, 5])
def test_updates_follow_the_gauss_seidel_schedule(seed, sweeps):
    model, obs, acts = random_case(seed)
    _, info = inference.vmp(model, priors(model), obs, acts, num_iter=sweeps)
    ref = reference_sweeps(model, priors(model), obs, acts, sweeps)
    assert info.iterations == sweeps
    for t, step in enumerate(info.history):
        for f, q in enumerate(step):
            np.testing.assert_allclose(q, ref[t][f], atol=1e-12)


@pytest.mark.parametrize("seed", range(50))
def test_free_energy_never_increases_and_never_beats_exact(seed):
    model, obs, acts = random_case(seed)
    prior = priors(model)
    _, infoe = inference.exact(model, prior, obs, acts)
    bound = infoe.total_free_energy  # -log p(o_1:T)
    joint = int(np.prod(model.num_states))
    if joint ** len(obs) <= 5000:  # and by path enumeration, where that is cheap
        assert bound == pytest.approx(-brute_force_log_evidence(model, prior, obs, acts), abs=1e-9)
    reported, recomputed = [], []
    for n in range(1, 13):
        q, info = inference.vmp(model, prior, obs, acts, num_iter=n)
        assert len(info.history) == len(obs)
        for f, x in enumerate(q):
            np.testing.assert_array_equal(x, info.history[-1][f])
        reported.append(info.total_free_energy)
        recomputed.append(window_free_energy(model, prior, obs, acts, info.history))
    reported, recomputed = np.array(reported), np.array(recomputed)
    np.testing.assert_allclose(recomputed, reported, atol=1e-10)
    assert np.all(np.diff(reported) <= 1e-10), (seed, reported)
    assert np.all(np.diff(recomputed) <= 1e-10), (seed, recomputed)
    assert np.all(reported >= bound - 1e-10), (seed, reported.min(), bound)


def _equal_columns(rng, n, controls):
    """Transitions that forget the current state: ``B[:, s, u]`` is one vector for every ``s``."""
    cols = dirichlet(rng, (n, controls))
    return np.repeat(cols[:, None, :], n, axis=1)


def memoryless_model(seed, sizes):
    """Each modality observes one factor and no transition depends on the current state: the
    exact posterior is a product over factors and over time."""
    rng = np.random.default_rng(seed)
    factors = [Factor(f"f{i}", n, num_controls=2) for i, n in enumerate(sizes)]
    mods = [Modality(f"m{i}", 3, (f"f{i}",)) for i in range(len(sizes))]
    mods.append(Modality("extra", 4, ("f0",)))
    A = {f"m{i}": dirichlet(rng, (3, n)) for i, n in enumerate(sizes)}
    A["extra"] = dirichlet(rng, (4, sizes[0]))
    B = {f"f{i}": _equal_columns(rng, n, 2) for i, n in enumerate(sizes)}
    D = {f"f{i}": dirichlet(rng, (n,), 2.0) for i, n in enumerate(sizes)}
    return compile(ModelSpec(factors=factors, modalities=mods, A=A, B=B, D=D))


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize(("sizes", "T"), [((4,), 5), ((3, 4), 4), ((2, 3, 2), 1), ((3, 2), 1)])
def test_exact_where_the_posterior_factorises(seed, sizes, T):
    model = memoryless_model(seed, sizes)
    obs, acts = random_sequence(model, T, seed, missing=0.2)
    prior = priors(model)
    q, info = inference.vmp(model, prior, obs, acts)
    qe, infoe = inference.exact(model, prior, obs, acts)
    exact_F = infoe.total_free_energy
    assert abs(info.total_free_energy - exact_F) <= 0.01 * abs(exact_F)
    assert info.total_free_energy == pytest.approx(exact_F, abs=1e-9)  # in fact equal
    for t in range(T):
        for f in range(len(sizes)):
            np.testing.assert_allclose(info.history[t][f], infoe.history[t][f], atol=1e-8)
    for f in range(len(sizes)):
        np.testing.assert_allclose(q[f], qe[f], atol=1e-8)


def aliased_grid():
    """The 3 x 3 room of ``aliased_room``: 9 places, 3 views each seen at 3 places (10 % noise),
    deterministic moves (stay, east, west, north, south), a uniform prior."""
    from cogmap.genmodel.demo_models import aliased_room, room_model

    A, B, _ = aliased_room(side=3, views=3, noise=0.1)
    return room_model(A, B)


def test_the_aliased_grid_vmp_is_close_to_exact_and_far_below_vmp_pymdp():
    from cogmap.inference.compare import compare_inference, generate_sequence

    model = aliased_grid()
    seq = generate_sequence(model, 30, seed=0)  # a random walk of 30 steps
    rows = {r.scheme: r for r in compare_inference(model, seq.observations, seq.actions, true_states=seq.states,
                                                   schemes=["exact", "vmp", "vmp_pymdp", "mmp"])}
    exact_F = rows["exact"].free_energy
    assert exact_F - 1e-9 <= rows["vmp"].free_energy <= exact_F + 0.01 * abs(exact_F)
    assert rows["vmp_pymdp"].free_energy > 10 * rows["vmp"].free_energy
    assert rows["vmp"].accuracy >= rows["vmp_pymdp"].accuracy
    assert rows["vmp"].accuracy >= rows["exact"].accuracy - 1e-12
    # the simultaneous schedule is no descent: more sweeps do not bring it down
    prior = priors(model)
    for n in (16, 64):
        _, info = inference.vmp_pymdp(model, prior, seq.observations, seq.actions, num_iter=n)
        assert info.total_free_energy > 10 * rows["vmp"].free_energy


def test_tol_stops_once_nothing_moves():
    model, obs, acts = random_case(3)
    prior = priors(model)
    q_full, info_full = inference.vmp(model, prior, obs, acts, num_iter=200)
    q, info = inference.vmp(model, prior, obs, acts, num_iter=200, tol=1e-12)
    assert 1 < info.iterations < 200
    for a, b in zip(q, q_full, strict=True):
        np.testing.assert_allclose(a, b, atol=1e-10)
    # tol only stops early: the sweeps it ran are those of num_iter=iterations
    _, same = inference.vmp(model, prior, obs, acts, num_iter=info.iterations)
    assert same.total_free_energy == info.total_free_energy


@pytest.fixture(scope="module")
def small():
    return random_model(1, sizes=(3,), modalities=((0,),))


@pytest.mark.parametrize(("options", "message"), [
    (dict(num_iter=0), "vmp: num_iter must be >= 1, got 0"),
    (dict(num_iter=-1), "vmp: num_iter must be >= 1, got -1"),
    (dict(num_iter=2.5), "vmp: num_iter must be an integer >= 1, got 2.5"),
    (dict(window=0), "vmp: window must be >= 1, got 0"),
    (dict(window=1.5), "vmp: window must be an integer >= 1 or None, got 1.5"),
    (dict(tol=-1.0), "vmp: tol must be a positive number or None, got -1.0"),
    (dict(tol=0), "vmp: tol must be a positive number or None, got 0"),
])
def test_bad_options_are_refused(small, options, message):
    with pytest.raises(InferenceError) as err:
        inference.get("vmp")(small, priors(small), [[0], [1]], [(0,)], **options)
    assert message in str(err.value)


def test_tau_is_an_option_of_vmp_pymdp_not_of_vmp(small):
    with pytest.raises(TypeError, match="unexpected keyword argument 'tau'"):
        inference.get("vmp")(small, priors(small), [[0]], tau=0.5)
    with pytest.raises(InferenceError, match=r"inference scheme 'vmp' has no option 'tau' \(its options: num_iter, "
                                             "window, tol\\)"):
        loop.init(small, scheme="vmp", tau=0.5)
    inference.get("vmp_pymdp")(small, priors(small), [[0]], tau=0.5)  # accepted there
    loop.init(small, scheme="vmp_pymdp", tau=0.5)


def test_both_are_registered_and_offered_for_discrete_models(small):
    assert {"vmp", "vmp_pymdp"} <= set(inference.available())
    assert {"vmp", "vmp_pymdp"} <= set(inference.accepting(small))
    assert inference.get("vmp") is inference.vmp and inference.get("vmp_pymdp") is inference.vmp_pymdp


def test_the_order_of_updates_matters_for_several_factors():
    """Gauss-Seidel differs from simultaneous updates after one sweep as soon as two factors share
    a modality (here on a single step, where vmp_pymdp's sweep is fpi's)."""
    model = random_model(2, sizes=(3, 3), modalities=((0, 1),))
    obs = [[1]]
    _, a = inference.vmp(model, priors(model), obs, num_iter=1)
    _, b = inference.vmp_pymdp(model, priors(model), obs, num_iter=1)
    assert max(np.abs(x - y).max() for x, y in zip(a.history[0], b.history[0], strict=True)) > 1e-3
    ref = reference_sweeps(model, priors(model), obs, [], 1)
    for f in range(2):
        np.testing.assert_allclose(a.history[0][f], ref[0][f], atol=1e-12)


def test_many_seeds_cover_several_factors_and_lengths():
    cases = [random_case(seed) for seed in range(50)]
    assert {len(m.factors) for m, _, _ in cases} == {1, 2, 3}
    assert {len(o) for _, o, _ in cases} == set(range(2, 7))
    assert any(any(len(d) > 1 for d in m.A_deps) for m, _, _ in cases)
    assert all(len(m.modalities) >= 2 for m, _, _ in cases)

