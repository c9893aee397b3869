import pytest

from aiorobot import ClockType, Duration, Time


def test_time_and_duration_arithmetic():
    t = Time(seconds=1, nanoseconds=500)
    d = Duration(seconds=0.5)
    assert (t + d).nanoseconds == 1_500_000_500
    assert (t + d) - t == d
    assert (t - d).nanoseconds == 500_000_500
    assert d * 2 == Duration(seconds=1)
    assert Duration(seconds=1) / Duration(seconds=0.25) == 4.0
    assert -d == Duration(nanoseconds=-500_000_000)


def test_ordering():
    assert Time(seconds=1) < Time(seconds=2) <= Time(seconds=2)
    assert Duration(seconds=-1) < Duration()


def test_times_of_different_clocks_do_not_mix():
    with pytest.raises(TypeError, match="different clocks"):
        _ = Time(seconds=1) < Time(seconds=1, clock_type=ClockType.STEADY_TIME)


def test_negative_time_is_rejected():
    with pytest.raises(ValueError, match="negative"):
        Time(seconds=-1)


def test_message_round_trip():
    t = Time(seconds=12, nanoseconds=345)
    msg = t.to_msg()
    assert (msg.sec, msg.nanosec) == (12, 345)
    assert Time.from_msg(msg) == t
    d = Duration(seconds=3, nanoseconds=7)
    assert Duration.from_msg(d.to_msg()) == d
