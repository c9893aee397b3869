"""Parameters beyond the names in ``aiorobot`` itself: ROS 2 YAML parameter files, the
``rcl_interfaces`` conversions, and the QoS of ``/parameter_events``.

``Parameter``, ``ParameterDescriptor``, ``ParameterType``, the ranges and the errors import
from ``aiorobot``; a node's parameter methods are rclpy's (see :class:`aiorobot.Node`).
"""

from __future__ import annotations

from .._core._parameter_types import get_parameter_value, parameter_value_to_python
from .._core._parameter_files import ParameterFile, ParameterFileError, load_parameter_file, parameter_dict_from_yaml_file
from .._core._parameter_services import qos_profile_parameter_events

__all__ = [
    "ParameterFile",
    "ParameterFileError",
    "get_parameter_value",
    "load_parameter_file",
    "parameter_dict_from_yaml_file",
    "parameter_value_to_python",
    "qos_profile_parameter_events",
]
