"""The example graph that ``aiorobot run`` starts when given no config file.

``default.toml`` wires :class:`~aiorobot.examples.sensor.ImuPublisher` (a timer-driven
publisher on the main loop) to :class:`~aiorobot.examples.monitor.RateMonitor` (a
subscriber on the priority loop that measures rate and latency). Both are short on
purpose: read them as templates for your own nodes.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["DEFAULT_CONFIG"]

#: The bundled example configuration file.
DEFAULT_CONFIG = Path(__file__).with_name("default.toml")
