"""``rclpy.parameter``: ``Parameter``, its type, and rclpy's conversion helpers."""

from ..._core._parameter_types import Parameter, ParameterType, get_parameter_value, parameter_value_to_python
from ..._core._parameter_files import parameter_dict_from_yaml_file

__all__ = [
    "Parameter", "ParameterType", "get_parameter_value", "parameter_dict_from_yaml_file",
    "parameter_value_to_python",
]
