"""``tf2_ros.transform_listener``."""

from ._listener import DEFAULT_STATIC_TF_TOPIC, DEFAULT_TF_TOPIC, TransformListener

__all__ = ["DEFAULT_STATIC_TF_TOPIC", "DEFAULT_TF_TOPIC", "TransformListener"]
