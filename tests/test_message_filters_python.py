"""The Python message_filters package's behaviour, restated from its own tests (ros2/message_filters)."""

import random
import time

import numpy as np
import pytest

from aiorobot import Duration, Node, Time
from aiorobot.message_filters import (
    ApproximateEpsilonTimePolicy,
    ApproximateTimeSynchronizer,
    Cache,
    LatestTimePolicy,
    PythonApproximateTimePolicy,
    PythonExactTimePolicy,
    SimpleFilter,
    Subscriber,
    Synchronizer,
    TimeSynchronizer,
)
from aiorobot.msgs.geometry_msgs import PointStamped, Vector3Stamped
from aiorobot.msgs.std_msgs import Header, String
from aiorobot.testing import settle


class MockHeader:
    pass


class MockMessage:
    def __init__(self, stamp, data):
        self.header = MockHeader()
        self.header.stamp = stamp
        self.data = data


class MockHeaderlessMessage:
    def __init__(self, data):
        self.data = data


def test_approx_pairs_are_delivered_as_soon_as_they_exist():
    # message_filters test/test_approxsync.py::TestApproxSync::test_approx (first part)
    m0, m1 = SimpleFilter(), SimpleFilter()
    ts = ApproximateTimeSynchronizer([m0, m1], 1, 0.1)
    collector = []
    ts.registerCallback(lambda a, b: collector.append((a, b)))
    for t in range(10):
        collector.clear()
        msg0 = MockMessage(Time(seconds=t).to_msg(), 33)
        msg1 = MockMessage(Time(seconds=t).to_msg(), 34)
        m0.signalMessage(msg0)
        assert collector == []
        m1.signalMessage(msg1)
        assert collector == [(msg0, msg1)]


def test_approx_recombines_scrambled_sequences():
    # message_filters test/test_approxsync.py::TestApproxSync::test_approx (scrambled sequences);
    # the stamps are aiorobot.Time objects, as upstream uses rclpy Time in the header.
    random.seed(0)
    for n in range(1, 10):
        m0, m1 = SimpleFilter(), SimpleFilter()
        seq0 = [MockMessage(Time(seconds=t), random.random()) for t in range(n)]
        seq1 = [MockMessage(Time(seconds=t), random.random()) for t in range(n)]
        ts = ApproximateTimeSynchronizer([m0, m1], n, 0.1)
        collector = []
        ts.registerCallback(lambda a, b: collector.append((a, b)))
        for msg in random.sample(seq0, n):
            m0.signalMessage(msg)
        assert collector == []
        for msg in random.sample(seq1, n):
            m1.signalMessage(msg)
        assert set(collector) == set(zip(seq0, seq1))


def test_approx_pairs_headerless_messages_stamped_on_arrival():
    # message_filters test/test_approxsync.py::TestApproxSync::test_approx (headerless part)
    random.seed(0)
    for n in range(1, 10):
        m0, m1 = SimpleFilter(), SimpleFilter()
        now = time.time_ns()
        seq0 = [MockMessage(Time(nanoseconds=now + t * 1_000_000_000), random.random()) for t in range(n)]
        seq1 = [MockHeaderlessMessage(random.random()) for _ in range(n)]
        ts = ApproximateTimeSynchronizer([m0, m1], n, 10, allow_headerless=True)
        collector = []
        ts.registerCallback(lambda a, b: collector.append((a, b)))
        for msg in random.sample(seq0, n):
            m0.signalMessage(msg)
        assert collector == []
        for msg in seq1:
            m1.signalMessage(msg)
        assert set(collector) == set(zip(seq0, seq1))


def test_registered_callback_gets_the_extra_arguments():
    # message_filters src/message_filters/__init__.py SimpleFilter.registerCallback(cb, *args)
    f = SimpleFilter()
    got = []
    f.registerCallback(lambda m, tag: got.append((m, tag)), "extra")
    f.signalMessage("m")
    assert got == [("m", "extra")]


def test_signal_message_without_a_loop_refuses_async_callbacks():
    f = SimpleFilter()

    async def cb(m):
        pass

    f.registerCallback(cb)
    with pytest.raises(RuntimeError, match=r"a callback is async but no event loop is running"):
        f.signalMessage("m")


async def test_signal_message_schedules_async_callbacks_in_order():
    f = SimpleFilter()
    got = []

    async def first(m):
        got.append(("first", m))

    f.registerCallback(first)
    f.registerCallback(lambda m: got.append(("second", m)))
    f.signalMessage("m")
    assert got == []  # the async one runs as a task; the plain one waits for it (order kept)
    await settle_tasks(f)
    assert got == [("first", "m"), ("second", "m")]


