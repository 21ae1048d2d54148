"""Compare inference schemes on one model and one observation sequence.

``compare_inference`` runs every scheme step by step: at step ``t`` each scheme gets the
observations up to ``t`` (and the actions between them) and returns its belief about the
state at ``t``; the reference is exact Bayes on the same prefix. ``window`` limits how many
past steps each call sees (the scheme's own prediction from ``window`` steps back is then
its prior), which is how an agent uses a scheme online.

Each scheme is called once per step on the whole prefix, so the cost grows with the square of
the number of steps: :data:`MAX_STEPS` bounds it (200 steps of the T-maze take about 100 s).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from cogmap import inference
from cogmap.genmodel.numerics import TINY_FLOOR, floor_log

#: longest sequence compared (``cogmap compare-inference --steps``, ``generate_sequence``'s ``T``):
#: every scheme reruns on each prefix, so the cost grows with its square (1000 steps of the T-maze,
#: about 40 minutes)
MAX_STEPS = 1000
#: the progress bar of :func:`compare_inference` appears once the comparison has run this many seconds
PROGRESS_DELAY_S = 1.0


def _check_steps(T, what: str) -> None:
    if isinstance(T, bool) or not isinstance(T, int | np.integer) or not 1 <= T <= MAX_STEPS:
        raise ValueError(f"{what}: expected an integer in 1..{MAX_STEPS} (MAX_STEPS: the comparison's cost grows "
                         f"with the square of the steps), got {T!r}")


class Row(NamedTuple):
    """One scheme's results: ``kl`` the mean KL(exact || scheme) of the filtered beliefs over
    steps and factors (nats); ``free_energy`` the variational free energy of the whole sequence
    under the scheme's own posterior marginals (:func:`cogmap.inference.window_free_energy`, an
    upper bound on ``-log p(o_1:T)``; exact's equals it)."""

    scheme: str
    kl: float
    free_energy: float
    accuracy: float
    ms_per_step: float
    error: str = ""


@dataclass(frozen=True)
class Sequence:
    """A sampled run: ``states[t]`` per-factor true states, ``observations[t]`` per-modality
    outcome indices (plus the noisy metric pose as the last entry when the model has poses),
    ``actions[t]`` per-factor controls (``T - 1`` of them)."""

    states: np.ndarray
    observations: list
    actions: list


def _kl(p: np.ndarray, q: np.ndarray) -> float:
    nz = p > 0
    return max(0.0, float(np.sum(p[nz] * (np.log(p[nz]) - floor_log(q[nz], TINY_FLOOR)))))


def _sample(rng, p: np.ndarray) -> int:
    p = np.asarray(p, dtype=float)
    return int(min(np.searchsorted(np.cumsum(p), rng.random() * p.sum()), p.size - 1))


def generate_sequence(model, T: int, seed: int = 0) -> Sequence:
    """Sample true states, observations and uniformly random actions from ``model`` (``T`` at most
    :data:`MAX_STEPS`)."""
    _check_steps(T, "generate_sequence: T")
    rng = np.random.default_rng(seed)
    F = len(model.factors)
    s = np.array([_sample(rng, model.live_D(f)) for f in range(F)])
    states, obs, actions = [], [], []
    for t in range(T):
        if t > 0:
            u = tuple(int(rng.integers(n)) for n in model.num_controls)
            actions.append(u)
            nxt = []
            for f in range(F):
                n = model.num_states[f]
                onehot = np.zeros(n)
                onehot[s[f]] = 1.0
                col = model.predict(f, onehot, u[f])
                nxt.append(_sample(rng, col))
            s = np.array(nxt)
        states.append(s.copy())
        step = []
        for m, deps in enumerate(model.A_deps):
            col = model.live_A(m)[(slice(None),) + tuple(int(s[f]) for f in deps)]
            step.append(_sample(rng, col))
        if model.pose is not None:
            pm = model.pose
            step.append(tuple(pm.poses[s[pm.factor]] + rng.normal(0.0, pm.sigma, size=2)))
        obs.append(step)
    return Sequence(np.array(states), obs, actions)


def load_model(spec: str, rng: np.random.Generator | None = None, plugins=()):
    """A model for the comparison: a built-in name, a saved model's path, or ``module:function`` of one of
    the ``plugins`` (the modules ``cogmap --plugin`` imported; the function gets ``rng`` if it takes an
    argument). Nothing is imported here: the name only selects among those modules. Raises ValueError
    naming the problem."""
    import inspect
    import sys
    from pathlib import Path

    from cogmap.genmodel import Model
    from cogmap.genmodel.demo_models import MODELS
    from cogmap.genmodel.io import load

    if spec in MODELS:
        return MODELS[spec](rng)
    path = Path(spec)
    if path.suffix in (".npz", ".json") or path.with_suffix(".json").exists():
        return load(path)
    if ":" in spec:
        module_name, _, attr = spec.partition(":")
        module = sys.modules.get(module_name) if module_name in plugins else None
        if module is None:
            raise ValueError(f"module '{module_name}' is not a loaded plugin (from --model {spec}): "
                             f"add --plugin {module_name}")
        factory = getattr(module, attr, None)
        if not callable(factory):
            raise ValueError(f"module '{module_name}' has no function '{attr}' (from --model {spec})")
        takes_rng = bool(inspect.signature(factory).parameters)
        model = factory(rng) if takes_rng else factory()
        if not isinstance(model, Model):
            raise ValueError(f"{spec} returned {type(model).__name__}, not a compiled Model")
        return model
    raise ValueError(f"unknown model {spec!r}: use a built-in one ({', '.join(sorted(MODELS))}), "
                     "a saved model's path or module:function")


