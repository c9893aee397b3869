"""rclpy's ``LoggingService`` (``Node(..., enable_logger_service=True)``): ``<node>/get_logger_levels``
and ``<node>/set_logger_levels`` with the rcl_interfaces types, answered as rclpy answers."""

from __future__ import annotations

from typing import Any

from ..msgs import rcl_interfaces as _ri
from .rclpy import logging as _logging

__all__ = ["create_logger_services"]


def _get_logger_levels(request: Any) -> Any:
    response = _ri.GetLoggerLevels.Response()
    response.levels = [_ri.LoggerLevel(name=name, level=int(_logging.get_logger_level(name))) for name in request.names]
    return response


def _set_logger_levels(request: Any) -> Any:
    results = []
    for level in request.levels:
        result = _ri.SetLoggerLevelsResult(successful=False)
        try:
            _logging.set_logger_level(level.name, level.level, detailed_error=True)
            result.successful = True
        except ValueError:
            result.reason = "Failed reason: Invalid logger level."
        results.append(result)
    return _ri.SetLoggerLevels.Response(results=results)


def create_logger_services(node: Any) -> list[Any]:
    """The two services of ``node`` (aiorobot's own entities: answered whichever executor spins)."""
    from ._node import raw

    name = node.get_name()
    with raw(node):
        return [
            node.create_service(_ri.GetLoggerLevels, f"{name}/get_logger_levels", _get_logger_levels),
            node.create_service(_ri.SetLoggerLevels, f"{name}/set_logger_levels", _set_logger_levels),
        ]
