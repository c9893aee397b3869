"""``nav2_simple_commander`` on aiorobot: ``robot_navigator.BasicNavigator`` for programs run by ``aiorobot exec``."""

from __future__ import annotations

__all__: list[str] = []
