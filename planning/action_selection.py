"""From the policy posterior to a control: habits, action precision and the two sampling modes.

``q(pi) = softmax(ln E - gamma G)`` (:func:`~.policies.policy_posterior`; ``E`` the habits).
The control of the next step is then drawn, with action precision ``alpha``, in one of two ways
(pymdp 1.0's ``sampling_mode``):

* ``"policy"``: a policy from ``softmax(alpha ln q(pi))`` and its first step (pymdp's ``"full"``;
  with ``alpha = 1`` this is ``q(pi)`` itself, the AIMAPP agent's choice);
* ``"marginal"``: each factor's control from ``softmax(alpha ln q(u_f))``, ``q(u_f)`` the
  marginal of ``q(pi)`` over the policies whose first step has ``u_f`` (pymdp's default,
  ``control.sample_action``; SPM's ``spm_MDP_VB_X`` draws ``u ~ softmax(alpha ln P(u))`` too).

A deterministic agent takes the mode instead: the most probable policy's first step, or each
factor's most probable control. :func:`control_probabilities` is the distribution a sampling
agent draws from, over every combination of first-step controls: the likelihood of a subject's
choice.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cogmap.genmodel.numerics import floor_log, softmax

SAMPLING = ("policy", "marginal")


def check_selection(alpha, sampling: str) -> float:
    """Validated action precision (a finite positive number) for ``sampling`` in :data:`SAMPLING`."""
    if sampling not in SAMPLING:
        raise ValueError(f"sampling must be one of {', '.join(SAMPLING)}, got {sampling!r}")
    if isinstance(alpha, bool) or not isinstance(alpha, int | float | np.integer | np.floating) \
            or not np.isfinite(alpha) or alpha <= 0:
        raise ValueError(f"alpha (action precision) must be a finite positive number, got {alpha!r}")
    return float(alpha)


def check_habits(E, num_policies: int) -> np.ndarray:
    """``ln E`` of habits ``E``: ``(num_policies,)`` finite positive weights, normalised here."""
    arr = np.asarray(E, dtype=float) if not isinstance(E, str | bytes) else None
    if arr is None or arr.ndim != 1 or arr.shape[0] != num_policies:
        raise ValueError(f"E (habits) must be a vector of {num_policies} weights, one per policy, "
                         f"got {np.shape(E) if arr is not None else type(E).__name__}")
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError("E (habits) must be finite and positive")
    return np.log(arr / arr.sum())


def marginals(q_pi: np.ndarray, policies: np.ndarray, num_controls: Sequence[int]) -> list[np.ndarray]:
    """Per factor, ``(num_controls[f],)`` marginal of ``q_pi`` over the first-step controls."""
    return [np.bincount(policies[:, 0, f], weights=q_pi, minlength=int(n)) for f, n in enumerate(num_controls)]


def control_probabilities(q_pi: np.ndarray, policies: np.ndarray, num_controls: Sequence[int],
                          alpha: float = 1.0, sampling: str = "policy") -> np.ndarray:
    """Probability of each first-step control combination, shaped ``num_controls``.

    Parameters
    ----------
    q_pi : numpy.ndarray
        ``(P,)`` float policy posterior.
    policies : numpy.ndarray
        ``(P, T, F)`` int policies.
    num_controls : sequence of int
        Controls per factor.
    alpha : float, optional
        Action precision, default 1.
    sampling : str, optional
        ``"policy"`` (default) or ``"marginal"`` (see the module docstring).

    Returns
    -------
    numpy.ndarray
        Float, sums to 1.
    """
    shape = tuple(int(u) for u in num_controls)
    if sampling == "marginal":
        out = np.ones(())
        for m in marginals(q_pi, policies, shape):  # factors drawn independently
            out = np.multiply.outer(out, softmax(alpha * floor_log(m)))
        return out
    w = q_pi if alpha == 1.0 else softmax(alpha * floor_log(q_pi))
    idx = np.ravel_multi_index(tuple(policies[:, 0, f] for f in range(len(shape))), shape)
    return np.bincount(idx, weights=w, minlength=int(np.prod(shape))).reshape(shape)


def select_action(q_pi: np.ndarray, policies: np.ndarray, num_controls: Sequence[int], alpha: float = 1.0,
                  sampling: str = "policy", rng: np.random.Generator | None = None) -> np.ndarray:
    """The first-step controls to apply: drawn with ``rng``, else the mode (see the module docstring).

    Parameters
    ----------
    q_pi, policies, num_controls, alpha, sampling
        As for :func:`control_probabilities`.
    rng : numpy.random.Generator, optional
        Sample when given; without it take the most probable policy (``"policy"``) or each
        factor's most probable control (``"marginal"``), the first on ties.

    Returns
    -------
    numpy.ndarray
        ``(F,)`` int controls.
    """
    if sampling == "marginal":
        if rng is None:
            return np.array([int(np.argmax(m)) for m in marginals(q_pi, policies, num_controls)])
        p = control_probabilities(q_pi, policies, num_controls, alpha, sampling)
        return np.array(np.unravel_index(int(rng.choice(p.size, p=p.ravel())), p.shape))
    if rng is None:
        return policies[int(np.argmax(q_pi)), 0].copy()
    w = q_pi if alpha == 1.0 else softmax(alpha * floor_log(q_pi))
    return policies[int(rng.choice(len(w), p=w)), 0].copy()
