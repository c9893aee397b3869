"""Message filters on a runtime: publishers -> Subscriber filters -> synchronizer -> callback."""

import logging

import numpy as np
import pytest

from aiorobot import Node, Time
from aiorobot.message_filters import (
    ApproximateTimeSynchronizer,
    Cache,
    SimpleFilter,
    Subscriber,
    TimeSynchronizer,
)
from aiorobot.msgs.geometry_msgs import PointStamped, Vector3Stamped
from aiorobot.msgs.std_msgs import Header, String
from aiorobot.testing import settle


def point(stamp_sec, x=0.0):
    msg = PointStamped(header=Header(stamp=Time(seconds=stamp_sec).to_msg()))
    msg.point.x = float(x)
    return msg


def vector(stamp_sec, x=0.0):
    msg = Vector3Stamped(header=Header(stamp=Time(seconds=stamp_sec).to_msg()))
    msg.vector.x = float(x)
    return msg


def stamp_sec(msg):
    return Time.from_msg(msg.header.stamp).nanoseconds / 1e9


async def test_time_synchronizer_pairs_equal_stamps_and_drops_unmatched(runtime):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    pb = pubs.create_publisher(Vector3Stamped, "/b", 10)
    sync = TimeSynchronizer([Subscriber(node, PointStamped, "/a"), Subscriber(node, Vector3Stamped, "/b")], 10)
    got = []
    sync.register_callback(lambda a, b: got.append((stamp_sec(a), stamp_sec(b), a.point.x, b.vector.x)))
    for t in (1.0, 2.0, 3.0):
        pa.publish(point(t, x=t))
    await settle(runtime)
    for t in (1.0, 2.5, 3.0):
        pb.publish(vector(t, x=-t))
    await settle(runtime)
    # 1.0 pairs; 2.0 (a) and 2.5 (b) never match; 3.0 pairs.
    assert got == [(1.0, 1.0, 1.0, -1.0), (3.0, 3.0, 3.0, -3.0)]


async def test_approximate_synchronizer_end_to_end_with_jittered_stamps(runtime):
    rng = np.random.default_rng(5)
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 50)
    pb = pubs.create_publisher(Vector3Stamped, "/b", 50)
    sync = ApproximateTimeSynchronizer(
        [Subscriber(node, PointStamped, "/a", 50), Subscriber(node, Vector3Stamped, "/b", 50)],
        queue_size=10,
        slop=0.02, policy="cpp",
    )
    got = []

    async def on_pair(a, b):  # async callbacks are awaited
        got.append((int(a.point.x), int(b.vector.x)))

    sync.register_callback(on_pair)
    for k in range(40):
        base = 1.0 + 0.1 * k
        pa.publish(point(base + rng.uniform(-0.005, 0.005), x=k))
        pb.publish(vector(base + rng.uniform(-0.005, 0.005), x=k))
        await settle(runtime)
    # Each frame k pairs with its own k; the newest pair waits for a newer message.
    assert got == [(k, k) for k in range(len(got))]
    assert len(got) >= 39


async def test_three_inputs_call_back_in_the_order_given(runtime):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    topics = ["/x", "/y", "/z"]
    publishers = [pubs.create_publisher(PointStamped, t, 10) for t in topics]
    subs = [Subscriber(node, PointStamped, t) for t in reversed(topics)]  # z, y, x
    sync = ApproximateTimeSynchronizer(subs, queue_size=5, slop=0.05)
    got = []
    sync.register_callback(lambda *msgs: got.append(tuple(m.point.x for m in msgs)))
    for t in (1.0, 2.0, 3.0):
        for i, pub in enumerate(publishers):
            pub.publish(point(t + 0.01 * i, x=10 * t + i))  # x: 10t, y: 10t+1, z: 10t+2
        await settle(runtime)
    assert got[:2] == [(12.0, 11.0, 10.0), (22.0, 21.0, 20.0)]


async def test_headerless_messages_are_dropped_with_a_warning(runtime, caplog):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    ps = pubs.create_publisher(String, "/s", 10)
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    sync = ApproximateTimeSynchronizer([Subscriber(node, String, "/s"), Subscriber(node, PointStamped, "/a")], 5, 0.1)
    got = []
    sync.register_callback(lambda *m: got.append(m))
    with caplog.at_level(logging.WARNING, logger="aiorobot.message_filters"):
        ps.publish(String(data="x"))
        ps.publish(String(data="y"))
        pa.publish(point(1.0))
        await settle(runtime)
    assert got == []
    warnings = [r for r in caplog.records if "has no header.stamp" in r.getMessage()]
    assert len(warnings) == 1 and "allow_headerless=True" in warnings[0].getMessage()


