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

from cogmap.compare import generate_sequence
from cogmap.genmodel import Factor, Modality, ModelSpec, PoseSpec, SparseB, compile
from cogmap.inference import filter as filter_scheme
from cogmap.inference import fpi

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


def time_ours(scheme, model, steps: int) -> float:
    obs, poses, acts = workload(model, steps)
    best = np.inf
    for _ in range(REPEATS):
        q = scheme(model, [model.live_D(0)], [[int(obs[0]), poses[0]]])[0][0]
        tic = time.perf_counter()
        for k in range(1, steps + 1):
            prior = model.predict(0, q, int(acts[k - 1]))
            q = scheme(model, [prior], [[int(obs[k]), poses[k]]])[0][0]
        best = min(best, time.perf_counter() - tic)
    return 1e3 * best / steps


def dense_gb(n: int) -> float:
    return n * n * U * 4 / 1e9  # float32, B only


def pymdp_step_fn():
    import equinox as eqx
    import jax.numpy as jnp

    @eqx.filter_jit
    def step(agent, qs, action, o):
        prior = agent.update_empirical_prior(action, qs)
        return agent.infer_states([o], prior)

    def run(agent, qs, a, o):
        return step(agent, qs, jnp.array([[a]]), jnp.array([o]))

    return run


def time_pymdp(model, steps: int) -> float:
    import jax

    from cogmap.inference import to_pymdp

    agent = to_pymdp(model)
    step = pymdp_step_fn()
    obs, _, acts = workload(model, steps)
    best = np.inf
    for _ in range(REPEATS):
        qs = [x[:, None] for x in agent.D]
        qs = step(agent, qs, STAY, int(obs[0]))  # compiles on the first repeat
        jax.block_until_ready(qs)
        tic = time.perf_counter()
        for k in range(1, steps + 1):
            qs = step(agent, qs, int(acts[k - 1]), int(obs[k]))
        jax.block_until_ready(qs)
        best = min(best, time.perf_counter() - tic)
    return 1e3 * best / steps


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

    step = pymdp_step_fn()
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
    print(f"Inference step (predict + update), ms per step (best of {REPEATS}); single factor, 13 controls, "
          f"sparse B with {SLOTS} slots, ~states/2 outcomes + pose evidence")
    head = f"{'states':>7}  {'filter':>8}  {'fpi':>8}  {'pymdp':>24}  {'pymdp/filter':>12}  {'pymdp/fpi':>9}"
    print(head)
    print("-" * len(head))
    for n in sizes:
        model = build(n)
        steps = 50 if quick else (400 if n <= 2000 else 200)
        t_filter = time_ours(filter_scheme, model, steps)
        t_fpi = time_ours(fpi, model, steps)
        if not have_pymdp:
            pm, r1, r2 = "n/a (pymdp missing)", "", ""
        elif dense_gb(n) > DENSE_BUDGET_GB:
            pm, r1, r2 = f"n/a (dense B needs {dense_gb(n):.1f} GB)", "", ""
        else:
            t_pm = time_pymdp(model, steps)
            pm, r1, r2 = f"{t_pm:.4f}", f"{t_pm / t_filter:.1f}x", f"{t_pm / t_fpi:.1f}x"
        print(f"{n:>7}  {t_filter:>8.4f}  {t_fpi:>8.4f}  {pm:>24}  {r1:>12}  {r2:>9}", flush=True)

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
