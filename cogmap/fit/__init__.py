"""Fit agents to behaviour on the JAX backend: likelihood of choices, MAP, NUTS and model comparison.

    from cogmap import fit, jax_agent
    from cogmap.envs import jax_worlds

    agent = jax_agent.build(jax_worlds.tmaze_model(), policy_len=2, gamma=2.0)
    free = [fit.Free("gamma", fit.LogNormal(0.7, 0.6))]
    data = fit.simulate_subjects(fit.Candidate("efe", agent, free), jax_worlds.tmaze_world(), key,
                                 true_values, trials=100, steps=2)
    fit.fit_map(agent, free, data).values          # (subjects, parameters)
    fit.fit_nuts(agent, free, data, key)            # draws, R-hat, ESS, per-subject summaries
    fit.compare([cand_a, cand_b], data).winner      # Laplace log evidence per subject

:mod:`~cogmap.fit.likelihood` (data, free parameters, priors, the likelihood),
:mod:`~cogmap.fit.map` (MAP with optax), :mod:`~cogmap.fit.nuts` (blackjax NUTS, group-level
priors) and :mod:`~cogmap.fit.compare` (Laplace evidence, model recovery).
"""

from .compare import Candidate, Comparison, compare, confusion, laplace_evidence, simulate_subjects
from .likelihood import (
    Behaviour,
    Free,
    LogNormal,
    Normal,
    apply,
    check_free,
    log_likelihood,
    log_posterior,
    log_prior,
    simulate,
    unconstrained,
    values,
)
from .map import MAPResult, fit_map
from .nuts import PosteriorResult, fit_nuts

__all__ = ["Behaviour", "Candidate", "Comparison", "Free", "LogNormal", "MAPResult", "Normal", "PosteriorResult",
           "apply", "check_free", "compare", "confusion", "fit_map", "fit_nuts", "laplace_evidence",
           "log_likelihood", "log_posterior", "log_prior", "simulate", "simulate_subjects", "unconstrained",
           "values"]
