"""Testing aiorobot nodes with pytest-asyncio.

The pytest plugin (registered through the ``pytest11`` entry point, so nothing
to configure) provides the fixtures ``runtime`` (a fresh local ``Runtime`` per
test, shut down after it), ``sim_runtime`` (the same with ``use_sim_time``) and
``sim_clock`` (a :class:`SimClock` on ``sim_runtime``), and ``bag_replay`` (a
:class:`BagReplay`: replay a recorded bag into nodes and compare their outputs)::

    async def test_talker_publishes(runtime):
        probe = runtime.add_node(aiorobot.Node("probe"))
        runtime.add_node(Talker())
        msg = await wait_for_message(probe, Twist, "/cmd_vel", timeout_sec=5)
        assert msg.linear.x == 0.0

``settle`` is ``Runtime.settle`` (``await settle(runtime)``) and ``wait_for_message`` is
``aiorobot.lowlevel.wait_for_message``: the core's, re-exported here for tests.
"""

from __future__ import annotations

from .. import Runtime
from ..lowlevel import wait_for_message
from ._bag import BagReplay
from ._sim import ClockPublisher, SimClock

settle = Runtime.settle

__all__ = ["BagReplay", "ClockPublisher", "SimClock", "settle", "wait_for_message"]
