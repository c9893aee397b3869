"""Navigation: costmaps, planning, Regulated Pure Pursuit, AMCL localisation (pure cores).

Cores follow Nav2's definitions and parameter names (nav2_costmap_2d, NavFn/Smac 2D,
nav2_regulated_pure_pursuit_controller, nav2_amcl) on numpy arrays, with Numba kernels where
they loop; they are tested without a runtime.
"""

from __future__ import annotations

from ._amcl import Amcl, AmclParameters, likelihood_field
from ._costmap import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap,
    inflation_cost,
)
from ._maps import MapError, OccupancyMap, load_map, save_map
from ._planner import Plan, PlanError, PlanFailure, plan
from ._amcl_node import AmclNode
from ._geometry import pose_stamped
from ._landmark_map import (
    LANDMARK_MAP_SUFFIX,
    LandmarkMap,
    LandmarkMapError,
    MarkerPlace,
    landmark_map_path,
    load_landmark_map,
    save_landmark_map,
)
from ._landmarks import LandmarkFixNode, base_pose_from_marker, base_pose_from_markers, map_from_marker
from ._lifecycle_manager import LifecycleManager, ManagedState
from ._map_server import MapServer
from ._mapping import MappingNode, OccupancyMapper
from ._navigation_server import NavigationFailure, NavigationServer, NavigationStatistics
from ._navigator import Navigator, TaskResult
from ._rpp import RegulatedPurePursuit, RppCommand, RppParameters

__all__ = [
    "AmclNode",
    "LandmarkFixNode",
    "LANDMARK_MAP_SUFFIX",
    "LandmarkMap",
    "LandmarkMapError",
    "MarkerPlace",
    "landmark_map_path",
    "load_landmark_map",
    "save_landmark_map",
    "base_pose_from_marker",
    "base_pose_from_markers",
    "map_from_marker",
    "LifecycleManager",
    "ManagedState",
    "MapServer",
    "MappingNode",
    "OccupancyMapper",
    "NavigationFailure",
    "NavigationServer",
    "NavigationStatistics",
    "Navigator",
    "TaskResult",
    "pose_stamped",
    "Amcl",
    "AmclParameters",
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "MapError",
    "NO_INFORMATION",
    "OccupancyMap",
    "Costmap",
    "Plan",
    "PlanError",
    "PlanFailure",
    "RegulatedPurePursuit",
    "RppCommand",
    "RppParameters",
    "inflation_cost",
    "likelihood_field",
    "load_map",
    "plan",
    "save_map",
]
