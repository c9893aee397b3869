"""``tf2_ros.static_transform_broadcaster``."""

from ._broadcasters import StaticTransformBroadcaster

__all__ = ["StaticTransformBroadcaster"]