async def test_allow_headerless_stamps_with_the_node_clock(sim_runtime, sim_clock):
    pubs = sim_runtime.add_node(Node("pubs"))
    node = sim_runtime.add_node(Node("listener"))
    ps = pubs.create_publisher(String, "/s", 10)
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    sync = ApproximateTimeSynchronizer(
        [Subscriber(node, String, "/s"), Subscriber(node, PointStamped, "/a")], 5, 0.01, allow_headerless=True
    )
    got = []
    sync.register_callback(lambda s, a: got.append((s.data, stamp_sec(a))))
    ps.publish(String(data="at one"))  # sim time is 1.0 s
    pa.publish(point(1.0))
    await settle(sim_runtime)
    await sim_clock.set(2.0)
    ps.publish(String(data="at two"))
    await settle(sim_runtime)
    assert got == [("at one", 1.0)]


async def test_cache_keeps_the_newest_messages_by_stamp(runtime):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    cache = Cache(Subscriber(node, PointStamped, "/a"), cache_size=3)
    passed = []
    cache.register_callback(lambda m: passed.append(stamp_sec(m)))
    for t in (1.0, 3.0, 2.0, 4.0):
        pa.publish(point(t))
    await settle(runtime)
    assert passed == [1.0, 3.0, 2.0, 4.0]
    assert [stamp_sec(m) for m in cache.get_interval(Time(seconds=0), Time(seconds=10))] == [2.0, 3.0, 4.0]
    assert cache.get_oldest_time() == Time(seconds=2) and cache.get_latest_time() == Time(seconds=4)
    assert stamp_sec(cache.get_elem_after_time(Time(seconds=2.5))) == 3.0
    assert stamp_sec(cache.get_elem_before_time(Time(seconds=2.5))) == 2.0
    assert cache.get_elem_after_time(Time(seconds=5)) is None
    assert stamp_sec(cache.get_last()) == 4.0


async def test_cache_feeds_a_synchronizer(runtime):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    pb = pubs.create_publisher(PointStamped, "/b", 10)
    cache = Cache(Subscriber(node, PointStamped, "/a"), cache_size=5)
    sync = TimeSynchronizer([cache, Subscriber(node, PointStamped, "/b")], 5)
    got = []
    sync.register_callback(lambda a, b: got.append(stamp_sec(a)))
    pa.publish(point(1.0))
    pb.publish(point(1.0))
    await settle(runtime)
    assert got == [1.0] and len(cache) == 1


async def test_disconnected_callbacks_are_not_called():
    f = SimpleFilter()
    got, kept = [], []
    conn = f.register_callback(got.append)
    f.register_callback(kept.append)
    conn.disconnect()
    await f.signal_message("m")
    assert not conn.connected and got == [] and kept == ["m"]


async def test_synchronizer_rejects_non_filter_inputs(runtime):
    node = runtime.add_node(Node("listener"))
    with pytest.raises(TypeError, match=r"inputs must be message filters \(e\.g\. message_filters\.Subscriber\), got '/a'"):
        TimeSynchronizer([Subscriber(node, PointStamped, "/b"), "/a"], 10)
    with pytest.raises(ValueError, match=r"^slop: expected a number of seconds >= 0, got -0\.1$"):
        ApproximateTimeSynchronizer([Subscriber(node, PointStamped, "/c"), Subscriber(node, PointStamped, "/d")], 5, -0.1)


async def test_inputs_on_the_main_and_priority_loops_synchronize(runtime):
    pubs = runtime.add_node(Node("pubs"))
    main_node = runtime.add_node(Node("main_listener"))
    prio_node = runtime.add_node(Node("prio_listener"), executor="priority")
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    pb = pubs.create_publisher(PointStamped, "/b", 10)
    sync = TimeSynchronizer([Subscriber(main_node, PointStamped, "/a"), Subscriber(prio_node, PointStamped, "/b")], 10)
    got = []
    sync.register_callback(lambda a, b: got.append((a.point.x, b.point.x)))
    for t in (1.0, 2.0, 3.0):
        pa.publish(point(t, x=t))
        pb.publish(point(t, x=-t))
        await settle(runtime)
    assert got == [(1.0, -1.0), (2.0, -2.0), (3.0, -3.0)]
