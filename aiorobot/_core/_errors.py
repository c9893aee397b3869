"""Exceptions raised by the aiorobot core."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

__all__ = [
    "ConfigError",
    "InvalidNameError",
    "InvalidParameterTypeError",
    "InvalidParameterValueError",
    "ParameterAlreadyDeclaredError",
    "ParameterError",
    "ParameterImmutableError",
    "ParameterNotDeclaredError",
    "ParameterUninitializedError",
    "QoSIncompatibleError",
    "ServiceError",
]


class InvalidNameError(ValueError):
    """A topic, service, node or namespace name breaks ROS 2's naming rules.

    The message quotes the name, says it "is invalid" (the words rclpy's tests match) and
    points a caret at the offending character.
    """

    def __init__(self, kind: str, name: str, reason: str, index: int | None = None) -> None:
        self.kind = kind
        self.name = name
        self.reason = reason
        self.index = index
        text = f"{kind} name {name!r} is invalid: {reason}"
        if index is not None:
            text += f"\n  {name}\n  {' ' * index}^"
        super().__init__(text)


class QoSIncompatibleError(RuntimeError):
    """A publisher and a subscription on one topic have incompatible QoS policies."""


class ParameterError(ValueError):
    """Base class of parameter errors."""


class ParameterNotDeclaredError(ParameterError, KeyError):
    """A parameter was read or set before ``declare_parameter``."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class ParameterAlreadyDeclaredError(ParameterError):
    """``declare_parameter`` was called twice for one name."""


class InvalidParameterValueError(ParameterError):
    """A value (override or default) has the wrong type or lies outside the range."""

    def __init__(self, name: str, reason: str) -> None:
        self.name = name
        self.reason = reason
        super().__init__(f"parameter {name!r}: {reason}")


class InvalidParameterTypeError(InvalidParameterValueError):
    """A value's type does not match the parameter's declared (static) type (rclpy's
    ``InvalidParameterTypeException``).

    rclpy difference: it is also an :class:`InvalidParameterValueError`, so code that
    catches bad values catches bad types too; the rclpy exception is unrelated to
    ``InvalidParameterValueException``.
    """


class ParameterImmutableError(ParameterError):
    """A read-only parameter was undeclared or re-described (rclpy's ``ParameterImmutableException``)."""


class ParameterUninitializedError(ParameterError):
    """A parameter declared with a type but no value was read before it got one
    (rclpy's ``ParameterUninitializedException``)."""


class ServiceError(RuntimeError):
    """A service call failed on the server side; the message carries the server's reason."""


class ConfigError(Exception):
    """A configuration file is unreadable or invalid: a graph file (aiorobot.launch) that is not
    TOML or does not describe a valid graph, or a zenoh session config (aiorobot.transport's
    ``ZenohConfigError``); one ``except ConfigError`` catches both.

    Attributes
    ----------
    path : str
        The file, as the user named it.
    key : str or None
        The key path inside the file (``nodes[1].executor``), ``None`` for file-level problems.
    message : str
        What was expected and what was found, on one line.
    """

    def __init__(self, path: str | Path, key: str | None, message: str) -> None:
        self.path = str(path)
        self.key = key
        self.message = _one_line(message)
        super().__init__(self.path, key, self.message)

    def __str__(self) -> str:
        if self.key:
            return f"{self.path}: {self.key}: {self.message}"
        return f"{self.path}: {self.message}"


def _one_line(text: str) -> str:
    return re.sub(r"\s*\n\s*", " ", text.strip())
