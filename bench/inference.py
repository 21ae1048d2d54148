"""Time per state-inference step and per map growth, ours against pymdp 1.0, in one run.

    python bench/inference.py [--quick]

Model per size: one factor with 13 controls (12 headings + stay), a sparse topological B with
8 successor slots per column, an observation modality with about states/2 outcomes and, for
our schemes, metric pose evidence over every live state. One step = predict through B under
the last action, then update on the new observation.

pymdp 1.0 gets the same model with a dense B (its only option) and the observation modality
only (it has no continuous pose likelihood), its step jitted and warmed up; beyond the size
whose dense B fits the memory budget it is reported as n/a.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, SparseB, compile
from cogmap.inference import bayes_filter as filter_scheme
from cogmap.inference import fpi
from cogmap.inference.compare import generate_sequence

U, STAY, SLOTS = 13, 12, 8
DENSE_BUDGET_GB = 1.5
REPEATS = 3  # best of, against noise from other work on the machine


def build(n: int, seed: int = 0, growable: bool = False):
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    poses = np.stack([np.arange(n) % side, np.arange(n) // side], axis=1).astype(float)
    # successors: the state itself and nearby grid neighbours (a topological map)
    offs = rng.integers(-side - 1, side + 2, size=(n, U, SLOTS))
    succ = np.clip(np.arange(n)[:, None, None] + offs, 0, n - 1)
    succ[:, :, 0] = np.arange(n)[:, None]
    prob = rng.dirichlet(np.ones(SLOTS), size=(n, U))
    succ[:, STAY] = np.arange(n)[:, None]
    prob[:, STAY] = 0.0
    prob[:, STAY, 0] = 1.0
    n_obs = max(2, n // 2)
    A = rng.gamma(0.3, size=(n_obs, n)) + 1e-3
    A /= A.sum(axis=0)
    spec = ModelSpec(
        factors=[Factor("loc", n, num_controls=U, stay=STAY, growable=growable)],
        modalities=[Modality("view", n_obs, ("loc",))],
        A={"view": A},
        B={"loc": SparseB(succ=succ, prob=prob)},
        pose=PoseSpec("loc", poses, np.linspace(0, 2 * np.pi, 12, endpoint=False)),
    )
    return compile(spec)


def workload(model, steps: int, seed: int = 1):
    """Observations, noisy poses and actions along a trajectory sampled from the model."""
    seq = generate_sequence(model, steps + 1, seed)
    obs = np.array([o[0] for o in seq.observations])
    poses = np.array([o[1] for o in seq.observations])
    acts = np.array([a[0] for a in seq.actions] + [STAY])
    return obs, poses, acts


def predicted_priors(model, steps: int):
    """The predicted prior before each step of the workload (from exact filtering)."""
    obs, poses, acts = workload(model, steps)
    q = filter_scheme(model, [model.live_D(0)], [[int(obs[0]), poses[0]]])[0][0]
    priors = []
    for k in range(1, steps + 1):
        priors.append(model.predict(0, q, int(acts[k - 1])))
        q = filter_scheme(model, [priors[-1]], [[int(obs[k]), poses[k]]])[0][0]
    return priors


def best_of(run) -> float:
    best = np.inf
    for _ in range(REPEATS):
        tic = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - tic)
    return best


def time_ours(scheme, model, steps: int, priors) -> tuple[float, float]:
    """(update only, predict + update) in ms per step."""
    obs, poses, acts = workload(model, steps)

    def updates():
        for k in range(1, steps + 1):
            scheme(model, [priors[k - 1]], [[int(obs[k]), poses[k]]])

    def full_steps():
        q = scheme(model, [model.live_D(0)], [[int(obs[0]), poses[0]]])[0][0]
        for k in range(1, steps + 1):
            prior = model.predict(0, q, int(acts[k - 1]))
            q = scheme(model, [prior], [[int(obs[k]), poses[k]]])[0][0]

    return 1e3 * best_of(updates) / steps, 1e3 * best_of(full_steps) / steps


def dense_gb(n: int) -> float:
    return n * n * U * 4 / 1e9  # float32, B only


def pymdp_fns():
    import equinox as eqx
    import jax.numpy as jnp

    @eqx.filter_jit
    def infer(agent, o, prior):
        return agent.infer_states([o], prior)

    @eqx.filter_jit
    def step(agent, qs, action, o):
        prior = agent.update_empirical_prior(action, qs)
        return agent.infer_states([o], prior)

    def run_infer(agent, o, prior):
        return infer(agent, jnp.array([o]), prior)

    def run_step(agent, qs, a, o):
        return step(agent, qs, jnp.array([[a]]), jnp.array([o]))

    return run_infer, run_step


def time_pymdp(model, steps: int, priors) -> tuple[float, float]:
    """(infer_states only, update_empirical_prior + infer_states) in ms per step, jitted."""
    import jax
    import jax.numpy as jnp

    from cogmap.inference import to_pymdp

    agent = to_pymdp(model)
    infer, step = pymdp_fns()
    obs, _, acts = workload(model, steps)
    jpriors = [[jnp.asarray(p, dtype=agent.D[0].dtype)[None]] for p in priors]
    jax.block_until_ready(infer(agent, int(obs[1]), jpriors[0]))  # compile

    def updates():
        out = None
        for k in range(1, steps + 1):
            out = infer(agent, int(obs[k]), jpriors[k - 1])
        jax.block_until_ready(out)

    qs0 = [x[:, None] for x in agent.D]
    jax.block_until_ready(step(agent, qs0, STAY, int(obs[0])))  # compile

    def full_steps():
        qs = step(agent, qs0, STAY, int(obs[0]))
        for k in range(1, steps + 1):
            qs = step(agent, qs, int(acts[k - 1]), int(obs[k]))
        jax.block_until_ready(qs)

    return 1e3 * best_of(updates) / steps, 1e3 * best_of(full_steps) / steps


def time_growth(n0: int, growths: int) -> tuple[float, int]:
    model = build(n0, growable=True)
    compiles = model.compile_count
    tic = time.perf_counter()
    for k in range(growths):
        model.add_state(0, pose=(float(k), -1.0))
    ms = 1e3 * (time.perf_counter() - tic) / growths
    return ms, model.compile_count - compiles


def time_pymdp_rebuild(n: int, rebuilds: int) -> float:
    import jax

    from cogmap.inference import to_pymdp

    _, step = pymdp_fns()
    total = 0.0
    for k in range(rebuilds):
        model = build(n + k)  # a new size: what pymdp sees after every growth
        tic = time.perf_counter()
        agent = to_pymdp(model)
        qs = [x[:, None] for x in agent.D]
        jax.block_until_ready(step(agent, qs, 0, 0))
        total += time.perf_counter() - tic
    return 1e3 * total / rebuilds


def main(quick: bool = False) -> None:
    try:
        import pymdp  # noqa: F401

        have_pymdp = True
    except ImportError:
        have_pymdp = False
    sizes = [25, 100, 400, 2000, 10000]
    print(f"Inference, ms per step (best of {REPEATS}); single factor, 13 controls, sparse B with "
          f"{SLOTS} slots, ~states/2 outcomes + pose evidence (pymdp: dense B, no pose)")
    print("update = posterior from a given prior (pymdp: infer_states); "
          "step = predict through B + update (pymdp: update_empirical_prior + infer_states)")
    head = (f"{'states':>7}  {'filter upd':>10}  {'fpi upd':>8}  {'pymdp upd':>26}  "
            f"{'pymdp/filter':>12}  {'pymdp/fpi':>9}  {'filter step':>11}  {'pymdp step':>10}  "
            f"{'pymdp/filter':>12}")
    print(head)
    print("-" * len(head))
    for n in sizes:
        model = build(n)
        steps = 50 if quick else (400 if n <= 2000 else 200)
        priors = predicted_priors(model, steps)
        f_upd, f_step = time_ours(filter_scheme, model, steps, priors)
        p_upd, _ = time_ours(fpi, model, steps, priors)
        cells = ["", "", "", "", ""]
        if not have_pymdp:
            cells[0] = "n/a (pymdp missing)"
        elif dense_gb(n) > DENSE_BUDGET_GB:
            cells[0] = f"n/a (dense B needs {dense_gb(n):.1f} GB)"
        else:
            m_upd, m_step = time_pymdp(model, steps, priors)
            cells = [f"{m_upd:.4f}", f"{m_upd / f_upd:.1f}x", f"{m_upd / p_upd:.1f}x",
                     f"{m_step:.4f}", f"{m_step / f_step:.1f}x"]
        print(f"{n:>7}  {f_upd:>10.4f}  {p_upd:>8.4f}  {cells[0]:>26}  {cells[1]:>12}  "
              f"{cells[2]:>9}  {f_step:>11.4f}  {cells[3]:>10}  {cells[4]:>12}", flush=True)

    growths = 200 if quick else 1000
    ms, reallocs = time_growth(25, growths)
    print()
    print(f"Growth: model.add_state, amortised over {growths} growths from 25 states "
          f"(sparse B, pose): {ms:.4f} ms per growth ({reallocs} capacity doublings)")
    if have_pymdp:
        for n in (100, 400):
            t = time_pymdp_rebuild(n, 2 if quick else 3)
            print(f"pymdp: rebuild Agent + first infer_states (recompiles) at {n} states: "
                  f"{t:.1f} ms per growth ({t / ms:.0f}x ours)", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    main(parser.parse_args().quick)
