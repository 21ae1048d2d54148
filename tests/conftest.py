"""Suite-wide settings: a JAX compilation cache shared by the workers, and files holding a test marked
``heavy`` run first.

The suite runs on two workers, one file at a time each (``--dist loadfile``); starting the longest files
first keeps one worker from being left with a long file at the end while the other idles. Many tests
compile the same functions (in both workers and in the child processes of the studies they run): the
persistent cache in pytest's cache directory compiles each once. It stores what XLA compiled, so results
are the same with or without it.
"""

import os
from pathlib import Path

import pytest

_JAX_CACHE = Path(__file__).resolve().parents[1] / ".pytest_cache" / "jax-compilation"
os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", str(_JAX_CACHE))  # read when jax is imported, here
os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "0.1")  # and by the child processes


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    heavy_files = {item.path for item in items if item.get_closest_marker("heavy") is not None}
    items.sort(key=lambda item: item.path not in heavy_files)  # stable: order within a file is kept


@pytest.fixture
def registered(request):
    """The names a test registers (it appends them); each is removed after the test with its
    module's ``UNREGISTER`` function."""
    names = []
    yield names
    for name in names:
        request.module.UNREGISTER(name)


class _CompiledPymdp:
    """pymdp 1.0 Agent methods compiled once (``equinox.filter_jit``), called with the agent first:
    pymdp's own code, without a retrace at every call."""

    def __init__(self):
        import equinox as eqx

        self.infer_states = eqx.filter_jit(lambda ag, o, p: ag.infer_states(o, p))
        self.infer_policies = eqx.filter_jit(lambda ag, q: ag.infer_policies(q))
        self.sample_action = eqx.filter_jit(lambda ag, q, k: ag.sample_action(q, rng_key=k))
        self.update_empirical_prior = eqx.filter_jit(lambda ag, a, q: ag.update_empirical_prior(a, q))


@pytest.fixture
def pymdp_jit():
    """:class:`_CompiledPymdp` for tests that step a pymdp Agent through an episode."""
    pytest.importorskip("equinox")
    return _CompiledPymdp()
