"""``rclpy.exceptions``."""

from ..._core._errors import (
    InvalidParameterValueError as InvalidParameterValueException,
    ParameterAlreadyDeclaredError as ParameterAlreadyDeclaredException,
    ParameterImmutableError as ParameterImmutableException,
    ParameterNotDeclaredError as ParameterNotDeclaredException,
    ParameterUninitializedError as ParameterUninitializedException,
    InvalidParameterTypeError as InvalidParameterTypeException,
    InvalidNameError as InvalidNamespaceException,
    InvalidNameError as InvalidNodeNameException,
    InvalidNameError as InvalidTopicNameException,
    InvalidNameError as InvalidServiceNameException,
)

__all__ = [
    "InvalidHandle", "InvalidNamespaceException", "InvalidNodeNameException", "InvalidParameterTypeException",
    "InvalidParameterValueException", "InvalidServiceNameException", "InvalidTopicNameException",
    "NotInitializedException", "ParameterAlreadyDeclaredException", "ParameterImmutableException",
    "ParameterNotDeclaredException", "ParameterUninitializedException", "ROSInterruptException",
    "TimeSourceChangedError",
]


class NotInitializedException(Exception):
    """rclpy.init() has not been called, or the context was shut down."""


class ROSInterruptException(Exception):
    """The program was interrupted (the context shut down) during a blocking call such as ``Rate.sleep``."""


class TimeSourceChangedError(Exception):
    """ROS time was switched on or off while an ``AsyncClock.sleep`` waited (rclpy's)."""


class InvalidHandle(RuntimeError):
    """An entity used after it was destroyed (rclpy raises ``rclpy._rclpy_pybind11.InvalidHandle``)."""
