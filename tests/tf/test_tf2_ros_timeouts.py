"""tf2_ros's blocking forms: lookup_transform / can_transform (and _full) with ``timeout``.

tf2_ros (geometry2 tf2_ros_py buffer.py) signatures: ``lookup_transform(target_frame, source_frame, time,
timeout=Duration())``, ``can_transform(target_frame, source_frame, time, timeout=Duration(),
return_debug_tuple=False)``; with a timeout they block the calling thread until the data is there.
"""

from __future__ import annotations

import asyncio

import pytest
from _tf_helpers import tf, xyz_of

from aiorobot import Duration, Time
from aiorobot.tf import Buffer, LookupException

GENEROUS = Duration(seconds=30)  # bounds only a broken wake-up would reach


async def test_lookup_transform_with_a_timeout_blocks_a_worker_thread_until_the_insert():
    b = Buffer()
    worker = asyncio.create_task(
        asyncio.to_thread(b.lookup_transform, "map", "base_link", Time(seconds=1), GENEROUS)
    )
    for _ in range(3):
        await asyncio.sleep(0)
    b.set_transform(tf("map", "base_link", 1, (1, 2, 3)), "t")
    assert xyz_of(await worker) == pytest.approx((1, 2, 3))


async def test_can_transform_with_a_timeout_in_a_worker_thread():
    b = Buffer()
    worker = asyncio.create_task(
        asyncio.to_thread(b.can_transform, "map", "base_link", Time(seconds=1), 30.0, True)
    )
    for _ in range(3):
        await asyncio.sleep(0)
    b.set_transform(tf("map", "base_link", 1), "t")
    assert await worker == (True, "")


def test_a_timeout_that_expires_raises_the_tf_exception_or_answers_false():
    b = Buffer()
    b.set_transform(tf("map", "odom", 1), "t")
    with pytest.raises(LookupException, match='"ghost" passed to lookup_transform argument source_frame'):
        b.lookup_transform("map", "ghost", Time(), timeout=Duration(nanoseconds=1_000_000))
    ok, why = b.can_transform("map", "ghost", Time(), timeout=0.001, return_debug_tuple=True)
    assert not ok and "ghost" in why


def test_zero_timeout_does_not_wait_and_full_forms_take_one():
    b = Buffer()
    b.set_transform(tf("odom", "base", 1, (1, 0, 0)), "t")
    b.set_transform(tf("odom", "base", 2, (2, 0, 0)), "t")
    out = b.lookup_transform("odom", "base", Time(seconds=1.5), timeout=Duration())
    assert xyz_of(out) == pytest.approx((1.5, 0, 0))
    full = b.lookup_transform_full("base", Time(seconds=2), "base", Time(seconds=1), "odom", timeout=0.0)
    assert xyz_of(full) == pytest.approx((-1, 0, 0))
    assert b.can_transform_full("base", Time(seconds=2), "base", Time(seconds=1), "odom", timeout=Duration())


async def test_blocking_on_an_event_loop_thread_is_refused():
    b = Buffer()
    with pytest.raises(RuntimeError, match="would stall this thread's event loop"):
        b.lookup_transform("map", "base", Time(), timeout=Duration(seconds=1))


def test_timeout_must_be_a_duration_or_seconds():
    b = Buffer()
    with pytest.raises(TypeError, match=r"^timeout: expected a Duration or a number of seconds, got '1s'$"):
        b.lookup_transform("map", "base", Time(), timeout="1s")
    with pytest.raises(ValueError, match=r"^timeout: expected >= 0, got -1$"):
        b.can_transform("map", "base", Time(), timeout=-1)


def test_buffer_takes_tf2_ros_cache_time_as_a_duration():
    # tf2_ros buffer.py: Buffer(cache_time: Duration = None, node=None)
    assert Buffer(Duration(seconds=5)).cache_time_sec == 5.0
    assert Buffer(cache_time=Duration(seconds=2.5)).cache_time_sec == 2.5
    assert Buffer(7.0).cache_time_sec == 7.0
