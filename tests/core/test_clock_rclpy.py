"""rclpy's test_clock.py cases, restated for aiorobot.Clock (upstream: ros2/rclpy 8.0.0)."""

from __future__ import annotations

import asyncio

import pytest

from aiorobot import (
    Clock,
    ClockChange,
    ClockType,
    Duration,
    JumpThreshold,
    Node,
    ROSClock,
    Runtime,
    Time,
    TimeJump,
)
from aiorobot.testing import SimClock


class Calls:
    def __init__(self) -> None:
        self.pre = 0
        self.post: list[TimeJump] = []

    def on_pre(self) -> None:
        self.pre += 1

    def on_post(self, jump: TimeJump) -> None:
        self.post.append(jump)


def test_invalid_jump_threshold():
    # rclpy test_clock.py::test_invalid_jump_threshold
    with pytest.raises(ValueError):
        JumpThreshold(min_forward=Duration(nanoseconds=0), min_backward=None)
    with pytest.raises(ValueError):
        JumpThreshold(min_forward=Duration(nanoseconds=-1), min_backward=None)
    with pytest.raises(ValueError):
        JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=0))
    with pytest.raises(ValueError):
        JumpThreshold(min_forward=None, min_backward=Duration(nanoseconds=1))
    with pytest.raises(ValueError):
        JumpThreshold(min_forward=None, min_backward=None, on_clock_change=False)


def test_clock_construction():
    # rclpy test_clock.py::test_clock_construction
    with pytest.raises(TypeError, match="clock_type: expected a ClockType"):
        Clock(clock_type="STEADY_TIME")  # type: ignore[arg-type]
    assert Clock(clock_type=ClockType.STEADY_TIME).clock_type == ClockType.STEADY_TIME
    assert Clock(clock_type=ClockType.SYSTEM_TIME).clock_type == ClockType.SYSTEM_TIME
    clock = Clock(clock_type=ClockType.ROS_TIME)
    assert clock.clock_type == ClockType.ROS_TIME and isinstance(clock, ROSClock)
    assert ROSClock().clock_type == ClockType.ROS_TIME


def test_clock_now():
    # rclpy test_clock.py::test_clock_now (steady time is monotonic, types follow the clock)
    for clock_type in ClockType:
        clock = Clock(clock_type=clock_type)
        a, b = clock.now(), clock.now()
        assert a.clock_type == clock_type and b >= a


def test_ros_time_is_active():
    # rclpy test_clock.py::test_ros_time_is_active
    clock = ROSClock()
    clock._set_ros_time_is_active(True)
    assert clock.ros_time_is_active
    clock._set_ros_time_is_active(False)
    assert not clock.ros_time_is_active


def test_triggered_time_jump_callbacks():
    # rclpy test_clock.py::test_triggered_time_jump_callbacks
    t1 = JumpThreshold(min_forward=Duration(seconds=1), min_backward=Duration(seconds=-0.5), on_clock_change=False)
    t2 = JumpThreshold(min_forward=Duration(seconds=0.5), min_backward=Duration(seconds=-1), on_clock_change=False)
    c1, c2 = Calls(), Calls()
    clock = ROSClock()
    h1 = clock.create_jump_callback(t1, pre_callback=c1.on_pre, post_callback=c1.on_post)
    h2 = clock.create_jump_callback(t2, pre_callback=c2.on_pre, post_callback=c2.on_post)
    clock.set_ros_time_override(Time(seconds=1))
    clock._set_ros_time_is_active(True)
    assert (c1.pre, c1.post, c2.pre, c2.post) == (0, [], 0, [])
    clock.set_ros_time_override(Time(seconds=1.75))  # forward 0.75 s: only t2
    assert (c1.pre, c1.post) == (0, [])
    assert c2.pre == 1 and c2.post == [TimeJump(ClockChange.ROS_TIME_NO_CHANGE, Duration(seconds=0.75))]
    clock.set_ros_time_override(Time(seconds=1))  # backward 0.75 s: only t1
    assert c1.pre == 1 and c1.post == [TimeJump(ClockChange.ROS_TIME_NO_CHANGE, Duration(seconds=-0.75))]
    assert c2.pre == 1
    h1.unregister()
    h2.unregister()
    clock.set_ros_time_override(Time(seconds=5))
    assert c2.pre == 1 and len(c2.post) == 1


