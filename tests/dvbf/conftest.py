"""Fixtures shared by the DVBF-LM tests."""

import jax
import pytest


@pytest.fixture
def float32():
    """Run in JAX's default precision (as the studies and the command line do) even when another test
    module has switched on float64."""
    before = jax.config.jax_enable_x64
    jax.config.update("jax_enable_x64", False)
    yield
    jax.config.update("jax_enable_x64", before)
