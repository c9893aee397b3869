"""The per-node ``use_sim_time`` parameter (rclpy's TimeSource)."""

from __future__ import annotations

from aiorobot import ClockPublisher, Duration, Node, Parameter, Runtime
from aiorobot.testing import settle


def test_no_use_sim_time_and_use_sim_time():
    # rclpy test_node.py::test_no_use_sim_time, ::test_use_sim_time
    assert Node("no_sim").get_parameter("use_sim_time").value is False
    sim = Node("sim", parameter_overrides=[Parameter("use_sim_time", value=True)])
    assert sim.has_parameter("use_sim_time") and sim.get_parameter("use_sim_time").value is True


async def test_node_left_alone_follows_the_runtime():
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        assert node.get_parameter("use_sim_time").value is True
        assert node.get_clock() is rt.clock


async def test_node_with_use_sim_time_follows_clock_in_a_wall_time_runtime():
    async with Runtime(handle_signals=False) as rt:
        clock_pub = rt.add_node(ClockPublisher())
        node = rt.add_node(Node("sim", parameter_overrides={"use_sim_time": True}))
        other = rt.add_node(Node("wall"))
        await settle(rt)
        clock_pub.publish_time(5_000_000_000)
        await settle(rt)
        assert node.now().nanoseconds == 5_000_000_000
        assert other.now().nanoseconds > 1_000_000_000_000_000_000  # the system clock
        assert not rt.clock.use_sim_time


async def test_switching_use_sim_time_at_run_time():
    # ROS time on and off through the parameter, as `ros2 param set /n use_sim_time true`
    async with Runtime(handle_signals=False) as rt:
        clock_pub = rt.add_node(ClockPublisher())
        node = rt.add_node(Node("n"))
        assert node.get_parameter("use_sim_time").value is False
        assert node.set_parameters([Parameter("use_sim_time", value=True)])[0].successful
        await settle(rt)
        clock_pub.publish_time(7_000_000_000)
        await settle(rt)
        assert node.get_clock().ros_time_is_active
        assert node.now().nanoseconds == 7_000_000_000
        sleeper = node._create_task(node.get_clock().sleep_for(Duration(seconds=100)))
        await settle(rt)
        assert node.set_parameters([Parameter("use_sim_time", value=False)])[0].successful
        assert await sleeper is False  # the time base changed under the sleep, as rclpy
        assert node.now().nanoseconds > 1_000_000_000_000_000_000
        assert not node.set_parameters([Parameter("use_sim_time", value="yes")])[0].successful


async def test_timers_follow_the_switched_clock():
    # a node switched to ROS time at run time: its timers fire on /clock, not on the wall clock
    async with Runtime(handle_signals=False) as rt:
        clock_pub = rt.add_node(ClockPublisher())
        node = rt.add_node(Node("n"))
        ticks: list[int] = []
        node.create_timer(100.0, lambda: ticks.append(node.now().nanoseconds))  # never on the wall clock here
        await settle(rt)
        clock_pub.publish_time(1_000_000_000)
        node.set_parameters([Parameter("use_sim_time", value=True)])
        await settle(rt)
        for step in range(2, 202):  # sim time 2 s .. 201 s in 1 s steps
            clock_pub.publish_time(step * 1_000_000_000)
            await settle(rt)
        # the period restarted at the switch, on the node's new clock (0 until its first /clock)
        assert ticks == [100_000_000_000, 200_000_000_000]


async def test_jump_callbacks_on_the_node_clock_see_ros_time_switch():
    # rclpy test_time_source.py::test_clock_change: ROS time activated / deactivated through the parameter
    from aiorobot import ClockChange, JumpThreshold

    async with Runtime(handle_signals=False) as rt:
        node = rt.add_node(Node("n"))
        changes: list = []
        threshold = JumpThreshold(min_forward=None, min_backward=None, on_clock_change=True)
        handle = node.get_clock().create_jump_callback(threshold, post_callback=lambda j: changes.append(j.clock_change))
        node.set_parameters([Parameter("use_sim_time", value=True)])
        node.set_parameters([Parameter("use_sim_time", value=False)])
        assert changes == [ClockChange.ROS_TIME_ACTIVATED, ClockChange.ROS_TIME_DEACTIVATED]
        assert node.get_clock() is not rt.clock
        handle.unregister()
