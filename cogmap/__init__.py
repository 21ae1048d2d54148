"""cogmap: active-inference navigation toolkit."""

__version__ = "0.1.0"
