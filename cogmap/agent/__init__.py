"""The AIMAPP agent: state and pose inference, map growth, planning, drift correction and the
swappable observation encoder (the shell over :mod:`cogmap.genmodel`, :mod:`cogmap.inference`
and :mod:`cogmap.planning`)."""
