"""``rclpy.parameter``."""

from ..._parameters import Parameter, ParameterType

__all__ = ["Parameter", "ParameterType"]
