"""A navigation node's costmap filters: Nav2's ``filters`` parameters, their info and mask topics.

Parameters as a Nav2 costmap's::

    filters: ["keepout_filter", "speed_filter"]
    keepout_filter: {plugin: "nav2_costmap_2d::KeepoutFilter", filter_info_topic: "keepout_filter_info",
                     override_lethal_cost: true, lethal_override_cost: 200}
    speed_filter: {plugin: "nav2_costmap_2d::SpeedFilter", filter_info_topic: "speed_filter_info",
                   speed_limit_topic: "speed_limit"}

Each filter subscribes to its nav2_msgs/CostmapFilterInfo (transient local, as Nav2's
costmap_filter_info_server publishes it), then to the OccupancyGrid mask the info names. The
keepout mask goes into the costmap as a layer (:meth:`Costmap.set_keepout`); with
``override_lethal_cost``, while the robot stands in a lethal part of the zone the zone's cells cost
``lethal_override_cost`` instead (at most 252), so it can plan its way out (Nav2's). The speed filter
gives the limit at the robot's position and publishes a nav2_msgs/SpeedLimit when it changes.
"""

from __future__ import annotations

from typing import Any

from ._costmap import FREE_SPACE, INSCRIBED_INFLATED_OBSTACLE, NO_INFORMATION, Costmap
from ._filters import NO_SPEED_LIMIT, FilterType, SpeedLimitFilter, keepout_cost_at, keepout_layer
from ._map_server import MAP_QOS
from ._maps import OccupancyMap

__all__ = ["FilterInputs"]

_PLUGINS = {"nav2_costmap_2d::KeepoutFilter": (FilterType.KEEPOUT_FILTER,),
            "nav2_costmap_2d::SpeedFilter": (FilterType.SPEED_FILTER_PERCENT, FilterType.SPEED_FILTER_ABSOLUTE)}


#: nav2_costmap_2d's MAX_NON_OBSTACLE: the highest cost that is not an obstacle
_MAX_NON_OBSTACLE = 252


