"""QoS events as rclpy's event_handler: deadline, liveliness, lifespan, incompatible QoS/type, message lost,
matched.

Cases restate rclpy test/test_qos_event.py and rcl test/rcl/test_events.cpp (named per test);
deadlines and leases run on sim time, so nothing waits on the wall clock.
"""

import asyncio
import logging
import threading

import pytest

from aiorobot import (
    Duration,
    DurabilityPolicy,
    IncompatibleTypeInfo,
    LivelinessPolicy,
    Node,
    PublisherEventCallbacks,
    QoSLivelinessChangedInfo,
    QoSLivelinessLostInfo,
    QoSMessageLostInfo,
    QoSOfferedDeadlineMissedInfo,
    QoSOfferedIncompatibleQoSInfo,
    QoSPolicyKind,
    QoSProfile,
    QoSPublisherMatchedInfo,
    QoSRequestedDeadlineMissedInfo,
    QoSRequestedIncompatibleQoSInfo,
    QoSSubscriptionMatchedInfo,
    ReliabilityPolicy,
    SubscriptionEventCallbacks,
    qos_policy_name_from_kind,
)
from aiorobot.msgs.std_msgs import Empty, Int32, String
from aiorobot.testing import settle

TOPIC = "/test_topic"


def recorder():
    got = []
    return got, got.append


async def test_publisher_constructor(runtime):
    # rclpy test_qos_event.py::test_publisher_constructor (aiorobot registers no default handlers:
    # the counts are rclpy's minus its two default incompatible-QoS/type loggers)
    node = runtime.add_node(Node("TestQoSEvent", namespace="/rclpy/test"))
    callbacks = PublisherEventCallbacks()
    assert len(node.create_publisher(Empty, TOPIC, 10).event_handlers) == 0
    assert len(node.create_publisher(Empty, TOPIC, 10, event_callbacks=callbacks).event_handlers) == 0
    callbacks.deadline = lambda info: None
    assert len(node.create_publisher(Empty, TOPIC, 10, event_callbacks=callbacks).event_handlers) == 1
    callbacks.liveliness = lambda info: None
    assert len(node.create_publisher(Empty, TOPIC, 10, event_callbacks=callbacks).event_handlers) == 2
    callbacks.incompatible_qos = lambda info: None
    publisher = node.create_publisher(Empty, TOPIC, 10, event_callbacks=callbacks)
    assert len(publisher.event_handlers) == 3
    node.destroy_publisher(publisher)
    callbacks.matched = lambda info: None
    publisher = node.create_publisher(Empty, TOPIC, 10, event_callbacks=callbacks)
    assert [h.event_type.name for h in publisher.event_handlers][-1] == "RCL_PUBLISHER_MATCHED"


async def test_subscription_constructor(runtime):
    # rclpy test_qos_event.py::test_subscription_constructor
    node = runtime.add_node(Node("TestQoSEvent", namespace="/rclpy/test"))
    callbacks = SubscriptionEventCallbacks()
    cb = lambda msg: None  # noqa: E731
    assert len(node.create_subscription(Empty, TOPIC, cb, 10).event_handlers) == 0
    assert len(node.create_subscription(Empty, TOPIC, cb, 10, event_callbacks=callbacks).event_handlers) == 0
    callbacks.deadline = lambda info: None
    assert len(node.create_subscription(Empty, TOPIC, cb, 10, event_callbacks=callbacks).event_handlers) == 1
    callbacks.liveliness = lambda info: None
    assert len(node.create_subscription(Empty, TOPIC, cb, 10, event_callbacks=callbacks).event_handlers) == 2
    callbacks.incompatible_qos = lambda info: None
    assert len(node.create_subscription(Empty, TOPIC, cb, 10, event_callbacks=callbacks).event_handlers) == 3
    callbacks.matched = lambda info: None
    subscription = node.create_subscription(Empty, TOPIC, cb, 10, event_callbacks=callbacks)
    assert [h.event_type.name for h in subscription.event_handlers][-1] == "RCL_SUBSCRIPTION_MATCHED"


