"""cogmap: active-inference navigation toolkit.

Libraries: :mod:`cogmap.genmodel` (specs, compilation, demo models, shared numerics),
:mod:`cogmap.inference` (schemes, learning, reduction, the comparison harness),
:mod:`cogmap.planning` (EFE, policies, MCTS), :mod:`cogmap.envs` (simulated rooms).
Shells: :mod:`cogmap.loop` (an agent for any compiled model), :mod:`cogmap.agent` (AIMAPP),
:mod:`cogmap.harness` (the episode loop every policy runs in), :mod:`cogmap.baselines`,
:mod:`cogmap.explore` / :mod:`cogmap.goal` (AIMAPP runs), :mod:`cogmap.study`,
:mod:`cogmap.drone`, :mod:`cogmap.cli`.
"""

__version__ = "0.1.0"
