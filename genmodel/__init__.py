"""Generative-model specifications, compilation, growth, persistence and the map graph."""

from .compile import compile
from .likelihood import DenseLikelihood, SparseLikelihood
from .model import Model, PoseModel
from .spec import Factor, InductiveSpec, Modality, ModelSpec, PoseSpec, SparseA, SparseB, SpecError, normalise
from .transitions import DenseTransitions, SparseTransitions

__all__ = [
    "DenseLikelihood",
    "DenseTransitions",
    "Factor",
    "InductiveSpec",
    "Modality",
    "Model",
    "ModelSpec",
    "PoseModel",
    "PoseSpec",
    "SparseA",
    "SparseB",
    "SparseLikelihood",
    "SparseTransitions",
    "SpecError",
    "compile",
    "normalise",
]
