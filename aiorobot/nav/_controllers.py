"""Which path-following controller the navigation server runs, and MPPI's parameters on a node.

The server's ``controller`` parameter takes a short name or the Nav2 plugin name a
``controller_server``'s ``FollowPath.plugin`` would hold:

    ``rpp``  / ``nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController`` (the default)
    ``mppi`` / ``nav2_mppi_controller::MPPIController``

MPPI's parameters are declared on the node only when it is selected, under nav2_mppi_controller's
names (``batch_size``, ``vx_max``, ``critics``, ``GoalCritic.cost_weight``, ...; Nav2 prefixes them
with the plugin's name, ``FollowPath.``, which a single-controller server does not need). So an MPPI
parameter given to a server running RPP is reported as unclaimed, as any unknown parameter is.
The goal tolerances (``xy_goal_tolerance``, ``yaw_goal_tolerance``) are shared with RPP's.
"""

from __future__ import annotations

from typing import Any

from ._mppi_parameters import MppiParameters

__all__ = ["CONTROLLERS", "controller_name", "declare_mppi_parameters"]

#: short name -> the Nav2 plugin it stands for
CONTROLLERS = {
    "rpp": "nav2_regulated_pure_pursuit_controller::RegulatedPurePursuitController",
    "mppi": "nav2_mppi_controller::MPPIController",
}


def controller_name(value: str) -> str:
    """The short name for ``value`` (a short name or a Nav2 plugin name); ValueError otherwise."""
    for short, plugin in CONTROLLERS.items():
        if value in (short, plugin):
            return short
    raise ValueError(f"parameter controller: expected one of {', '.join(CONTROLLERS)} (or the Nav2 plugin names "
                     f"{', '.join(CONTROLLERS.values())}), found {value!r}")


#: parameters a server declares already (shared with RPP's) or sets itself
_SHARED = ("xy_goal_tolerance", "yaw_goal_tolerance")


def declare_mppi_parameters(node: Any, controller_period: float) -> MppiParameters:
    """Declare MPPI's parameters on ``node`` (defaults: nav2_mppi_controller's) and return them checked.

    ``model_dt`` defaults to ``controller_period`` (Nav2's advice, and what lets the sequence shift).
    """
    values: dict[str, Any] = {}
    for name, default in MppiParameters.flat_defaults().items():
        if name == "model_dt":
            default = controller_period
        if name in _SHARED:
            values[name] = node.get_parameter(name).value
            continue
        values[name] = node.declare_parameter(name, default).value
    values["critics"] = tuple(values["critics"])
    values["controller_period"] = controller_period
    return MppiParameters.from_dict(values)
