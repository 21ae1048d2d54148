"""Moved to :mod:`cogmap.genmodel.demo_models` (the built-in models live with the
generative-model specifications); this module keeps the old import path working."""

from cogmap.genmodel.demo_models import MODELS, corridor, random_model, tmaze

__all__ = ["MODELS", "corridor", "random_model", "tmaze"]
