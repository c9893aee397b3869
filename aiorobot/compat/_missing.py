"""Names of rclpy that aiorobot does not provide yet: they fail at the name, with the docs link."""

from __future__ import annotations

from typing import Any

__all__ = ["DOCS_URL", "MissingInterfaceError", "NotProvidedError", "module_getattr", "not_provided"]

DOCS_URL = "https://github.com/aiorobot/aiorobot/blob/main/docs/rclpy-compat.md"


class NotProvidedError(NotImplementedError):
    """An rclpy name aiorobot does not implement yet (raised where the program uses it)."""


class MissingInterfaceError(ImportError):
    """``from <pkg>.msg|srv|action import <Name>`` of a type aiorobot does not know.

    An ImportError, as with rclpy (``except ImportError`` still works); ``aiorobot exec``
    prints it in one line at the program's line.
    """


def not_provided(qualname: str) -> NotProvidedError:
    return NotProvidedError(f"aiorobot does not provide {qualname} yet; see {DOCS_URL}")


def module_getattr(module_name: str, public_name: str, missing: frozenset[str] | set[str]) -> Any:
    """A module ``__getattr__``: known-missing rclpy names raise :class:`NotProvidedError`."""

    def __getattr__(name: str) -> Any:
        if name in missing:
            raise not_provided(f"{public_name}.{name}")
        raise AttributeError(f"module {public_name!r} has no attribute {name!r}")

    return __getattr__
