"""DVBF-LM agent layer: online SLAM in the LiDAR mazes and its run directory (``cogmap dvbf slam``).

Needs the ``dvbf`` extra (equinox, optax); jax and equinox are imported when a run starts.
"""