def test_event_callbacks_take_keywords_only_and_callables():
    with pytest.raises(TypeError):
        SubscriptionEventCallbacks(lambda info: None)  # type: ignore[misc]
    with pytest.raises(TypeError):
        PublisherEventCallbacks(lambda info: None)  # type: ignore[misc]


async def test_event_callbacks_must_be_callable(runtime):
    node = runtime.add_node(Node("n"))
    with pytest.raises(TypeError, match="SubscriptionEventCallbacks.deadline: expected a callable"):
        node.create_subscription(Empty, TOPIC, lambda m: None, 10,
                                 event_callbacks=SubscriptionEventCallbacks(deadline=5))
    with pytest.raises(TypeError, match="expected a PublisherEventCallbacks"):
        node.create_publisher(Empty, TOPIC, 10, event_callbacks=SubscriptionEventCallbacks())


async def test_call_rclpy_event_apis_start_at_zero(runtime):
    # rclpy test_qos_event.py::test_call_publisher_rclpy_event_apis and
    # ::test_call_subscription_rclpy_event_apis: nothing happened, so every status is zero
    node = runtime.add_node(Node("TestQoSEvent"))
    pub = node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(
        deadline=print, liveliness=print, incompatible_qos=print))
    sub = node.create_subscription(Empty, TOPIC, lambda m: None, 10, event_callbacks=SubscriptionEventCallbacks(
        deadline=print, liveliness=print, incompatible_qos=print, message_lost=print))
    deadline, liveliness, incompatible = pub.event_handlers
    assert deadline.take_event() == QoSOfferedDeadlineMissedInfo(total_count=0, total_count_change=0)
    assert liveliness.take_event() == QoSLivelinessLostInfo(total_count=0, total_count_change=0)
    info = incompatible.take_event()
    assert isinstance(info, QoSOfferedIncompatibleQoSInfo)
    assert (info.total_count, info.total_count_change, info.last_policy_kind) == (0, 0, QoSPolicyKind.INVALID)
    deadline, incompatible, _, lost = sub.event_handlers
    assert deadline.take_event() == QoSRequestedDeadlineMissedInfo()
    assert incompatible.take_event() == QoSRequestedIncompatibleQoSInfo(0, 0, QoSPolicyKind.INVALID)
    # rcl test_events.cpp::test_sub_message_lost_event
    assert lost.take_event() == QoSMessageLostInfo(total_count=0, total_count_change=0)


async def test_default_incompatible_qos_is_reported(runtime, caplog):
    # rclpy test_qos_event.py::test_default_incompatible_qos_callbacks: durability VOLATILE offered,
    # TRANSIENT_LOCAL requested; aiorobot logs one warning naming both endpoints and the policy
    node = runtime.add_node(Node("TestQoSEvent"))
    with caplog.at_level(logging.WARNING):
        node.create_publisher(Empty, TOPIC, QoSProfile(depth=10, durability=DurabilityPolicy.VOLATILE))
        node.create_subscription(Empty, TOPIC, lambda m: None,
                                 QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL))
    warnings = [r.getMessage() for r in caplog.records if "incompatible QoS" in r.getMessage()]
    assert len(warnings) == 1 and "durability" in warnings[0] and TOPIC in warnings[0]


LEASE = Duration(seconds=1)
DEADLINE = Duration(seconds=1)
# rcl test_events.cpp TestEventFixture::default_qos_profile (depth 0 means the system default)
BASE = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT, deadline=DEADLINE,
                  liveliness=LivelinessPolicy.MANUAL_BY_TOPIC, liveliness_lease_duration=LEASE)


def replaced(qos, **changes):
    fields = {f: getattr(qos, f) for f in QoSProfile.__dataclass_fields__}
    fields.update(changes)
    return QoSProfile(**fields)


