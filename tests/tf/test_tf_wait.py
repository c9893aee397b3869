"""Waiting for transforms: woken by inserts (same loop, other threads, other loops), never by polling."""

from __future__ import annotations

import asyncio
import threading

import pytest
from _tf_helpers import sec_of, tf, xyz_of

from aiorobot import Time
from aiorobot.tf import Buffer, ExtrapolationException, InvalidArgumentException, LookupException

GENEROUS_SEC = 30.0  # bounds only a broken wake-up would reach


async def _registered(task: asyncio.Task) -> None:
    """Let a freshly created waiting task run up to its first await (no wall-clock sleep)."""
    for _ in range(3):
        await asyncio.sleep(0)
    assert not task.done()


async def test_wait_for_transform_returns_when_the_data_is_inserted():
    b = Buffer()
    task = asyncio.create_task(b.wait_for_transform("map", "base_link", Time(seconds=1), GENEROUS_SEC))
    await _registered(task)
    b.set_transform(tf("map", "base_link", 1, (1, 0, 0)), "t")
    await task
    assert xyz_of(b.lookup_transform("map", "base_link", Time(seconds=1))) == pytest.approx((1, 0, 0))


async def test_wait_is_not_satisfied_by_data_that_does_not_reach_the_time():
    b = Buffer()
    b.set_transform(tf("map", "base_link", 1), "t")
    task = asyncio.create_task(b.wait_for_transform("map", "base_link", Time(seconds=2), GENEROUS_SEC))
    await _registered(task)
    b.set_transform(tf("map", "base_link", 1.5), "t")
    await _registered(task)  # still waiting: 1.5 < 2
    b.set_transform(tf("map", "base_link", 2.5), "t")
    await task


async def test_wait_returns_at_once_when_already_available():
    b = Buffer()
    b.set_transform(tf("map", "base_link", 1), "t")
    await b.wait_for_transform("map", "base_link", Time(seconds=1), timeout_sec=0)


async def test_wait_woken_by_an_insert_from_another_thread():
    b = Buffer()
    task = asyncio.create_task(b.lookup_transform_async("map", "base_link", Time(), timeout_sec=GENEROUS_SEC))
    await _registered(task)
    await asyncio.to_thread(b.set_transform, tf("map", "base_link", 3, (2, 0, 0)), "t")
    out = await task
    assert sec_of(out) == 3.0
    assert xyz_of(out) == pytest.approx((2, 0, 0))


async def test_waiter_on_another_event_loop_is_woken_on_its_own_loop():
    b = Buffer()
    registered = threading.Event()
    result: dict[str, object] = {}

    async def waiter_side() -> None:
        task = asyncio.create_task(b.lookup_transform_async("map", "odom", Time(seconds=1), GENEROUS_SEC))
        await _registered(task)
        registered.set()
        result["out"] = await task
        result["loop"] = asyncio.get_running_loop()

    thread = threading.Thread(target=asyncio.run, args=(waiter_side(),))
    thread.start()
    assert await asyncio.to_thread(registered.wait, GENEROUS_SEC)
    b.set_transform(tf("map", "odom", 1, (0, 4, 0)), "t")  # inserted on this loop's thread
    await asyncio.to_thread(thread.join, GENEROUS_SEC)
    assert xyz_of(result["out"]) == pytest.approx((0, 4, 0))
    assert result["loop"] is not asyncio.get_running_loop()


async def test_timeout_raises_the_error_that_still_holds():
    b = Buffer()
    with pytest.raises(LookupException, match=r'^Timed out after 0.01 s waiting for the transform: "map" passed to'):
        await b.wait_for_transform("map", "base_link", Time(seconds=1), timeout_sec=0.01)
    b.set_transform(tf("map", "base_link", 1), "t")
    b.set_transform(tf("map", "base_link", 2), "t")
    with pytest.raises(ExtrapolationException, match=r"^Timed out after 0.01 s .*extrapolation into the future"):
        await b.lookup_transform_async("map", "base_link", Time(seconds=5), timeout_sec=0.01)


async def test_malformed_frame_ids_fail_at_once_instead_of_waiting():
    b = Buffer()
    with pytest.raises(InvalidArgumentException, match=r"frame_ids cannot start with a '/'"):
        await b.wait_for_transform("/map", "base_link", Time(), timeout_sec=GENEROUS_SEC)
    with pytest.raises(InvalidArgumentException, match=r"frame_ids cannot be empty"):
        await b.lookup_transform_async("map", "", Time(), timeout_sec=GENEROUS_SEC)


async def test_a_time_older_than_the_cache_can_hold_fails_at_once():
    b = Buffer(cache_time_sec=10.0)
    b.set_transform(tf("map", "base_link", 100), "t")
    b.set_transform(tf("map", "base_link", 101), "t")
    with pytest.raises(ExtrapolationException, match=r"it can never become available$"):
        await b.wait_for_transform("map", "base_link", Time(seconds=50), timeout_sec=GENEROUS_SEC)


async def test_pending_waiter_fails_once_the_data_moves_past_the_cache():
    b = Buffer(cache_time_sec=10.0)
    b.set_transform(tf("map", "base_link", 100), "t")
    b.set_transform(tf("map", "base_link", 101), "t")
    task = asyncio.create_task(b.wait_for_transform("map", "base_link", Time(seconds=95), GENEROUS_SEC))
    await _registered(task)
    b.set_transform(tf("map", "base_link", 110), "t")
    with pytest.raises(ExtrapolationException, match=r"never become available"):
        await task


async def test_cancelled_waiters_are_forgotten():
    b = Buffer()
    task = asyncio.create_task(b.wait_for_transform("map", "x", Time(seconds=1), GENEROUS_SEC))
    await _registered(task)
    task.cancel()
    with pytest.raises(asyncio.CancelledError):
        await task
    assert b._waiters == []
    b.set_transform(tf("map", "x", 1), "t")  # nothing left to wake


async def test_lookup_transform_full_async_waits_for_both_times():
    b = Buffer()
    b.set_transform(tf("odom", "base_link", 1), "t")
    task = asyncio.create_task(
        b.lookup_transform_full_async("base_link", Time(seconds=2), "base_link", Time(seconds=1), "odom", GENEROUS_SEC)
    )
    await _registered(task)
    b.set_transform(tf("odom", "base_link", 2, (1, 0, 0)), "t")
    out = await task
    assert xyz_of(out) == pytest.approx((-1, 0, 0))


async def test_blocking_wait_on_an_event_loop_thread_is_refused():
    from aiorobot.msgs.geometry_msgs import PointStamped
    from aiorobot.msgs.std_msgs import Header

    b = Buffer()
    msg = PointStamped(header=Header(stamp=Time(seconds=1).to_msg(), frame_id="a"))
    with pytest.raises(RuntimeError, match=r"use 'await buffer.transform_async"):
        b.transform(msg, "b", timeout_sec=1.0)


async def test_blocking_transform_in_a_worker_thread_is_woken_by_an_insert():
    from aiorobot.msgs.geometry_msgs import Point, PointStamped
    from aiorobot.msgs.std_msgs import Header

    b = Buffer()
    msg = PointStamped(header=Header(stamp=Time(seconds=1).to_msg(), frame_id="lidar"), point=Point(x=1.0))
    worker = asyncio.create_task(asyncio.to_thread(b.transform, msg, "map", GENEROUS_SEC))
    for _ in range(3):
        await asyncio.sleep(0)
    b.set_transform(tf("map", "lidar", 1, (0, 0, 2)), "t")
    out = await worker
    assert (out.point.x, out.point.y, out.point.z) == pytest.approx((1, 0, 2))
