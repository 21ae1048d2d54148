"""cogmap.inference."""