INCOMPATIBLE = {
    # rcl test_events.cpp get_test_pubsub_incompatible_qos_inputs()
    "durability": (QoSPolicyKind.DURABILITY, {"durability": DurabilityPolicy.VOLATILE},
                   {"durability": DurabilityPolicy.TRANSIENT_LOCAL}),
    "deadline": (QoSPolicyKind.DEADLINE, {"deadline": Duration(seconds=6)}, {}),
    "liveliness": (QoSPolicyKind.LIVELINESS, {"liveliness": LivelinessPolicy.AUTOMATIC}, {}),
    "lease": (QoSPolicyKind.LIVELINESS, {"liveliness_lease_duration": Duration(seconds=6)}, {}),
    "reliability": (QoSPolicyKind.RELIABILITY, {"reliability": ReliabilityPolicy.BEST_EFFORT},
                    {"reliability": ReliabilityPolicy.RELIABLE}),
}


@pytest.mark.parametrize("case", sorted(INCOMPATIBLE))
async def test_pubsub_incompatible_qos(runtime, case, caplog):
    # rcl test_events.cpp::test_pubsub_incompatible_qos (each TestPubSubIncompatibility... input)
    kind, pub_changes, sub_changes = INCOMPATIBLE[case]
    node = runtime.add_node(Node("events"))
    pub_got, pub_cb = recorder()
    sub_got, sub_cb = recorder()
    node.create_publisher(String, TOPIC, replaced(BASE, **pub_changes),
                          event_callbacks=PublisherEventCallbacks(incompatible_qos=pub_cb))
    sub = node.create_subscription(String, TOPIC, lambda m: None, replaced(BASE, **sub_changes),
                                   event_callbacks=SubscriptionEventCallbacks(incompatible_qos=sub_cb))
    await settle(runtime)
    assert pub_got == [QoSOfferedIncompatibleQoSInfo(total_count=1, total_count_change=1, last_policy_kind=kind)]
    assert sub_got == [QoSRequestedIncompatibleQoSInfo(total_count=1, total_count_change=1, last_policy_kind=kind)]
    assert qos_policy_name_from_kind(kind) == kind.name
    assert sub.get_publisher_count() == 0
    # a second publisher that does not connect counts again
    node.create_publisher(String, TOPIC, replaced(BASE, **pub_changes))
    await settle(runtime)
    assert sub_got[-1].total_count == 2 and sub_got[-1].total_count_change == 1


async def test_incompatible_type_is_reported_to_both_endpoints(runtime):
    node = runtime.add_node(Node("events"))
    pub_got, pub_cb = recorder()
    sub_got, sub_cb = recorder()
    node.create_publisher(Int32, TOPIC, 10, event_callbacks=PublisherEventCallbacks(incompatible_type=pub_cb))
    node.create_subscription(String, TOPIC, lambda m: None, 10,
                             event_callbacks=SubscriptionEventCallbacks(incompatible_type=sub_cb))
    await settle(runtime)
    assert pub_got == [IncompatibleTypeInfo(total_count=1, total_count_change=1)]
    assert sub_got == [IncompatibleTypeInfo(total_count=1, total_count_change=1)]


def matched(total, total_change, current, current_change):
    return QoSPublisherMatchedInfo(total_count=total, total_count_change=total_change,
                                   current_count=current, current_count_change=current_change)


async def test_call_publisher_rclpy_event_matched(runtime):
    # rclpy test_qos_event.py::test_call_publisher_rclpy_event_matched: a subscription joins, then leaves
    node = runtime.add_node(Node("TestQoSEvent"))
    got, cb = recorder()
    pub = node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=cb))
    (handler,) = pub.event_handlers
    assert handler.event_type.name == "RCL_PUBLISHER_MATCHED"
    await settle(runtime)
    assert got == []  # nothing matched yet: not ready
    sub = node.create_subscription(Empty, TOPIC, lambda m: None, 10)
    await settle(runtime)
    assert got == [matched(1, 1, 1, 1)]
    assert isinstance(got[0], QoSPublisherMatchedInfo)
    sub.destroy()
    await settle(runtime)
    assert got[1:] == [matched(1, 0, 0, -1)]
    assert handler.take_event() == matched(1, 0, 0, 0)  # taking again: no change since