class FilterInputs:
    """The filters a node's ``filters`` parameter names; :attr:`keepout` and :attr:`speed` once their masks arrived."""

    def __init__(self, node: Any) -> None:
        from aiorobot import Parameter
        from aiorobot.msgs.nav2_msgs import CostmapFilterInfo, SpeedLimit

        self.node = node
        self.keepout: OccupancyMap | None = None
        self.speed: SpeedLimitFilter | None = None
        self.costmap: Costmap | None = None
        self._speed_pub: Any = None
        self._last_limit: float | None = None
        self._mask_topics: dict[str, str] = {}
        self.override_lethal_cost = False
        self.lethal_override_cost = _MAX_NON_OBSTACLE
        #: the robot stands in a lethal part of the keepout zone (its cells cost lethal_override_cost meanwhile)
        self.pose_lethal = False
        names = list(node.declare_parameter("filters", Parameter.Type.STRING_ARRAY).value or [])
        for name in names:
            plugin = str(node.declare_parameter(f"{name}.plugin", "").value)
            if plugin not in _PLUGINS:
                raise ValueError(f"{node.get_name()}: parameter {name}.plugin: expected one of {', '.join(_PLUGINS)}, found {plugin!r}")
            topic = str(node.declare_parameter(f"{name}.filter_info_topic", "").value)
            if not topic:
                raise ValueError(f"{node.get_name()}: parameter {name}.filter_info_topic: expected the CostmapFilterInfo topic, found none")
            if not bool(node.declare_parameter(f"{name}.enabled", True).value):
                continue
            if plugin.endswith("KeepoutFilter"):
                self.override_lethal_cost = bool(node.declare_parameter(f"{name}.override_lethal_cost", False).value)
                cost = int(node.declare_parameter(f"{name}.lethal_override_cost", _MAX_NON_OBSTACLE).value)
                self.lethal_override_cost = min(max(cost, FREE_SPACE), _MAX_NON_OBSTACLE)  # clamped, as Nav2
            if plugin.endswith("SpeedFilter"):
                self._speed_pub = node.create_publisher(SpeedLimit, str(node.declare_parameter(f"{name}.speed_limit_topic", "speed_limit").value), 1)
            node.create_subscription(CostmapFilterInfo, topic, lambda m, n=name, p=plugin: self._on_info(n, p, m), MAP_QOS)

    def attach(self, costmap: Costmap) -> None:
        """The node's (new) costmap: the keepout layer goes into it."""
        self.costmap = costmap
        if self.keepout is not None:
            layer = keepout_layer(costmap, self.keepout)
            if self.pose_lethal:
                layer[(layer != NO_INFORMATION) & (layer > 0)] = self.lethal_override_cost  # every zone cell, as Nav2
            costmap.set_keepout(layer)

    def update(self, controller: Any, x: float, y: float) -> None:
        """The robot is at (x, y): give ``controller`` (Nav2's ``setSpeedLimit``) the speed filter's limit
        there, and with ``override_lethal_cost`` lower the keepout zone while the robot stands in it."""
        limit = self.speed_limit_at(x, y)
        controller.set_speed_limit(limit, self.speed.percentage if self.speed is not None else False)
        if self.override_lethal_cost and self.keepout is not None:
            lethal = int(keepout_cost_at(self.keepout, x, y)) >= INSCRIBED_INFLATED_OBSTACLE
            if lethal != self.pose_lethal:
                self.pose_lethal = lethal
                if lethal:
                    self.node.get_logger().warning("KeepoutFilter: Pose is in keepout zone, reducing cost override to navigate out.")
                if self.costmap is not None:
                    self.attach(self.costmap)

    def speed_limit_at(self, x: float, y: float) -> float:
        """The speed filter's limit at (x, y) (NO_SPEED_LIMIT without one), published when it changes."""
        if self.speed is None:
            return NO_SPEED_LIMIT
        try:
            limit = self.speed.limit_at(x, y)
        except ValueError as err:
            self.node.get_logger().error(str(err), throttle_duration_sec=2.0)
            limit = self._last_limit if self._last_limit is not None else NO_SPEED_LIMIT
        if limit != self._last_limit and self._speed_pub is not None:
            from aiorobot.msgs.nav2_msgs import SpeedLimit

            msg = SpeedLimit(percentage=self.speed.percentage, speed_limit=float(limit))
            msg.header.frame_id = self.speed.mask.frame_id
            msg.header.stamp = self.node.now().to_msg()
            self._speed_pub.publish(msg)
        self._last_limit = limit
        return limit

    def _on_info(self, name: str, plugin: str, info: Any) -> None:
        from aiorobot.msgs.nav_msgs import OccupancyGrid

        if int(info.type) not in _PLUGINS[plugin]:
            self.node.get_logger().error(f"filter {name}: {plugin} expects CostmapFilterInfo type "
                                         f"{' or '.join(str(int(t)) for t in _PLUGINS[plugin])}, found {int(info.type)}; ignored")
            return
        topic = str(info.filter_mask_topic)
        if self._mask_topics.get(name) == topic:
            return
        self._mask_topics[name] = topic
        self.node.create_subscription(OccupancyGrid, topic, lambda m: self._on_mask(name, info, m), MAP_QOS)
        self.node.get_logger().info(f"filter {name}: subscribing to the mask on {topic}")

    def _on_mask(self, name: str, info: Any, msg: Any) -> None:
        mask = OccupancyMap.from_msg(msg)
        if FilterType(int(info.type)) == FilterType.KEEPOUT_FILTER:
            self.keepout = mask
            if self.costmap is not None:
                self.attach(self.costmap)
        else:
            self.speed = SpeedLimitFilter(mask, FilterType(int(info.type)), float(info.base), float(info.multiplier))
            self._last_limit = None