def test_triggered_clock_change_callbacks():
    # rclpy test_clock.py::test_triggered_clock_change_callbacks
    one, minus_one = Duration(seconds=1), Duration(seconds=-1)
    calls = [Calls(), Calls(), Calls()]
    thresholds = [
        JumpThreshold(min_forward=one, min_backward=minus_one, on_clock_change=False),
        JumpThreshold(min_forward=None, min_backward=None, on_clock_change=True),
        JumpThreshold(min_forward=one, min_backward=minus_one, on_clock_change=True),
    ]
    clock = ROSClock()
    handles = [
        clock.create_jump_callback(t, pre_callback=c.on_pre, post_callback=c.on_post)
        for t, c in zip(thresholds, calls, strict=True)
    ]
    clock._set_ros_time_is_active(True)
    assert [c.pre for c in calls] == [0, 1, 1]
    assert [len(c.post) for c in calls] == [0, 1, 1]
    assert calls[1].post[0].clock_change == ClockChange.ROS_TIME_ACTIVATED
    clock._set_ros_time_is_active(True)  # no change, no callbacks
    assert [c.pre for c in calls] == [0, 1, 1]
    clock._set_ros_time_is_active(False)
    assert calls[2].post[-1].clock_change == ClockChange.ROS_TIME_DEACTIVATED
    for h in handles:
        h.unregister()


def test_with_jump_handle():
    # rclpy test_clock.py::test_with_jump_handle
    clock = ROSClock()
    clock._set_ros_time_is_active(False)
    calls = Calls()
    threshold = JumpThreshold(min_forward=None, min_backward=None, on_clock_change=True)
    with clock.create_jump_callback(threshold, post_callback=calls.on_post):
        clock._set_ros_time_is_active(True)
        assert len(calls.post) == 1
    clock._set_ros_time_is_active(False)
    assert len(calls.post) == 1


def test_jump_handle_needs_a_callback():
    clock = ROSClock()
    threshold = JumpThreshold(min_forward=None, min_backward=None)
    with pytest.raises(ValueError, match="one of pre_callback or post_callback"):
        clock.create_jump_callback(threshold)


async def test_sleep_until_mismatched_clock_type():
    # rclpy test_clock.py::test_sleep_until_mismatched_clock_type
    clock = Clock(clock_type=ClockType.SYSTEM_TIME)
    with pytest.raises(ValueError, match="clock type"):
        await clock.sleep_until(Time(clock_type=ClockType.STEADY_TIME))


@pytest.mark.parametrize("clock_type", [ClockType.SYSTEM_TIME, ClockType.STEADY_TIME, ClockType.ROS_TIME])
async def test_sleep_until_basic_and_time_in_past(clock_type):
    # rclpy test_clock.py::test_sleep_until_basic, ::test_sleep_until_time_in_past,
    # ::test_sleep_for_basic, ::test_sleep_for_negative_duration
    clock = Clock(clock_type=clock_type)
    start = clock.now()
    assert await clock.sleep_until(start + Duration(seconds=0.01))
    assert clock.now() - start >= Duration(seconds=0.01)
    assert await clock.sleep_until(start)
    assert await clock.sleep_for(Duration(seconds=0.01))
    assert await clock.sleep_for(Duration(seconds=-1))


@pytest.mark.parametrize("ros_time_enabled", [True, False])
async def test_sleep_until_ros_time_toggled(ros_time_enabled):
    # rclpy test_clock.py::test_sleep_until_ros_time_toggled / ::test_sleep_for_ros_time_toggled
    clock = ROSClock()
    clock._set_ros_time_is_active(not ros_time_enabled)
    task = asyncio.create_task(clock.sleep_until(clock.now() + Duration(seconds=10)))
    await asyncio.sleep(0)  # the task is now inside sleep_until
    clock._set_ros_time_is_active(ros_time_enabled)
    assert await asyncio.wait_for(task, 5) is False


async def test_sleep_until_ros_time_enabled():
    # rclpy test_clock.py::test_sleep_until_ros_time_enabled / ::test_sleep_for_ros_time_enabled
    clock = ROSClock()
    clock._set_ros_time_is_active(True)
    start = Time(seconds=1)
    stop = start + Duration(seconds=10)
    clock.set_ros_time_override(start)
    task = asyncio.create_task(clock.sleep_until(stop))
    await asyncio.sleep(0)
    clock.set_ros_time_override(Time(seconds=0.5))  # a backwards jump keeps it waiting
    await asyncio.sleep(0)
    assert not task.done()
    clock.set_ros_time_override(stop)
    assert await asyncio.wait_for(task, 5) is True


async def test_sim_runtime_jump_callback_sees_clock_messages():
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = SimClock(rt)
        node = Node("jumper")
        rt.add_node(node)
        jumps: list[TimeJump] = []
        threshold = JumpThreshold(min_forward=Duration(seconds=5), min_backward=None, on_clock_change=False)
        handle = node.get_clock().create_jump_callback(threshold, post_callback=jumps.append)
        await sim.set(1.0)
        await sim.advance(1.0)  # 1 ms steps: none crosses 5 s
        assert jumps == []
        await sim.set(8.0)
        assert [j.delta for j in jumps] == [Duration(seconds=6)]
        handle.unregister()