async def test_call_subscription_rclpy_event_matched_unmatched(runtime):
    # rclpy test_qos_event.py::test_call_subscription_rclpy_event_matched_unmatched
    node = runtime.add_node(Node("TestQoSEvent"))
    got, cb = recorder()
    sub = node.create_subscription(Empty, TOPIC, lambda m: None, 10,
                                   event_callbacks=SubscriptionEventCallbacks(matched=cb))
    assert sub.event_handlers[0].take_event() == QoSSubscriptionMatchedInfo(0, 0, 0, 0)
    await settle(runtime)
    assert got == []
    pub = node.create_publisher(Empty, TOPIC, 10)
    await settle(runtime)
    assert got == [matched(1, 1, 1, 1)]
    pub.destroy()
    await settle(runtime)
    assert got[1:] == [matched(1, 0, 0, -1)]


async def test_matched_counts_follow_the_demo_sequence(runtime):
    # demo_nodes_py events/matched_event_detect.py's steps: peers join and leave one at a time
    node = runtime.add_node(Node("detect"))
    peers = runtime.add_node(Node("peers"))
    pub_got, pub_cb = recorder()
    sub_got, sub_cb = recorder()
    pub = node.create_publisher(String, "/a", 10, event_callbacks=PublisherEventCallbacks(matched=pub_cb))
    node.create_subscription(String, "/b", lambda m: None, 10, event_callbacks=SubscriptionEventCallbacks(matched=sub_cb))
    subs = []
    for _ in range(2):
        subs.append(peers.create_subscription(String, "/a", lambda m: None, 10))
        await settle(runtime)
    for sub in subs:
        peers.destroy_subscription(sub)
        await settle(runtime)
    assert pub_got == [matched(1, 1, 1, 1), matched(2, 1, 2, 1), matched(2, 0, 1, -1), matched(2, 0, 0, -1)]
    assert pub.get_subscription_count() == 0
    pubs = []
    for _ in range(2):
        pubs.append(peers.create_publisher(String, "/b", 10))
        await settle(runtime)
    for p in pubs:
        peers.destroy_publisher(p)
        await settle(runtime)
    assert sub_got == pub_got


async def test_matched_events_coalesce_until_the_callback_runs(runtime):
    node = runtime.add_node(Node("n"))
    got, cb = recorder()
    node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=cb))
    first = node.create_subscription(Empty, TOPIC, lambda m: None, 10)
    node.create_subscription(Empty, TOPIC, lambda m: None, 10)
    first.destroy()  # no await between: one callback sees the net change
    await settle(runtime)
    assert got == [matched(2, 2, 1, 1)]


async def test_an_incompatible_peer_does_not_match(runtime):
    node = runtime.add_node(Node("n"))
    pub_got, pub_cb = recorder()
    sub_got, sub_cb = recorder()
    node.create_publisher(Empty, TOPIC, QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT),
                          event_callbacks=PublisherEventCallbacks(matched=pub_cb))
    node.create_subscription(Empty, TOPIC, lambda m: None, QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE),
                             event_callbacks=SubscriptionEventCallbacks(matched=sub_cb))
    node.create_subscription(Int32, TOPIC, lambda m: None, 10, event_callbacks=SubscriptionEventCallbacks(matched=sub_cb))
    await settle(runtime)
    assert pub_got == [] and sub_got == []


async def test_a_removed_node_unmatches_its_peers_and_reports_nothing_to_itself(runtime):
    node = runtime.add_node(Node("stays"))
    got, cb = recorder()
    gone_got, gone_cb = recorder()
    node.create_subscription(Empty, TOPIC, lambda m: None, 10, event_callbacks=SubscriptionEventCallbacks(matched=cb))
    leaving = runtime.add_node(Node("leaves"))
    leaving.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=gone_cb))
    await settle(runtime)
    assert got == [matched(1, 1, 1, 1)] and gone_got == [matched(1, 1, 1, 1)]
    runtime.remove_node(leaving)
    await settle(runtime)
    assert got[1:] == [matched(1, 0, 0, -1)]
    assert gone_got == [matched(1, 1, 1, 1)]


