"""Online SLAM with DVBF-LM (paper Section IV): one pass over a traversal, filtering poses with the
particle filter under the current map belief while the ELBO trains q(M) and the emission network.

Per step ``t``: the filter resamples, moves its particles through the engineered transition with the
commanded control and weights them by ``p(x_t | z, M_hat)`` at the map mean ``M_hat``; the resampled
particles are cached for step ``t`` (the asynchronous particle representation, III-D2). Every
``train_every`` steps, ``train_iters`` Adam steps on the ELBO (Eq. 3) use random time steps seen so far,
each with its cached particles. The initial pose is known (the paper's ``rho(z_1)``).

This module is the stateful shell; the mathematics lives in ``genmodel.dvbf``, ``inference.particle_filter``
and ``inference.elbo``.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from cogmap.genmodel.dvbf import DVBFConfig
from cogmap.genmodel.numerics import wrap_angle


@dataclass(frozen=True)
class SLAMConfig:
    """Online-SLAM settings. ``pf_sigma``: per-beam std used to weight particles (the paper's offline
    filter uses a sharper std than the training emission, Appendix B-I); ``cache``: cached particles
    per step used by training; ``marginal``: weight particles by the likelihood with the map's
    uncertainty carried to first order (:func:`~cogmap.genmodel.dvbf.log_likelihood_marginal`) rather
    than at the map mean alone; ``recent``: share of each training batch drawn from the last
    ``recent_window`` steps, so the map where the agent is now is learnt before the filter leans on it;
    ``freeze_emission``: keep the starting emission network fixed and learn only q(M).

    Attributes
    ----------
    n_particles : int
        Particles of the filter.
    pf_sigma : float
        Per-beam std (in the emission's range units) used to weight particles (Appendix B).
    train_every : int
        Steps filtered between two training rounds (the chunk length).
    train_iters : int
        Adam steps on the ELBO (Eq. 3) after each chunk.
    batch : int
        Time steps per ELBO batch.
    cache : int
        Resampled particles kept per step for training (asynchronous particles, III-D2).
    learning_rate : float
        Adam learning rate.
    init_std : tuple of float
        Std of the initial particles around the known start: (x m, y m, yaw rad).
    model : DVBFConfig
        The DVBF-LM model (map grid, emission, transition noise).
    marginal : bool
        Weight particles by the map-marginal likelihood instead of the map mean.
    recent : float
        Share in [0, 1] of each training batch drawn from the last ``recent_window`` steps.
    recent_window : int
        Length in steps of that recent window.
    freeze_emission : bool
        Keep the starting emission network fixed.
    seed : int
        Seed of the filter's and training's random numbers.
    """

    n_particles: int = 20
    pf_sigma: float = 0.05
    train_every: int = 10
    train_iters: int = 20
    batch: int = 32
    cache: int = 8
    learning_rate: float = 1e-2
    init_std: tuple[float, float, float] = (0.001, 0.001, 0.005)
    model: DVBFConfig = field(default_factory=DVBFConfig)
    marginal: bool = True
    recent: float = 0.75
    recent_window: int = 100
    freeze_emission: bool = False
    seed: int = 0

    def to_json(self) -> dict:
        """The settings as a JSON-ready dict (``model`` nested as a dict).

        Returns
        -------
        dict
            Field name -> value.
        """
        d = asdict(self)
        d["model"] = asdict(self.model)
        return d


@dataclass
class SLAMResult:
    """What :func:`online_slam` returns.

    Attributes
    ----------
    estimates : numpy.ndarray, shape (T, 3)
        Weighted particle mean per step: (x m, y m, yaw rad).
    spreads : numpy.ndarray, shape (T, 3)
        Weighted particle std per step, same units.
    particles : numpy.ndarray, shape (n_particles, 3)
        The filter's particles at the last step.
    params : DVBFParams
        q(M) and the emission network after the last training step.
    losses : numpy.ndarray, shape (n_train_steps,)
        Negative ELBO (Eq. 3) of each training step.
    seconds : float
        Wall-clock time of the run (not counting construction).
    """

    estimates: np.ndarray  # (T, 3) weighted particle mean per step
    spreads: np.ndarray  # (T, 3) weighted particle std per step
    particles: np.ndarray  # (n_particles, 3) at the last step
    params: object  # DVBFParams after the last training step
    losses: np.ndarray  # negative ELBO of each training step
    seconds: float


def path_integration(start, controls) -> np.ndarray:
    """Poses ``(T, 3)`` from dead reckoning with the engineered transition mean (no map).

    The control is applied as "turn, then drive": ``yaw += u[0]``, then move ``u[1]`` along the
    new heading (``genmodel.dvbf.kinematic_mean``, the transition without its noise).

    Parameters
    ----------
    start : array_like, shape (3,)
        Initial pose (x m, y m, yaw rad).
    controls : array_like, shape (T - 1, 2)
        Per step (turn in rad, forward distance in m).

    Returns
    -------
    numpy.ndarray, shape (T, 3)
        ``start`` followed by the integrated poses, yaw wrapped to [-pi, pi).
    """
    poses = [np.asarray(start, float)]
    for u in np.asarray(controls, float):
        x, y, a = poses[-1]
        a = a + u[0]
        poses.append(np.array([x + u[1] * np.cos(a), y + u[1] * np.sin(a), wrap_angle(a)]))
    return np.array(poses)


def fit_known_poses(poses, scans, cfg: DVBFConfig, iters: int = 1500, batch: int = 32,
                    learning_rate: float = 1e-2, seed: int = 0, emission=None):
    """q(M) and the emission network fit by the ELBO to a traversal with known poses (each time step's
    only particle is its true pose). With ``emission`` given, that network is kept fixed and only q(M)
    is learnt.

    Parameters
    ----------
    poses : array_like, shape (T, 3)
        True pose per step (x m, y m, yaw rad).
    scans : array_like, shape (T, n_beams)
        Range scan per step.
    cfg : DVBFConfig
        The model.
    iters : int
        Adam steps on the ELBO (Eq. 3).
    batch : int
        Time steps per batch, drawn uniformly.
    learning_rate : float
        Adam learning rate.
    seed : int
        Seed of the initial parameters and the batches.
    emission : optional
        A fixed emission network; if given, only q(M) is learnt.

    Returns
    -------
    params : DVBFParams
        The fitted q(M) and emission.
    losses : numpy.ndarray, shape (iters,)
        Negative ELBO of each step.
    """
    import jax
    import jax.numpy as jnp

    from cogmap.inference.elbo import Batch, init_opt_state, init_params, make_optimizer, make_train_step

    poses, scans = jnp.asarray(np.asarray(poses, float))[:, None, :], jnp.asarray(np.asarray(scans, float))
    params = init_params(cfg, jax.random.PRNGKey(seed))
    if emission is not None:
        params = params._replace(emission=emission)
    opt = make_optimizer(learning_rate)
    state = init_opt_state(opt, params)
    step = make_train_step(cfg, opt, scans.shape[0])
    rng = np.random.default_rng(seed)
    losses = []
    for i in range(iters):
        idx = rng.integers(0, scans.shape[0], batch)
        new, state, terms = step(params, state, jax.random.PRNGKey(i), Batch(poses[idx], scans[idx]))
        params = new if emission is None else new._replace(emission=emission)
        losses.append(float(terms.loss))
    return params, np.array(losses)


def pretrain_emission(poses, scans, cfg: DVBFConfig, iters: int = 1500, batch: int = 32,
                      learning_rate: float = 1e-2, seed: int = 0):
    """Emission network trained (with a map of its own, then discarded) on a traversal with known
    poses, such as a first maze that is not used for evaluation (the paper pretrains its transition
    this way, Section IV).

    Parameters
    ----------
    poses, scans, cfg, iters, batch, learning_rate, seed
        As in :func:`fit_known_poses`.

    Returns
    -------
    emission
        The trained emission network.
    losses : numpy.ndarray, shape (iters,)
        Negative ELBO of each step.
    """
    params, losses = fit_known_poses(poses, scans, cfg, iters, batch, learning_rate, seed)
    return params.emission, losses


@functools.lru_cache(maxsize=8)
def _compiled(config: SLAMConfig, capacity: int):
    """Optimizer, jitted ELBO step and jitted filter chunk of one configuration, shared by every
    :class:`OnlineSLAM` with it, so a process compiles them once (compiling is most of a short run)."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    from cogmap.genmodel.dvbf import log_likelihood, log_likelihood_marginal, transition_sample
    from cogmap.inference.elbo import make_optimizer, make_train_step
    from cogmap.inference.particle_filter import pf_run, weighted_moments

    cfg = config.model
    opt = make_optimizer(config.learning_rate)
    train_step = make_train_step(cfg, opt, capacity)
    sigma_t = jnp.asarray(cfg.sigma_t)

    @eqx.filter_jit
    def filter_chunk(key, state, us, xs, emission, q_map):
        """``len(us)`` filter steps in one compiled scan; returns cached particles and moments."""

        def lik(z, obs):
            if config.marginal:
                return log_likelihood_marginal(emission, q_map, z, obs, cfg, sigma=config.pf_sigma)
            return log_likelihood(emission, q_map.mean, z, obs, cfg, sigma=config.pf_sigma)

        def trans(k, z, ctrl):
            return transition_sample(k, z, ctrl, sigma_t)

        def record(k, s):  # a sample of the filtered particles (for training) and their moments
            idx = jax.random.choice(jax.random.fold_in(k, 7), s.particles.shape[0], (config.cache,),
                                    p=jnp.exp(s.log_weights))
            mean, std = weighted_moments(s)
            return s.particles[idx], mean, std

        return pf_run(key, state, us, xs, trans, lik, record=record)

    return opt, train_step, filter_chunk


class OnlineSLAM:
    """The online-SLAM loop as a stepper: :meth:`advance` filters new steps in chunks of
    ``train_every`` and trains the ELBO after each chunk. :func:`online_slam` runs it over a recorded
    traversal; the exploration agent (:mod:`cogmap.dvbf.explore`) feeds it step by step.

    ``capacity``: the most steps that will be seen (scales the ELBO's reconstruction term, Eq. 3, and
    sizes the buffers). ``emission``: an emission network to start from (for example one trained on a
    first maze, as the paper pretrains its transition); by default a freshly initialised one. The map
    always starts at the prior; the initial pose ``start`` is known.

    Parameters
    ----------
    start : array_like, shape (3,)
        Known initial pose (x m, y m, yaw rad); particles start around it with ``config.init_std``.
    config : SLAMConfig
        Filter and training settings.
    capacity : int
        The most steps that will be seen, including the first.
    emission : optional
        Emission network to start from.
    first_scan : array_like, shape (n_beams,), optional
        The scan at ``start`` (step 0), used by training.

    Attributes
    ----------
    params : DVBFParams
        Current q(M) and emission.
    estimates, spreads : numpy.ndarray, shape (capacity, 3)
        Weighted particle mean and std per filtered step.
    losses : list of float
        Negative ELBO of each training step so far.
    t : int
        Index of the last filtered step.
    """

    def __init__(self, start, config: SLAMConfig, capacity: int, emission=None, first_scan=None):
        import jax
        import jax.numpy as jnp

        from cogmap.inference.elbo import init_opt_state, init_params
        from cogmap.inference.particle_filter import pf_init

        self.config = config
        cfg = config.model
        self.capacity = int(capacity)
        key = jax.random.PRNGKey(config.seed)
        self.key, k_init, k_part = jax.random.split(key, 3)
        params = init_params(cfg, k_init)
        if emission is not None:
            params = params._replace(emission=emission)
        self.params = params
        # the seed is used only here, not inside the compiled functions: runs of other seeds share them
        self._opt, self._train_step, self._filter_chunk = _compiled(dataclasses.replace(config, seed=0), self.capacity)
        self.opt_state = init_opt_state(self._opt, params)
        particles = jnp.asarray(start, float) + jnp.asarray(config.init_std) * jax.random.normal(
            k_part, (config.n_particles, 3))
        self.state = pf_init(particles)
        T = self.capacity
        self.cache = np.zeros((T, config.cache, 3), np.float32)
        self.cache[0] = np.asarray(particles[: config.cache])
        self.scans = np.zeros((T, cfg.n_beams), np.float32)
        if first_scan is not None:
            self.scans[0] = np.asarray(first_scan, float)
        self.estimates, self.spreads = np.zeros((T, 3)), np.zeros((T, 3))
        self.estimates[0] = np.asarray(start, float)
        self.spreads[0] = np.asarray(config.init_std)
        self.losses: list[float] = []
        self.t = 0  # index of the last step filtered
        self._rng = np.random.default_rng(config.seed)
        self._pending_u: list[np.ndarray] = []
        self._pending_x: list[np.ndarray] = []

    @property
    def particles(self) -> np.ndarray:
        """The filter's current particles, shape (n_particles, 3): (x m, y m, yaw rad)."""
        return np.asarray(self.state.particles)

    @property
    def estimate(self) -> np.ndarray:
        """Weighted particle mean at the last filtered step (pending steps not yet included)."""
        return self.estimates[self.t]

    def advance(self, controls, scans, flush: bool = False) -> None:
        """Queue steps (``controls (n, 2)`` leading to ``scans (n, n_beams)``); every full chunk of
        ``train_every`` steps is filtered and followed by ``train_iters`` ELBO steps. ``flush`` also
        processes a last, shorter chunk.

        Parameters
        ----------
        controls : array_like, shape (n, 2) or (2,)
            Per step (turn rad, forward m).
        scans : array_like, shape (n, n_beams) or (n_beams,)
            The scan observed after each control.
        flush : bool
            Also filter and train on a last chunk shorter than ``train_every``.

        Raises
        ------
        ValueError
            If ``controls`` and ``scans`` differ in length, or the steps exceed ``capacity``.
        """
        for u, x in zip(np.atleast_2d(controls), np.atleast_2d(scans), strict=True):
            self._pending_u.append(np.asarray(u, float))
            self._pending_x.append(np.asarray(x, float))
            if len(self._pending_u) == self.config.train_every:
                self._chunk()
        if flush and self._pending_u:
            self._chunk()

    def flush(self) -> None:
        """Filter (and train after) the steps queued since the last full chunk."""
        if self._pending_u:
            self._chunk()

    def _chunk(self) -> None:
        import jax
        import jax.numpy as jnp

        from cogmap.inference.elbo import Batch

        config, t = self.config, self.t
        n = len(self._pending_u)
        if t + n >= self.capacity:
            raise ValueError(f"OnlineSLAM: more than capacity = {self.capacity} steps")
        us, xs = np.array(self._pending_u), np.array(self._pending_x)
        self._pending_u, self._pending_x = [], []
        self.key, k = jax.random.split(self.key)
        self.state, (cached, mean, std) = self._filter_chunk(k, self.state, jnp.asarray(us), jnp.asarray(xs),
                                                             self.params.emission, self.params.q_map)
        self.scans[t + 1:t + 1 + n] = xs
        self.cache[t + 1:t + 1 + n] = np.asarray(cached)
        self.estimates[t + 1:t + 1 + n], self.spreads[t + 1:t + 1 + n] = np.asarray(mean), np.asarray(std)
        t = self.t = t + n
        scans = self.scans
        for _ in range(config.train_iters):
            n_recent = int(round(config.recent * config.batch))
            idx = np.concatenate([self._rng.integers(max(0, t + 1 - config.recent_window), t + 1, n_recent),
                                  self._rng.integers(0, t + 1, config.batch - n_recent)])
            self.key, k = jax.random.split(self.key)
            new, self.opt_state, terms = self._train_step(self.params, self.opt_state, k,
                                                          Batch(jnp.asarray(self.cache[idx]),
                                                                jnp.asarray(scans[idx])))
            self.params = new._replace(emission=self.params.emission) if config.freeze_emission else new
            self.losses.append(float(terms.loss))


def online_slam(scans, controls, start, config: SLAMConfig, progress=None, emission=None) -> SLAMResult:
    """Run online SLAM on ``scans (T, n_beams)`` and ``controls (T - 1, 2)`` from the known ``start``
    (:class:`OnlineSLAM` over a recorded traversal).

    ``emission``: an emission network to start from (for example one trained on a first maze, as
    the paper pretrains its transition); by default a freshly initialised one. The map always starts
    at the prior.

    Parameters
    ----------
    scans : array_like, shape (T, n_beams)
        Range scan per step.
    controls : array_like, shape (T - 1, 2)
        Control (turn rad, forward m) leading from step ``t`` to ``t + 1``.
    start : array_like, shape (3,)
        Known initial pose (x m, y m, yaw rad).
    config : SLAMConfig
        Filter and training settings.
    progress : callable, optional
        Called with the number of steps filtered after each chunk.
    emission : optional
        Emission network to start from.

    Returns
    -------
    SLAMResult
        Per-step estimates and spreads, final particles and parameters, losses and run time.

    Raises
    ------
    ValueError
        If there are not exactly ``T - 1`` controls.
    """
    scans = np.asarray(scans, float)
    controls = np.asarray(controls, float)
    T = scans.shape[0]
    if controls.shape[0] != T - 1:
        raise ValueError(f"online_slam: {controls.shape[0]} controls for {T} scans (need T - 1)")
    slam = OnlineSLAM(start, config, T, emission=emission, first_scan=scans[0])
    tic = time.perf_counter()
    t = 0
    while t < T - 1:
        n = min(config.train_every, T - 1 - t)
        slam.advance(controls[t:t + n], scans[t + 1:t + 1 + n], flush=True)
        t += n
        if progress is not None:
            progress(t)
    return SLAMResult(slam.estimates, slam.spreads, slam.particles, slam.params, np.array(slam.losses),
                      time.perf_counter() - tic)
