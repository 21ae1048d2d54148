"""Batched agent steps: cogmap's JAX backend against pymdp 1.0.4's batched ``Agent``, in one run.

For the T-maze and a 100-state grid, at batch 1, 64, 1024 and 4096: both step the same agents
(fpi with 16 sweeps, one-step policies, gamma 16, utility + state information gain) on the same
observations, drawn from the model's own generative process, and the same random controls (given
to both in place of their own choice, so ties between policies cannot send them apart); the
largest difference of the state and policy posteriors over the run is printed, and the compile
time (first two calls) is reported apart from the steady steps. At batch 1 the default
single-agent backend (the numpy ``loop``) runs the same inputs too (``numpy_steps_per_s``).
``steps_per_s`` counts agent-steps per second (batch x calls / seconds). cogmap runs twice:
with every agent holding its own copy of the model arrays, as pymdp's batched ``Agent`` does
(``cogmap_steps_per_s``, the like-for-like ratio), and as a population sharing one copy
(``cogmap_shared_steps_per_s``: ``jax_agent.population``). Float64 on both sides.

    python bench/batched.py [--steps 20] [--batches 1 64 ...] [--models tmaze grid100] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time

import jax

jax.config.update("jax_enable_x64", True)  # both sides in float64: posteriors compared to 1e-12

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

from cogmap import jax_agent, loop  # noqa: E402
from cogmap.envs import jax_worlds  # noqa: E402
from cogmap.envs.jax_worlds import grid_model, tmaze_model  # noqa: E402
from cogmap.inference import to_pymdp  # noqa: E402

BATCHES = (1, 64, 1024, 4096)
WARM = 2  # calls counted as compilation (pymdp compiles its first two calls apart)


def world_inputs(model, batch: int, steps: int, seed: int) -> list:
    """``steps`` pairs (per-modality ``(batch,)`` int outcomes, ``(batch, F)`` int controls): random
    controls, and the outcomes the model's generative process gives for them (so every agent's
    observations are possible under its model)."""
    rng = np.random.default_rng(seed)
    world = jax_worlds.world_of(model)
    keys = jax.random.split(jax.random.key(seed), (steps, batch))
    state, obs = jax.vmap(lambda k: jax_worlds.reset(world, k))(keys[0])
    move = jax.jit(jax.vmap(lambda s, a, k: jax_worlds.step(world, s, a, k)))
    out = []
    for t in range(steps):
        u = np.stack([rng.integers(0, n, size=batch) for n in model.num_controls], axis=1)
        out.append(([np.asarray(o.argmax(axis=1)) for o in obs], u))
        state, obs = move(state, jnp.asarray(u), keys[t])
    return out


def run_numpy(model, inputs):
    """The default single-agent backend (``cogmap.loop``, numpy) on batch-1 inputs."""
    agent = loop.init(model, sample=False, gamma=16.0, num_iter=16)
    trace, seconds = [], 0.0
    for k, (o, u) in enumerate(inputs):
        t0 = time.perf_counter()
        agent, info = loop.step(agent, [int(x[0]) for x in o], action=tuple(int(a) for a in u[0]))
        if k >= WARM:
            seconds += time.perf_counter() - t0
        trace.append(([q[None] for q in info.qs], info.q_pi[None]))
    return seconds, trace


def run_cogmap(model, batch: int, inputs, shared: bool):
    agent = jax_agent.build(model, sample=False, gamma=16.0, num_iter=16)
    layout = agent.config.layout
    keys = jax.random.split(jax.random.key(0), batch)
    if shared:  # one copy of the model for the whole population
        states = jax_agent.population(agent, keys)
        axes = (jax_agent.SHARED, 0)
        step = jax.jit(jax.vmap(agent.step, in_axes=axes + (0,), out_axes=axes), donate_argnums=0)
    else:  # every agent holds its own arrays (as pymdp's batched Agent does)
        states = jax.vmap(agent.init)(keys)
        step = jax.jit(jax.vmap(agent.step), donate_argnums=0)

    def one_hot(o):
        return tuple(jax.nn.one_hot(jnp.asarray(x), layout.obs_capacity[m], dtype=agent.params.arrays.D[0].dtype)
                     for m, x in enumerate(o))

    trace = []
    t0 = time.perf_counter()
    for o, u in inputs[:WARM]:
        states, info = step(states, one_hot(o), jnp.asarray(u))
        trace.append((info.qs, info.q_pi))
    jax.block_until_ready(info)
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    for o, u in inputs[WARM:]:
        states, info = step(states, one_hot(o), jnp.asarray(u))
        trace.append((info.qs, info.q_pi))
    jax.block_until_ready(info)
    return compile_s, time.perf_counter() - t0, trace


def run_pymdp(model, batch: int, inputs):
    import equinox as eqx
    from pymdp.agent import Agent
    from pymdp.envs.rollout import infer_and_plan  # the package's name `rollout` is a function
    one = to_pymdp(model, policy_len=1, gamma=16.0, num_iter=16, inference_algo="fpi",
                   action_selection="deterministic")

    def rep(xs):
        return [jnp.repeat(x, batch, axis=0) for x in xs]

    agent = Agent(rep(one.A), rep(one.B), rep(one.C), rep(one.D), A_dependencies=[list(d) for d in model.A_deps],
                  B_dependencies=[[f] for f in range(len(model.factors))], num_controls=list(model.num_controls),
                  policy_len=1, gamma=16.0, num_iter=16, inference_algo="fpi", action_selection="deterministic",
                  batch_size=batch)
    step = eqx.filter_jit(infer_and_plan)
    qs = [jnp.repeat(d, batch, axis=0)[:, None] for d in agent.D]
    key = jax.random.key(0)
    t0 = time.perf_counter()
    prev, trace = None, []
    for o, u in inputs[:WARM]:  # the first call (no previous action) and the second compile apart
        agent, action, qs, info = step(agent, qs, [jnp.asarray(x)[:, None] for x in o], prev, key)
        trace.append((qs, info["qpi"]))
        prev = jnp.asarray(u)
    jax.block_until_ready(action)
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    for o, u in inputs[WARM:]:
        agent, action, qs, info = step(agent, qs, [jnp.asarray(x)[:, None] for x in o], prev, key)
        trace.append((qs, info["qpi"]))
        prev = jnp.asarray(u)
    jax.block_until_ready(action)
    return compile_s, time.perf_counter() - t0, trace


def compare(trace_c, trace_p) -> float:
    """Largest difference of the state and policy posteriors over the run."""
    worst = 0.0
    for (qc, pc), (qp, pp) in zip(trace_c, trace_p, strict=True):
        for f, q in enumerate(qc):
            worst = max(worst, float(np.abs(np.asarray(q) - np.asarray(qp[f])[:, -1]).max()))
        worst = max(worst, float(np.abs(np.asarray(pc) - np.asarray(pp)).max()))
    return worst


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=50, help="timed calls per run (after the compiling ones)")
    ap.add_argument("--batches", type=int, nargs="*", default=list(BATCHES))
    ap.add_argument("--models", nargs="*", choices=("tmaze", "grid100"), default=["tmaze", "grid100"])
    ap.add_argument("--json", metavar="FILE", help="write the rows as JSON")
    args = ap.parse_args(argv)
    rows, numpy_rows = [], []
    print(f"{'model':>7} {'batch':>6} {'cogmap steps/s':>15} {'pymdp steps/s':>14} {'ratio':>6} "
          f"{'shared steps/s':>15} {'ratio':>6} {'compile s':>8} {'pymdp':>8} {'max |dq|':>9}")
    for name, build in (("tmaze", tmaze_model), ("grid100", grid_model)):
        if name not in args.models:
            continue
        model = build()
        for batch in args.batches:
            inputs = world_inputs(model, batch, args.steps + WARM, seed=batch)
            cc, ct, trace_c = run_cogmap(model, batch, inputs, shared=False)
            _, st, trace_s = run_cogmap(model, batch, inputs, shared=True)
            pc, pt, trace_p = run_pymdp(model, batch, inputs)
            dq = max(compare(trace_c, trace_p), compare(trace_s, trace_p))
            extra = {}
            if batch == 1:
                nt, trace_n = run_numpy(model, inputs)
                dq = max(dq, compare(trace_n, trace_p))
                extra = {"numpy_steps_per_s": args.steps / nt}
                numpy_rows.append(f"{name:>7} {args.steps / nt:>15.0f} {args.steps / pt:>14.0f} {pt / nt:>6.2f}")
            row = {"model": name, "batch": batch, "cogmap_steps_per_s": batch * args.steps / ct,
                   "pymdp_steps_per_s": batch * args.steps / pt, "cogmap_compile_s": cc, "pymdp_compile_s": pc,
                   "cogmap_shared_steps_per_s": batch * args.steps / st, "max_posterior_difference": dq, **extra}
            rows.append(row)
            print(f"{name:>7} {batch:>6} {row['cogmap_steps_per_s']:>15.0f} {row['pymdp_steps_per_s']:>14.0f} "
                  f"{pt / ct:>6.2f} {row['cogmap_shared_steps_per_s']:>15.0f} {pt / st:>6.2f} "
                  f"{cc:>8.2f} {pc:>8.2f} {dq:>9.1e}", flush=True)
    if numpy_rows:
        print("\nbatch 1, the default single-agent backend (numpy loop.step) on the same inputs:")
        print(f"{'model':>7} {'numpy steps/s':>15} {'pymdp steps/s':>14} {'ratio':>6}")
        print("\n".join(numpy_rows))
    print(f"float type: {jnp.zeros(1).dtype}; devices: {', '.join(str(d) for d in jax.devices())}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
