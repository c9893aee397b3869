"""rclpy's test_time.py cases, restated for aiorobot.Time / Duration (upstream: ros2/rclpy 8.0.0)."""

from __future__ import annotations

import pytest

from aiorobot import ClockType, Duration, Infinite, Time
from aiorobot.msgs.builtin_interfaces import Time as TimeMsg


def test_time_construction():
    # rclpy test_time.py::test_time_construction
    assert Time().nanoseconds == 0
    t = Time(seconds=1, nanoseconds=5e8, clock_type=ClockType.SYSTEM_TIME)
    assert t.nanoseconds == 1_500_000_000
    assert t.clock_type == ClockType.SYSTEM_TIME
    with pytest.raises(OverflowError):
        Time(nanoseconds=2**63)
    assert Time(nanoseconds=2**63 - 1).nanoseconds == 2**63 - 1
    with pytest.raises(ValueError):
        Time(seconds=-1)
    with pytest.raises(ValueError):
        Time(nanoseconds=-1)
    with pytest.raises(TypeError, match="clock_type: expected a ClockType"):
        Time(clock_type="SYSTEM_TIME")  # type: ignore[arg-type]


def test_duration_construction():
    # rclpy test_time.py::test_duration_construction
    assert Duration().nanoseconds == 0
    assert Duration(seconds=1, nanoseconds=5e8).nanoseconds == 1_500_000_000
    with pytest.raises(OverflowError):
        Duration(nanoseconds=2**63)
    assert Duration(nanoseconds=2**63 - 1).nanoseconds == 2**63 - 1
    assert Duration(seconds=-1).nanoseconds == -1_000_000_000
    assert Duration(nanoseconds=-1).nanoseconds == -1
    assert Duration(seconds=-(2**63) / 1e9).nanoseconds == -(2**63)
    with pytest.raises(OverflowError):
        Duration(seconds=-(2**63) / 1e9 - 1)
    assert Duration(nanoseconds=-(2**63)).nanoseconds == -(2**63)
    with pytest.raises(OverflowError):
        Duration(nanoseconds=-(2**63) - 1)


def test_duration_operators():
    # rclpy test_time.py::test_duration_operators
    d1, d2 = Duration(seconds=1), Duration(seconds=2)
    assert (d1 + d2).nanoseconds == 3_000_000_000
    assert (d2 - d1).nanoseconds == 1_000_000_000
    assert d1 * 2 == d2
    assert d2 * 0.5 == d1
    assert d2 * float("inf") == Infinite
    with pytest.raises(ValueError):
        d2 * float("nan")


def test_time_operators():
    # rclpy test_time.py::test_time_operators
    t1 = Time(nanoseconds=1, clock_type=ClockType.STEADY_TIME)
    d = Duration(nanoseconds=1)
    for t2 in (t1 + d, d + t1):
        assert isinstance(t2, Time)
        assert t2.nanoseconds == 2
        assert t2.clock_type == ClockType.STEADY_TIME
    t2 = t1 - d
    assert t2.nanoseconds == 0 and t2.clock_type == ClockType.STEADY_TIME
    with pytest.raises(OverflowError):
        Duration(nanoseconds=1) + Time(nanoseconds=2**63 - 1)
    with pytest.raises(ValueError):
        Time(nanoseconds=1) - Duration(nanoseconds=2)
    diff = t1 - t2
    assert isinstance(diff, Duration) and diff.nanoseconds == 1
    assert (Time(nanoseconds=1) - Time(nanoseconds=2)).nanoseconds == -1
    with pytest.raises(TypeError):
        Time(nanoseconds=2, clock_type=ClockType.SYSTEM_TIME) - Time(nanoseconds=1, clock_type=ClockType.STEADY_TIME)
    with pytest.raises(TypeError):
        t1 + t2  # type: ignore[operator]
    with pytest.raises(TypeError):
        d - t1  # type: ignore[operator]


def test_time_comparators():
    # rclpy test_time.py::test_time_comparators
    t1, t2 = Time(nanoseconds=1), Time(nanoseconds=2)
    assert not t1 == t2
    assert t1 != t2
    assert not t1 > t2 and not t1 >= t2 and t1 < t2 and t1 <= t2
    assert Time(nanoseconds=5e9) == Time(seconds=5)
    a = Time(nanoseconds=1, clock_type=ClockType.SYSTEM_TIME)
    b = Time(nanoseconds=2, clock_type=ClockType.STEADY_TIME)
    for compare in (
        lambda: a == b,
        lambda: a != b,
        lambda: a > b,
        lambda: a >= b,
        lambda: a < b,
        lambda: a <= b,
    ):
        with pytest.raises(TypeError, match="different clocks"):
            compare()
    t1 = Time(nanoseconds=1)
    assert not t1 == 1
    d = Duration(nanoseconds=1)
    assert not t1 == d
    assert t1 != d
    for compare in (lambda: t1 > d, lambda: t1 >= d, lambda: t1 < d, lambda: t1 <= d):
        with pytest.raises(TypeError):
            compare()


def test_duration_comparators():
    # rclpy test_time.py::test_duration_comparators
    d1, d2 = Duration(nanoseconds=1), Duration(nanoseconds=2)
    assert not d1 == d2 and d1 != d2
    assert not d1 > d2 and not d1 >= d2 and d1 < d2 and d1 <= d2
    assert Duration(nanoseconds=5e9) == Duration(seconds=5)
    t = Time(nanoseconds=1)
    assert not d1 == 1
    assert not d1 == t and d1 != t
    for compare in (lambda: d1 > t, lambda: d1 >= t, lambda: d1 < t, lambda: d1 <= t):
        with pytest.raises(TypeError):
            compare()


def test_time_message_conversions():
    # rclpy test_time.py::test_time_message_conversions and ::test_time_message_conversions_big_nanoseconds
    for ns in (1, 1553575413247045598):
        t1 = Time(nanoseconds=ns, clock_type=ClockType.ROS_TIME)
        msg = t1.to_msg()
        assert isinstance(msg, TimeMsg)
        assert Time.from_msg(msg) == t1
    assert Time.from_msg(Time(nanoseconds=1).to_msg(), clock_type=ClockType.SYSTEM_TIME).clock_type == ClockType.SYSTEM_TIME


def test_duration_message_conversions():
    # rclpy test_time.py::test_duration_message_conversions
    assert Duration.from_msg(Duration(nanoseconds=1).to_msg()).nanoseconds == 1


def test_seconds_nanoseconds():
    # rclpy test_time.py::test_seconds_nanoseconds
    assert Time(seconds=1, nanoseconds=5e8).seconds_nanoseconds() == (1, 500_000_000)
    assert Time(seconds=0, nanoseconds=15e8).seconds_nanoseconds() == (1, 500_000_000)
    assert Time().seconds_nanoseconds() == (0, 0)


def test_infinite_duration():
    # rclpy test_time.py::test_infinite_duration
    assert str(Infinite) == "Infinite"
    assert Infinite.nanoseconds == 2**63 - 1
    assert str(Duration(nanoseconds=3)) == "3 nanoseconds"


def test_times_hash_by_value():
    assert len({Time(seconds=1), Time(nanoseconds=1_000_000_000)}) == 1


def test_from_msg_rejects_other_objects():
    # rclpy time.py / duration.py from_msg: TypeError for a non-message
    with pytest.raises(TypeError, match="expected a builtin_interfaces/msg/Time"):
        Time.from_msg(5)
    with pytest.raises(TypeError, match="expected a builtin_interfaces/msg/Duration"):
        Duration.from_msg("1s")