def compare_inference(
    model,
    observations,
    actions=None,
    schemes=None,
    prior=None,
    *,
    true_states=None,
    window: int | None = None,
    options: dict | None = None,
    progress: bool = False,
) -> list[Row]:
    """Run ``schemes`` (default: every registered one that accepts ``model``,
    :func:`cogmap.inference.accepting`) over the sequence; one :class:`Row` each.

    ``accuracy`` is the fraction of (step, factor) pairs whose MAP state equals
    ``true_states`` when given, else the exact MAP. Each scheme also runs once over the whole
    sequence: its free energy is that of its posterior marginals over the whole sequence.
    ``options`` maps a scheme name to keyword options for it. A scheme that refuses the model
    (for example ``filter`` on several factors) gets a row with NaNs and the error message.
    ``progress`` shows a bar on stderr (steps of every scheme) once the comparison has run
    :data:`PROGRESS_DELAY_S` seconds. The sequence has at most :data:`MAX_STEPS` steps.
    """
    from tqdm import tqdm

    names = list(inference.accepting(model)) if schemes is None else list(schemes)
    options = options or {}
    F = len(model.factors)
    prior = [model.live_D(f) for f in range(F)] if prior is None else list(prior)
    T = len(observations)
    _check_steps(T, "compare_inference: observations (steps)")
    bar = tqdm(total=T * (len(names) + 1), disable=not progress, delay=PROGRESS_DELAY_S, desc="compare-inference",
               unit="step", leave=False)
    if actions is None:
        actions = [(0,) * F] * (T - 1)
    exact_fn = inference.get("exact")
    ref = []
    bar.set_postfix_str("exact (reference)")
    for t in range(T):
        ref.append(exact_fn(model, prior, observations[: t + 1], actions[:t], smooth=False)[0])
        bar.update()
    rows = []
    for name in names:
        bar.set_postfix_str(name)
        done = bar.n
        fn = inference.get(name)
        opts = options.get(name, {})
        posts, fes, elapsed = [], [], 0.0
        try:
            for t in range(T):
                start = 0 if window is None else max(0, t - window + 1)
                if start == 0:
                    pri = prior
                else:
                    pri = inference.predict_factorised(model, posts[start - 1], actions[start - 1])
                tic = time.perf_counter()
                q, info = fn(model, pri, observations[start : t + 1], actions[start:t], **opts)
                elapsed += time.perf_counter() - tic
                posts.append([np.asarray(x) for x in q])
                fes.append(info.free_energy)
                bar.update()
        except (ValueError, KeyError) as err:
            nan = float("nan")
            rows.append(Row(name, nan, nan, nan, nan, str(err)))
            bar.update(done + T - bar.n)
            continue
        fe = _window_free_energy(fn, name, model, prior, observations, actions, opts)
        kl = np.mean([_kl(ref[t][f], posts[t][f]) for t in range(T) for f in range(F)])
        if true_states is not None:
            target = np.asarray(true_states)
        else:
            target = np.array([[int(np.argmax(r[f])) for f in range(F)] for r in ref])
        hits = [int(np.argmax(posts[t][f])) == int(target[t][f]) for t in range(T) for f in range(F)]
        rows.append(Row(name, float(kl), fe, float(np.mean(hits)), 1e3 * elapsed / T))
    bar.close()
    return rows


def _window_free_energy(fn, name, model, prior, observations, actions, opts) -> float:
    """Free energy of the whole sequence under the scheme's posterior marginals (exact Bayes:
    ``-log p(o_1:T)``, the exact posterior not being a product of marginals)."""
    q, info = fn(model, prior, observations, actions, **opts)
    if name == "exact":
        return float(info.total_free_energy)
    return inference.window_free_energy(model, prior, observations, actions, info.history)


def format_table(rows) -> str:
    """Plain-text table of :class:`Row` values."""
    head = ("scheme", "KL from exact", "F of sequence (nats)", "MAP accuracy", "ms/step")
    lines = []
    for r in rows:
        if r.error:
            lines.append((r.scheme, "n/a", "n/a", "n/a", "n/a"))
            continue
        lines.append(
            (r.scheme, f"{r.kl:.3g}", f"{r.free_energy:.4f}", f"{r.accuracy:.3f}", f"{r.ms_per_step:.3f}")
        )
    widths = [max(len(h), *(len(x[i]) for x in lines)) if lines else len(h) for i, h in enumerate(head)]
    fmt = "  ".join(f"{{:<{w}}}" if i == 0 else f"{{:>{w}}}" for i, w in enumerate(widths))
    out = [fmt.format(*head), "  ".join("-" * w for w in widths)]
    out += [fmt.format(*x) for x in lines]
    notes = [f"{r.scheme}: {r.error}" for r in rows if r.error]
    legend = [
        "KL from exact: mean KL(exact || scheme) of the filtered beliefs over steps and factors.",
        "F of sequence: variational free energy of the whole sequence under each scheme's own posterior",
        "  marginals, an upper bound on -log p(o_1:T) (lower is better); exact's equals -log p(o_1:T).",
        "MAP accuracy: fraction of (step, factor) MAP states equal to the true ones (else exact's MAP).",
    ]
    return "\n".join(out + notes + [""] + legend)
