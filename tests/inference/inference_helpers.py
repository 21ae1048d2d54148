"""Random small models for inference tests."""

from __future__ import annotations

import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, compile


def dirichlet(rng, shape, conc=1.0):
    x = rng.gamma(conc, size=shape)
    return x / x.sum(axis=0, keepdims=True)


def random_model(seed, sizes=(3,), controls=None, modalities=((0,),), obs_sizes=None, conc=1.0,
                 growable=False):
    """Random model: ``modalities`` lists each modality's factor dependencies."""
    rng = np.random.default_rng(seed)
    controls = controls or tuple(2 for _ in sizes)
    obs_sizes = obs_sizes or tuple(3 + i for i in range(len(modalities)))
    factors = [
        Factor(f"f{i}", n, num_controls=u, growable=growable)
        for i, (n, u) in enumerate(zip(sizes, controls, strict=True))
    ]
    mods = [
        Modality(f"m{j}", no, tuple(f"f{i}" for i in deps))
        for j, (deps, no) in enumerate(zip(modalities, obs_sizes, strict=False))
    ]
    A = {
        f"m{j}": dirichlet(rng, (no,) + tuple(sizes[i] for i in deps), conc)
        for j, (deps, no) in enumerate(zip(modalities, obs_sizes, strict=False))
    }
    B = {f"f{i}": dirichlet(rng, (n, n, u), conc) for i, (n, u) in enumerate(zip(sizes, controls, strict=False))}
    D = {f"f{i}": dirichlet(rng, (n,), 2.0) for i, n in enumerate(sizes)}
    return compile(ModelSpec(factors=factors, modalities=mods, A=A, B=B, D=D))


def random_sequence(model, T, seed, missing=0.0):
    """Random observations (indices, sometimes missing) and actions for ``model``."""
    rng = np.random.default_rng(seed + 1000)
    obs = []
    for _ in range(T):
        step = [int(rng.integers(n)) for n in model.num_obs]
        step = [None if rng.random() < missing else o for o in step]
        obs.append(step)
    actions = [tuple(int(rng.integers(u)) for u in model.num_controls) for _ in range(T - 1)]
    return obs, actions


def _weighted_paths(model, prior, obs, actions):
    """Every joint state path with its probability p(path, o_1:T) (tiny models only)."""
    import itertools

    F = len(model.factors)
    joint_states = list(itertools.product(*[range(n) for n in model.num_states]))
    T = len(obs)
    for path in itertools.product(joint_states, repeat=T):
        p = np.prod([prior[f][path[0][f]] for f in range(F)])
        for t in range(T):
            if t > 0:
                p *= np.prod(
                    [model.live_B(f)[path[t][f], path[t - 1][f], actions[t - 1][f]] for f in range(F)]
                )
            for m, o in enumerate(obs[t]):
                if o is not None:
                    p *= model.live_A(m)[(o,) + tuple(path[t][f] for f in model.A_deps[m])]
        yield path, p


def brute_force_log_evidence(model, prior, obs, actions):
    """log p(o_1:T) by summing over every state path (tiny models only)."""
    return float(np.log(sum(p for _, p in _weighted_paths(model, prior, obs, actions))))


def brute_force_marginals(model, prior, obs, actions):
    """Smoothed per-factor marginals p(s_t^f | o_1:T) by path enumeration (tiny models)."""
    out = [[np.zeros(n) for n in model.num_states] for _ in range(len(obs))]
    for path, p in _weighted_paths(model, prior, obs, actions):
        for t, states in enumerate(path):
            for f, s in enumerate(states):
                out[t][f][s] += p
    return [[x / x.sum() for x in row] for row in out]


def pose_model(n, seed, slots=4, num_obs=None, dense=False, growable=False):
    """A single-factor map with 13 controls (12 headings + stay), sparse B and stored poses."""
    from cogmap.genmodel import PoseSpec, SparseB

    rng = np.random.default_rng(seed)
    U, stay = 13, 12
    num_obs = num_obs or max(2, n // 2)
    succ = rng.integers(0, n, size=(n, U, slots))
    prob = dirichlet(rng, (slots, n, U), 1.0).transpose(1, 2, 0)
    succ[:, stay] = np.arange(n)[:, None]
    prob[:, stay] = 0.0
    prob[:, stay, 0] = 1.0
    sparse = SparseB(succ=succ, prob=prob)
    if dense:
        from cogmap.genmodel import SparseTransitions

        Bd = SparseTransitions(succ, prob).to_dense(n)
        B = Bd
    else:
        B = sparse
    A = dirichlet(rng, (num_obs, n), 0.3)
    poses = rng.uniform(0, np.sqrt(n), size=(n, 2))
    headings = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    spec = ModelSpec(
        factors=[Factor("loc", n, num_controls=U, stay=stay, growable=growable)],
        modalities=[Modality("view", num_obs, ("loc",))],
        A={"view": A},
        B={"loc": B},
        pose=PoseSpec("loc", poses, headings, step=1.0, influence_radius=1.0),
    )
    return compile(spec)