async def settle_tasks(f):
    while f._tasks:
        await next(iter(f._tasks))


def test_python_time_synchronizer_matches_out_of_order_input():
    # message_filters src/message_filters/__init__.py TimeSynchronizer.add: per-input queues, common stamps
    p = PythonExactTimePolicy(2, 3)
    assert p.add(0, 3, "a3") == [] and p.add(0, 1, "a1") == [] and p.add(0, 2, "a2") == []
    assert p.add(1, 2, "b2") == [("a2", "b2")]
    assert p.add(1, 1, "b1") == [("a1", "b1")]  # older than a delivered set: still matched
    assert p.add(0, 4, "a4") == [] and p.add(0, 5, "a5") == [] and p.add(0, 6, "a6") == []
    assert p.queued(0) == 3 and p.dropped == 1  # a3 fell out of the full queue
    assert p.add(1, 3, "b3") == []


def test_python_approximate_picks_the_closest_stamps_first():
    p = PythonApproximateTimePolicy(3, 5, slop_ns=10)
    p.add(1, 100, "b100")
    p.add(1, 104, "b104")
    p.add(2, 95, "c95")
    p.add(2, 103, "c103")
    assert p.add(0, 105, "a105") == [("a105", "b104", "c103")]
    assert p.queued(1) == 1 and p.queued(2) == 1
    assert p.add(0, 98, "a98") == [("a98", "b100", "c95")]


def test_python_approximate_never_outputs_a_set_wider_than_the_slop():
    rng = np.random.default_rng(3)
    p = PythonApproximateTimePolicy(3, 8, slop_ns=20)
    for _ in range(500):
        index = int(rng.integers(3))
        stamp = int(rng.integers(0, 1000))
        for s in p.add(index, stamp, (index, stamp)):
            stamps = [x[1] for x in s]
            assert [x[0] for x in s] == [0, 1, 2]
            assert max(stamps) - min(stamps) <= 20


def test_python_approximate_with_zero_slop_matches_equal_stamps():
    p = PythonApproximateTimePolicy(2, 2, slop_ns=0)
    assert p.add(0, 7, "a") == [] and p.add(1, 7, "b") == [("a", "b")]


def _epsilon_run(events, epsilon_ns, queue_size=10):
    p = ApproximateEpsilonTimePolicy(2, queue_size, epsilon_ns)
    out = []
    for stamp, index in events:
        out.extend(p.add(index, stamp, stamp))
    return out


S = 1_000_000_000


