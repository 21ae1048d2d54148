"""Moved to :mod:`cogmap.inference.compare` (the comparison harness lives with the inference
schemes); this module keeps the old import path working."""

from cogmap.inference.compare import Row, Sequence, compare_inference, format_table, generate_sequence, load_model

__all__ = ["Row", "Sequence", "compare_inference", "format_table", "generate_sequence", "load_model"]