async def test_a_destroyed_endpoint_reports_nothing_to_itself(runtime):
    node = runtime.add_node(Node("n"))
    pub_got, pub_cb = recorder()
    sub_got, sub_cb = recorder()
    pub = node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=pub_cb))
    sub = node.create_subscription(Empty, TOPIC, lambda m: None, 10,
                                   event_callbacks=SubscriptionEventCallbacks(matched=sub_cb))
    await settle(runtime)
    node.destroy_publisher(pub)
    await settle(runtime)
    assert pub_got == [matched(1, 1, 1, 1)]
    assert sub_got == [matched(1, 1, 1, 1), matched(1, 0, 0, -1)]
    pub = node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=pub_cb))
    await settle(runtime)
    node.destroy_subscription(sub)
    await settle(runtime)
    assert pub_got[1:] == [matched(1, 1, 1, 1), matched(1, 0, 0, -1)]
    assert sub_got[2:] == [matched(2, 1, 1, 1)]


async def test_a_remote_endpoint_matches_and_unmatches_as_it_joins_and_leaves_the_bus(runtime):
    # what the zenoh transport does for a remote subscription (tests/transport/test_peers.py runs it on
    # zenoh): a Tap named after the remote node joins the bus, and leaves it when the peer goes; its
    # hidden sender tap is nobody's peer
    from aiorobot._core._pubsub import Tap

    node = runtime.add_node(Node("n"))
    got, cb = recorder()
    pub = node.create_publisher(Empty, TOPIC, 10, event_callbacks=PublisherEventCallbacks(matched=cb))
    sender = Tap(Empty, TOPIC, QoSProfile(depth=10), lambda m: None, owner="<zenoh>")
    sender.hidden = True
    runtime._bus.add_subscription(sender)
    remote = Tap(Empty, TOPIC, QoSProfile(depth=10), lambda m: None, owner="/remote_node")
    runtime._bus.add_subscription(remote)
    await settle(runtime)
    assert got == [matched(1, 1, 1, 1)] and pub.get_subscription_count() == 1
    runtime._bus.remove(remote)
    await settle(runtime)
    assert got[1:] == [matched(1, 0, 0, -1)]


class Pair:
    """A publisher and a subscription on one node with recorded deadline and liveliness events."""

    def __init__(self, runtime, pub_qos=BASE, sub_qos=BASE, executor="main"):
        self.node = runtime.add_node(Node("events"), executor=executor)
        self.pub_deadline, self.pub_liveliness, self.sub_deadline, self.sub_liveliness = [], [], [], []
        self.threads = set()
        self.received = []
        self.pub = self.node.create_publisher(String, TOPIC, pub_qos, event_callbacks=PublisherEventCallbacks(
            deadline=self._rec(self.pub_deadline), liveliness=self._rec(self.pub_liveliness)))
        self.sub = self.node.create_subscription(
            String, TOPIC, self.received.append, sub_qos, event_callbacks=SubscriptionEventCallbacks(
                deadline=self._rec(self.sub_deadline), liveliness=self._rec(self.sub_liveliness)))

    def _rec(self, into):
        def record(info):
            self.threads.add(threading.get_ident())
            into.append(info)
        return record


async def test_pubsub_no_deadline_missed(sim_runtime, sim_clock):
    # rcl test_events.cpp::test_pubsub_no_deadline_missed: a message within the deadline
    pair = Pair(sim_runtime)
    pair.pub.publish(String(data="testing"))
    await sim_clock.advance(0.5, step_sec=0.05)
    assert [m.data for m in pair.received] == ["testing"]
    assert pair.pub_deadline == [] and pair.sub_deadline == []
    assert pair.pub.event_handlers[0].take_event() == QoSOfferedDeadlineMissedInfo(0, 0)