def test_epsilon_exact_match():
    # message_filters test/test_approximate_epsilon_time_policy.cpp::ApproxTimeSync.ExactMatch
    events = [(0, 0), (0, 1), (3 * S, 0), (3 * S, 1), (6 * S, 0), (6 * S, 1)]
    assert _epsilon_run(events, S // 2) == [(0, 0), (3 * S, 3 * S), (6 * S, 6 * S)]


def test_epsilon_perfect_match():
    # message_filters test/test_approximate_epsilon_time_policy.cpp::ApproxTimeSync.PerfectMatch
    events = [(0, 0), (S, 1), (3 * S, 0), (4 * S, 1), (6 * S, 0), (7 * S, 1)]
    assert _epsilon_run(events, 3 * S // 2) == [(0, S), (3 * S, 4 * S), (6 * S, 7 * S)]


def test_epsilon_imperfect_match():
    # message_filters test/test_approximate_epsilon_time_policy.cpp::ApproxTimeSync.ImperfectMatch
    events = [(0, 0), (S, 1), (2 * S, 0), (3 * S, 0), (4 * S, 1), (6 * S, 0), (7 * S, 1)]
    assert _epsilon_run(events, 3 * S // 2) == [(0, S), (3 * S, 4 * S), (6 * S, 7 * S)]


def test_epsilon_policy_runs_in_a_synchronizer():
    m0, m1 = SimpleFilter(), SimpleFilter()
    sync = Synchronizer([m0, m1], ApproximateEpsilonTimePolicy(2, 10, epsilon_ns=S // 2))
    got = []
    sync.registerCallback(lambda a, b: got.append((a.data, b.data)))
    m0.signalMessage(MockMessage(Time(seconds=1), "a"))
    m1.signalMessage(MockMessage(Time(seconds=1.2), "b"))
    assert got == [("a", "b")]
    with pytest.raises(ValueError, match=r"^Synchronizer: the policy expects 2 inputs, got 3$"):
        Synchronizer([m0, m1, SimpleFilter()], ApproximateEpsilonTimePolicy(2, 10, epsilon_ns=1))


def test_policy_names_are_checked():
    m0, m1 = SimpleFilter(), SimpleFilter()
    expected = r"^ApproximateTimeSynchronizer policy: expected 'python' \(the Python message_filters\) or 'cpp' "
    with pytest.raises(ValueError, match=expected + r"\(the C\+\+ policy\), got 'best'$"):
        ApproximateTimeSynchronizer([m0, m1], 5, 0.1, policy="best")
    with pytest.raises(TypeError, match=r"needs the C\+\+ policy"):
        ApproximateTimeSynchronizer([m0, m1], 5, 0.1).set_inter_message_lower_bound(0, 0.1)


class AnonymMsg:
    def __init__(self, stamp):
        self.header = MockHeader()
        self.header.stamp = stamp


def test_cache_all_funcs():
    # message_filters test/test_message_filters_cache.py::TestCache::test_all_funcs
    cache = Cache(SimpleFilter(), 5)
    for t in range(5):
        cache.add(AnonymMsg(Time(seconds=t)))
    assert len(cache.getInterval(Time(seconds=2.5), Time(seconds=3.5))) == 1
    assert len(cache.getInterval(Time(seconds=2), Time(seconds=3))) == 2
    assert len(cache.getInterval(Time(), Time(seconds=4))) == 5
    assert cache.getElemAfterTime(Time()).header.stamp == Time()
    assert cache.getElemBeforeTime(Time(seconds=3.5)).header.stamp == Time(seconds=3)
    assert cache.getLastestTime() == Time(seconds=4)
    assert cache.getOldestTime() == Time()
    cache.add(AnonymMsg(Time(seconds=5)))
    assert cache.getOldestTime() == Time(seconds=1)  # the right one was discarded


def test_cache_headerless():
    # message_filters test/test_message_filters_cache.py::TestCache::test_headerless
    sub = SimpleFilter()
    msg = String()
    cache = Cache(sub, 5, allow_headerless=False)
    cache.add(msg)
    assert cache.getElemAfterTime(Time()) is None
    cache = Cache(sub, 5, True)  # positional, as upstream allows
    cache.add(msg)
    assert cache.getElemAfterTime(Time()) is msg
    current = Time(nanoseconds=time.time_ns())
    assert cache.getElemAfterTime(current) is None
    cache.add(msg)
    assert cache.getInterval(Time(), current) == [msg]
    assert cache.getInterval(Time(), current + Duration(seconds=2)) == [msg, msg]


def test_cache_add_passes_messages_on_synchronously():
    src = SimpleFilter()
    cache = Cache(src, 2)
    got = []
    cache.registerCallback(got.append)
    m = AnonymMsg(Time(seconds=1))
    src.signalMessage(m)
    assert got == [m] and cache.getLast() is m


def point(stamp_sec, x=0.0):
    msg = PointStamped(header=Header(stamp=Time(seconds=stamp_sec).to_msg()))
    msg.point.x = float(x)
    return msg


def vector(stamp_sec, x=0.0):
    msg = Vector3Stamped(header=Header(stamp=Time(seconds=stamp_sec).to_msg()))
    msg.vector.x = float(x)
    return msg


async def test_python_policy_end_to_end_delivers_every_pair_at_once(runtime):
    rng = np.random.default_rng(5)
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 50)
    pb = pubs.create_publisher(Vector3Stamped, "/b", 50)
    sync = ApproximateTimeSynchronizer(
        [Subscriber(node, PointStamped, "/a", 50), Subscriber(node, Vector3Stamped, "/b", qos_profile=50)],
        queue_size=10,
        slop=0.02,
    )
    got = []

    async def on_pair(a, b):
        got.append((int(a.point.x), int(b.vector.x)))

    sync.registerCallback(on_pair)
    for k in range(20):
        base = 1.0 + 0.1 * k
        # b before a on odd frames: arrival order does not matter
        msgs = [(pa, point(base + rng.uniform(-0.005, 0.005), x=k)), (pb, vector(base + rng.uniform(-0.005, 0.005), x=k))]
        for pub, m in msgs if k % 2 == 0 else reversed(msgs):
            pub.publish(m)
        await settle(runtime)
        assert got[-1] == (k, k)  # no waiting for the next frame
    assert got == [(k, k) for k in range(20)]


async def test_time_synchronizer_python_default_pairs_late_older_stamps(runtime):
    pubs = runtime.add_node(Node("pubs"))
    node = runtime.add_node(Node("listener"))
    pa = pubs.create_publisher(PointStamped, "/a", 10)
    pb = pubs.create_publisher(PointStamped, "/b", 10)
    sync = TimeSynchronizer([Subscriber(node, PointStamped, "/a"), Subscriber(node, PointStamped, "/b")], 10)
    got = []
    sync.registerCallback(lambda a, b: got.append(a.point.x))
    for t in (1.0, 2.0):
        pa.publish(point(t, x=t))
    pb.publish(point(2.0))
    pb.publish(point(1.0))
    await settle(runtime)
    assert got == [2.0, 1.0]
    assert Subscriber(node, PointStamped, "/c").getTopic() == "/c"


class FakeClock:
    def __init__(self):
        self.ns = 0

    def __call__(self):
        return self.ns


def _latest_run(schedule, steps):
    """Drive a 3-input LatestTimePolicy: ``schedule(idx)`` lists (input, data) added at step idx (20 ms apart).

    Returns, per step, (count, last output) as message_filters' test_latest_time_policy.cpp checks them.
    """
    clock = FakeClock()
    policy = LatestTimePolicy(3, now_ns=clock)
    count, last, seen = 0, None, []
    for idx in range(steps):
        for index, data in schedule(idx):
            for out in policy.add(index, 0, data):
                count += 1
                last = out
        seen.append((count, last))
        clock.ns += 20_000_000
    return seen


def test_latest_time_leading():
    # message_filters test/test_latest_time_policy.cpp::LatestTimePolicy.Leading
    def schedule(idx):
        adds = []
        if idx % 2 == 0:
            adds.append((1, ("q", idx // 2 * 2)))
        if idx % 4 == 0:
            adds.append((2, ("r", idx // 4 * 4)))
        adds.append((0, ("p", idx)))
        return adds

    for idx, (count, last) in enumerate(_latest_run(schedule, 8)):
        assert count == idx
        if idx > 0:
            assert last == (("p", idx), ("q", idx // 2 * 2), ("r", idx // 4 * 4))
        else:
            assert last is None


def test_latest_time_trailing():
    # message_filters test/test_latest_time_policy.cpp::LatestTimePolicy.Trailing
    def schedule(idx):
        adds = []
        if idx % 2 == 1:
            adds.append((1, ("q", (idx - 1) // 2)))
        if idx % 4 == 3:
            adds.append((2, ("r", (idx - 3) // 4)))
        adds.append((0, ("p", idx)))
        return adds

    for idx, (count, last) in enumerate(_latest_run(schedule, 8)):
        if idx > 2:
            assert count == idx - 2
            assert last == (("p", idx), ("q", (idx - 1) // 2), ("r", (idx - 3) // 4))
        else:
            assert last is None


def test_latest_time_change_rate_leading():
    # message_filters test/test_latest_time_policy.cpp::LatestTimePolicy.ChangeRateLeading
    p_next = iter(range(4, 12))

    def schedule(idx):
        adds = []
        if idx % 2 == 0:
            adds.append((1, ("q", idx // 2)))
        if idx % 4 == 0:
            adds.append((2, ("r", idx // 4)))
        if idx < 4:
            adds.append((0, ("p", idx)))
        elif idx % 3 == 0:  # p slows down
            adds.append((0, ("p", next(p_next))))
        return adds

    for idx, (count, last) in enumerate(_latest_run(schedule, 12)):
        if 1 <= idx < 4:
            assert (count, last) == (idx, (("p", idx), ("q", idx // 2), ("r", idx // 4)))
        elif 4 <= idx < 6:
            # p is slower but not yet found late: nothing new until q takes over as pivot at idx 6
            assert (count, last) == ((idx + 2) // 2, (("p", 3), ("q", 1), ("r", 0)))
        elif idx >= 6:
            assert count == (idx + 2) // 2
            assert last == (("p", idx // 2), ("q", idx // 2), ("r", (idx - 2) // 4))
        else:
            assert last is None


def test_latest_time_change_rate_trailing():
    # message_filters test/test_latest_time_policy.cpp::LatestTimePolicy.ChangeRateTrailing
    p_next = iter(range(4, 12))

    def schedule(idx):
        adds = []
        if idx % 2 == 1:
            adds.append((1, ("q", (idx - 1) // 2)))
        if idx % 4 == 3:
            adds.append((2, ("r", (idx - 3) // 4)))
        if idx < 4:
            adds.append((0, ("p", idx)))
        elif idx % 3 == 1:
            adds.append((0, ("p", next(p_next))))
        return adds

    for idx, (count, last) in enumerate(_latest_run(schedule, 12)):
        if 2 < idx <= 4:
            assert count == idx - 2
            assert last == (("p", idx), ("q", (idx - 1) // 2), ("r", (idx - 3) // 4))
        elif 4 < idx < 7:
            assert (count, last) == (2, (("p", 4), ("q", 1), ("r", 0)))
        elif idx >= 7:
            assert count == (idx - 1) // 2
            assert last == (("p", (idx + 1) // 2), ("q", (idx - 1) // 2), ("r", (idx - 5) // 4))
        else:
            assert last is None


async def test_latest_time_synchronizer_on_sim_time_with_headerless_messages(sim_runtime, sim_clock):
    pubs = sim_runtime.add_node(Node("pubs"))
    node = sim_runtime.add_node(Node("listener"))
    fast = pubs.create_publisher(String, "/fast", 10)
    slow = pubs.create_publisher(String, "/slow", 10)
    sync = Synchronizer(
        [Subscriber(node, String, "/fast"), Subscriber(node, String, "/slow")], LatestTimePolicy(2)
    )
    got = []
    sync.registerCallback(lambda f, s: got.append((f.data, s.data)))
    for k in range(8):
        if k % 4 == 0:
            slow.publish(String(data=f"s{k}"))  # leading the fast one, as in the Leading test
            await settle(sim_runtime)
        fast.publish(String(data=f"f{k}"))
        await settle(sim_runtime)
        await sim_clock.advance(0.01)
    assert got == [(f"f{k}", f"s{k // 4 * 4}") for k in range(1, 8)]  # the slow one is held


def _cache_msg(sec, data):
    return MockMessage(Time(seconds=sec), data)


def _fill_easy(cache, start, end):
    for i in range(start, end):
        cache.add(_cache_msg(i * 10, i))


def test_cache_empty_surrounding_interval():
    # message_filters test/msg_cache_unittest.cpp::Cache.emptySurroundingInterval
    assert Cache(SimpleFilter(), 10).getSurroundingInterval(Time(seconds=5), Time(seconds=9)) == []


def test_cache_easy_interval():
    # message_filters test/msg_cache_unittest.cpp::Cache.easyInterval
    cache = Cache(SimpleFilter(), 10)
    _fill_easy(cache, 0, 5)
    assert [m.data for m in cache.getInterval(Time(seconds=5), Time(seconds=35))] == [1, 2, 3]
    assert cache.getInterval(Time(seconds=55), Time(seconds=65)) == []
    _fill_easy(cache, 5, 20)  # the old ones fall off the back
    assert cache.getInterval(Time(seconds=5), Time(seconds=35)) == []


def test_cache_easy_surrounding_interval():
    # message_filters test/msg_cache_unittest.cpp::Cache.easySurroundingInterval
    cache = Cache(SimpleFilter(), 10)
    _fill_easy(cache, 1, 6)
    around = cache.getSurroundingInterval
    assert [m.data for m in around(Time(seconds=15), Time(seconds=35))] == [1, 2, 3, 4]
    assert [m.data for m in around(Time(seconds=0), Time(seconds=35))] == [1, 2, 3, 4]
    assert [m.data for m in around(Time(seconds=35), Time(seconds=35))] == [3, 4]
    assert [m.data for m in around(Time(seconds=55), Time(seconds=55))] == [5]


def test_cache_easy_unsorted():
    # message_filters test/msg_cache_unittest.cpp::Cache.easyUnsorted
    cache = Cache(SimpleFilter(), 10)
    for sec, data in ((10, 1), (30, 3), (70, 7), (5, 0), (20, 2)):
        cache.add(_cache_msg(sec, data))
    assert [m.data for m in cache.getInterval(Time(seconds=3), Time(seconds=15))] == [0, 1]
    assert [m.data for m in cache.getInterval(Time(seconds=0), Time(seconds=80))] == [0, 1, 2, 3, 7]


def test_cache_easy_elem_before_after():
    # message_filters test/msg_cache_unittest.cpp::Cache.easyElemBeforeAfter
    cache = Cache(SimpleFilter(), 10)
    _fill_easy(cache, 5, 10)
    assert cache.getElemAfterTime(Time(seconds=85)).data == 9
    assert cache.getElemBeforeTime(Time(seconds=85)).data == 8
    assert cache.getElemBeforeTime(Time(seconds=45)) is None
