"""The hierarchical active-inference drone: agent shell, study methods and runs (its baselines are in
:mod:`cogmap.planning.drone_policies`, its voxel memory in :mod:`cogmap.genmodel.voxel_map`).

The maths lives in the libraries: suitability and binned factors in ``cogmap.genmodel``
(:mod:`~cogmap.genmodel.suitability`, :mod:`~cogmap.genmodel.drone_beliefs`), the Gaussian-kernel
belief update as the ``"kernel"`` inference scheme, waypoint generation, filtering and EFE ranking in
``cogmap.planning`` (:mod:`~cogmap.planning.drone_planner`), the field, drone, LiDAR and the
episode in ``cogmap.envs`` (:mod:`~cogmap.envs.drone_sim`, :mod:`~cogmap.envs.drone_episode`).
"""

from .agent import DroneAgent, DroneAgentConfig
from .methods import make_policy

__all__ = ["DroneAgent", "DroneAgentConfig", "make_policy"]
