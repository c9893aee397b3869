"""``tf2_ros.transform_broadcaster``."""

from ._broadcasters import TransformBroadcaster

__all__ = ["TransformBroadcaster"]
