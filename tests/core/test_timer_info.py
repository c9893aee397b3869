"""TimerInfo, time_until_next_call, timers as context managers, destroy_rate (rclpy rclpy/test/test_timer.py)."""

import functools

import pytest

from aiorobot import ClockType, Node, TimerInfo


def test_timer_info_construction():
    # rclpy test_timer.py::test_timer_info_construction
    info = TimerInfo()
    assert info.expected_call_time.nanoseconds == 0 and info.actual_call_time.nanoseconds == 0
    assert info.expected_call_time.clock_type == ClockType.SYSTEM_TIME
    info = TimerInfo(expected_call_time=123456789, actual_call_time=987654321, clock_type=ClockType.STEADY_TIME)
    assert info.expected_call_time.nanoseconds == 123456789
    assert info.actual_call_time.nanoseconds == 987654321
    assert info.actual_call_time.clock_type == ClockType.STEADY_TIME
    with pytest.raises(TypeError):
        TimerInfo(clock_type="STEADY_TIME")
    with pytest.raises(ValueError, match="must not be negative"):
        TimerInfo(expected_call_time=-1)


async def test_timer_with_info(sim_runtime, sim_clock):
    # rclpy test_timer.py::test_timer_with_info (on sim time: exact due and run times)
    node = sim_runtime.add_node(Node("n"))
    infos = []

    def timer_callback(info: TimerInfo):
        infos.append(info)

    timer = node.create_timer(1, timer_callback)
    await sim_clock.advance(2.5, step_sec=0.25)
    timer.cancel()
    assert [i.expected_call_time.nanoseconds for i in infos] == [2_000_000_000, 3_000_000_000]
    assert [i.actual_call_time.nanoseconds for i in infos] == [2_000_000_000, 3_000_000_000]
    assert infos[0].actual_call_time.clock_type == timer.clock.clock_type == ClockType.ROS_TIME


async def test_timer_info_with_partial_and_by_position(sim_runtime, sim_clock):
    # rclpy test_timer.py::test_timer_info_with_partial; an unannotated one-argument callback gets it too
    node = sim_runtime.add_node(Node("n"))
    by_name, by_position, none = [], [], []

    def annotated(tag, info: TimerInfo):
        by_name.append((tag, info.expected_call_time.nanoseconds))

    node.create_timer(0.5, functools.partial(annotated, "p"))
    node.create_timer(0.5, lambda info: by_position.append(info.expected_call_time.nanoseconds))
    node.create_timer(0.5, lambda: none.append(1))
    await sim_clock.advance(0.6, step_sec=0.1)
    assert by_name == [("p", 1_500_000_000)] and by_position == [1_500_000_000] and none == [1]


async def test_timer_info_on_wall_time_is_on_the_node_clock(runtime):
    import asyncio

    node = runtime.add_node(Node("n"))
    got = asyncio.Event()
    infos = []

    def cb(info):
        infos.append(info)
        got.set()

    node.create_timer(0.001, cb)
    await asyncio.wait_for(got.wait(), 10)
    info = infos[0]
    now = node.get_clock().now().nanoseconds
    assert 0 < info.expected_call_time.nanoseconds <= info.actual_call_time.nanoseconds <= now


async def test_time_until_next_call(sim_runtime, sim_clock):
    # rclpy test_timer.py::test_time_until_next_call
    node = sim_runtime.add_node(Node("n"))
    timer = node.create_timer(1, lambda: None)
    assert not timer.is_canceled()
    await sim_clock.advance(0.25)
    assert timer.time_until_next_call() == 750_000_000
    assert timer.time_since_last_call() == 250_000_000
    timer.reset()
    assert not timer.is_canceled() and timer.time_until_next_call() == 1_000_000_000
    timer.cancel()
    assert timer.is_canceled() and timer.time_until_next_call() is None


def test_timer_without_autostart_and_as_a_context_manager():
    # rclpy test_timer.py::test_timer_without_autostart, ::test_timer_context_manager
    node = Node("n")
    with node.create_timer(1, lambda: None, autostart=False) as timer:
        assert timer.is_canceled()
        timer.reset()
        assert not timer.is_canceled()
        timer.cancel()
        assert timer.is_canceled()
    assert timer.destroyed and timer not in node.timers


async def test_destroy_rate(runtime):
    node = runtime.add_node(Node("n"))
    rate = node.create_rate(1000)
    await rate.sleep()
    node.destroy_rate(rate)
    with pytest.raises(RuntimeError, match="was destroyed"):
        await rate.sleep()


async def test_changing_the_period_and_is_ready(sim_runtime, sim_clock):
    # rclpy timer.py: Timer.timer_period_ns setter, Timer.is_ready
    node = sim_runtime.add_node(Node("n"))
    ticks = []
    timer = node.create_timer(1, lambda: ticks.append(node.now().nanoseconds))
    assert not timer.is_ready()
    timer.timer_period_ns = 250_000_000  # restarts the grid from now (t = 1 s)
    await sim_clock.advance(0.6, step_sec=0.05)
    assert ticks == [1_250_000_000, 1_500_000_000]
    with pytest.raises(ValueError, match="expected an int > 0"):
        timer.timer_period_ns = 0