async def test_pubsub_deadline_missed(sim_runtime, sim_clock):
    # rcl test_events.cpp::test_pubsub_deadline_missed: one message, then silence past the deadline
    pair = Pair(sim_runtime)
    pair.pub.publish(String(data="testing"))
    await sim_clock.advance(1.5, step_sec=0.05)
    assert pair.pub_deadline == [QoSOfferedDeadlineMissedInfo(total_count=1, total_count_change=1)]
    assert pair.sub_deadline == [QoSRequestedDeadlineMissedInfo(total_count=1, total_count_change=1)]
    await sim_clock.advance(1.0, step_sec=0.05)  # one more silent period: one more miss each
    assert pair.pub_deadline[-1] == QoSOfferedDeadlineMissedInfo(total_count=2, total_count_change=1)
    assert pair.sub_deadline[-1] == QoSRequestedDeadlineMissedInfo(total_count=2, total_count_change=1)


async def test_steady_publishing_within_the_deadline_misses_nothing(sim_runtime, sim_clock):
    pair = Pair(sim_runtime)
    for k in range(10):
        pair.pub.publish(String(data=str(k)))
        await sim_clock.advance(0.9, step_sec=0.1)
    assert len(pair.received) == 10
    assert pair.pub_deadline == [] and pair.sub_deadline == []
    assert pair.pub_liveliness == []


async def test_no_deadline_watch_before_the_first_message(sim_runtime, sim_clock):
    # DDS deadlines are per instance: the first period starts at the first message (rcl's tests)
    pair = Pair(sim_runtime)
    await sim_clock.advance(3.0, step_sec=0.1)
    assert pair.pub_deadline == [] and pair.sub_deadline == []


async def test_pubsub_liveliness_kill_pub(sim_runtime, sim_clock):
    # rcl test_events.cpp::test_pubsub_liveliness_kill_pub: a MANUAL_BY_TOPIC publisher goes silent
    pair = Pair(sim_runtime, pub_qos=replaced(BASE, deadline=None), sub_qos=replaced(BASE, deadline=None))
    pair.pub.publish(String(data="testing"))
    await settle(sim_runtime)
    assert pair.sub_liveliness == [QoSLivelinessChangedInfo(alive_count=1, not_alive_count=0,
                                                            alive_count_change=1, not_alive_count_change=0)]
    await sim_clock.advance(2.0, step_sec=0.05)
    assert pair.pub_liveliness == [QoSLivelinessLostInfo(total_count=1, total_count_change=1)]
    last = pair.sub_liveliness[-1]
    assert (last.alive_count, last.not_alive_count, last.alive_count_change, last.not_alive_count_change) == (
        0, 1, -1, 1)
    # asserting liveliness brings it back; silence loses it again, counted once per lapse
    pair.pub.assert_liveliness()
    await settle(sim_runtime)
    assert pair.sub_liveliness[-1] == QoSLivelinessChangedInfo(1, 0, 1, -1)
    await sim_clock.advance(3.0, step_sec=0.05)
    assert pair.pub_liveliness[-1] == QoSLivelinessLostInfo(total_count=2, total_count_change=1)
    assert len(pair.pub_liveliness) == 2


async def test_assert_liveliness_keeps_a_manual_publisher_alive(sim_runtime, sim_clock):
    pair = Pair(sim_runtime, pub_qos=replaced(BASE, deadline=None), sub_qos=replaced(BASE, deadline=None))
    for _ in range(8):
        await sim_clock.advance(0.5, step_sec=0.05)
        pair.pub.assert_liveliness()
    assert pair.pub_liveliness == []
    assert pair.sub_liveliness[-1].alive_count == 1


async def test_automatic_liveliness_follows_the_publisher_existing(sim_runtime, sim_clock):
    qos = QoSProfile(liveliness=LivelinessPolicy.AUTOMATIC, liveliness_lease_duration=LEASE)
    pair = Pair(sim_runtime, pub_qos=qos, sub_qos=qos)
    await sim_clock.advance(3.0, step_sec=0.1)
    assert pair.pub_liveliness == []
    assert pair.sub_liveliness == [QoSLivelinessChangedInfo(1, 0, 1, 0)]
    pair.node.destroy_publisher(pair.pub)
    await settle(sim_runtime)
    assert pair.sub_liveliness[-1] == QoSLivelinessChangedInfo(0, 0, -1, 0)


