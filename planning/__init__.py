"""cogmap.planning."""
