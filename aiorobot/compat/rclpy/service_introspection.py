"""``rclpy.service_introspection``: the states ``configure_introspection`` takes."""

from ..._core._service_introspection import ServiceIntrospectionState

__all__ = ["ServiceIntrospectionState"]
