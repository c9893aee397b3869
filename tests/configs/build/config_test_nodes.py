"""Node classes used by the config fixtures in this folder (imported from the config's folder)."""

from __future__ import annotations

from typing import Any

from aiorobot import Node


class Ranged(Node):
    """Declares ``gain`` (a float in [0, 1]) and ``label`` (a string)."""

    def __init__(self, **kw: Any) -> None:
        super().__init__("ranged", **kw)
        self.declare_parameter("gain", 0.5, range=(0.0, 1.0))
        self.declare_parameter("label", "x")


class Exploding(Node):
    def __init__(self, **kw: Any) -> None:
        super().__init__("exploding", **kw)
        raise RuntimeError("motor port /dev/ttyUSB9 is missing")


class NoKeywords(Node):
    def __init__(self) -> None:
        super().__init__("no_keywords")


class NotANode:
    def __init__(self, **kw: Any) -> None:
        pass


def not_a_class(**kw: Any) -> None:
    return None