async def test_events_run_on_the_priority_loop_of_a_priority_node(sim_runtime, sim_clock):
    pair = Pair(sim_runtime, executor="priority")
    pair.pub.publish(String(data="x"))
    await sim_clock.advance(1.5, step_sec=0.05)
    for _ in range(100):  # the priority loop runs in its own thread
        if pair.pub_deadline and pair.sub_deadline:
            break
        await asyncio.sleep(0.01)
    assert pair.pub_deadline and pair.sub_deadline
    assert pair.threads == {pair.node._thread_id}
    assert pair.node._thread_id != threading.get_ident()


async def test_default_qos_has_no_watchers(runtime):
    node = runtime.add_node(Node("plain"))
    pub = node.create_publisher(Int32, TOPIC, 10)
    sub = node.create_subscription(Int32, TOPIC, lambda m: None, 10)
    await settle(runtime)
    assert pub._deadline is None and pub._liveliness is None and sub._deadline is None
    assert not pub._watched and pub.publish.__func__ is type(pub).publish  # the plain publish path
    assert sub._infos is None
    assert not [t for t in node._tasks if t.get_name() == "qos lease"]


async def test_message_lost_counts_messages_a_full_queue_dropped(runtime):
    node = runtime.add_node(Node("lossy"))
    got, cb = recorder()
    received = []
    sub = node.create_subscription(Int32, TOPIC, received.append, 1,
                                   event_callbacks=SubscriptionEventCallbacks(message_lost=cb))
    pub = node.create_publisher(Int32, TOPIC, 10)
    for k in range(3):  # no await between: the queue of one keeps only the last
        pub.publish(Int32(data=k))
    await settle(runtime)
    assert [m.data for m in received] == [2]
    assert got == [QoSMessageLostInfo(total_count=2, total_count_change=2)]
    assert sub.dropped == 2


async def test_lifespan_drops_expired_messages_from_the_late_joiner_history(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Node("latched"))
    qos = QoSProfile(depth=5, durability=DurabilityPolicy.TRANSIENT_LOCAL, lifespan=Duration(seconds=1))
    pub = node.create_publisher(Int32, TOPIC, qos)
    pub.publish(Int32(data=1))  # t = 1.0: expires at 2.0
    await sim_clock.advance(0.6, step_sec=0.1)
    pub.publish(Int32(data=2))  # t = 1.6: expires at 2.6
    await sim_clock.advance(0.6, step_sec=0.1)  # t = 2.2
    received = []
    node.create_subscription(Int32, TOPIC, received.append, qos)
    await settle(sim_runtime)
    assert [m.data for m in received] == [2]


async def test_lifespan_drops_expired_messages_from_a_queue(sim_runtime, sim_clock):
    node = sim_runtime.add_node(Node("queued"))
    pub = node.create_publisher(Int32, TOPIC, QoSProfile(depth=10, lifespan=Duration(seconds=1)))
    stream = node.subscribe(Int32, TOPIC, 10)
    pub.publish(Int32(data=1))
    await sim_clock.advance(1.5, step_sec=0.1)  # nobody reads: it expires in the queue
    pub.publish(Int32(data=2))
    msg = await asyncio.wait_for(stream.__anext__(), 5.0)
    assert msg.data == 2
    assert stream.subscription.queued == 0
    stream.close()


async def test_deadline_on_wall_time_fires(runtime):
    # the same watcher without sim time: a 20 ms deadline after one message fires (bounded wait)
    node = runtime.add_node(Node("wall"))
    missed = asyncio.Event()
    qos = QoSProfile(deadline=Duration(seconds=0.02))
    node.create_subscription(Int32, TOPIC, lambda m: None, qos,
                             event_callbacks=SubscriptionEventCallbacks(deadline=lambda info: missed.set()))
    node.create_publisher(Int32, TOPIC, qos).publish(Int32(data=1))
    await asyncio.wait_for(missed.wait(), 10.0)
