import warnings

import pytest

from aiorobot import (
    DurabilityPolicy,
    Duration,
    HistoryPolicy,
    Node,
    QoSPresetProfiles,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from aiorobot._core._qos import incompatibility, to_qos_profile
from aiorobot.msgs.std_msgs import Int32
from aiorobot.testing import settle


def test_defaults_match_ros2():
    qos = QoSProfile()
    assert qos.reliability is ReliabilityPolicy.RELIABLE
    assert qos.durability is DurabilityPolicy.VOLATILE
    assert qos.history is HistoryPolicy.KEEP_LAST
    assert qos.depth == 10
    assert qos_profile_system_default == qos


def test_sensor_data_preset_is_best_effort_depth_5():
    assert qos_profile_sensor_data.reliability is ReliabilityPolicy.BEST_EFFORT
    assert qos_profile_sensor_data.durability is DurabilityPolicy.VOLATILE
    assert qos_profile_sensor_data.depth == 5


def test_int_means_keep_last_with_that_depth():
    qos = to_qos_profile(7)
    assert qos.history is HistoryPolicy.KEEP_LAST and qos.depth == 7


@pytest.mark.parametrize("bad", [-1, 1.5, "10", True])
def test_bad_depth_is_rejected(bad):
    with pytest.raises((ValueError, TypeError)):
        QoSProfile(depth=bad) if not isinstance(bad, bool) else to_qos_profile(bad)


def test_keep_last_zero_depth_constructor():
    # rclpy test/test_qos.py::test_keep_last_zero_depth_constructor (issue 10 item 6: raised before)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", category=UserWarning)
        qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=0)
    assert len(caught) == 1 and issubclass(caught[0].category, UserWarning)
    assert "A zero depth with KEEP_LAST doesn't make sense" in str(caught[0])
    assert qos.history is HistoryPolicy.KEEP_LAST and qos.depth == 0
    assert qos.queue_limit == 10  # the system default queue, not none
    assert QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=0).queue_limit is None


def test_policy_short_keys():
    # rclpy test/test_qos.py::test_policy_short_names (the members aiorobot has)
    assert ReliabilityPolicy.short_keys() == ["reliable", "best_effort"]
    assert ReliabilityPolicy.get_from_short_key("reliable") == ReliabilityPolicy.RELIABLE.value
    assert ReliabilityPolicy.get_from_short_key("BEST_effort") == ReliabilityPolicy.BEST_EFFORT.value
    assert DurabilityPolicy.get_from_short_key("transient_local") == DurabilityPolicy.TRANSIENT_LOCAL.value
    assert HistoryPolicy.get_from_short_key("KEEP_ALL") == HistoryPolicy.KEEP_ALL.value
    assert HistoryPolicy.get_from_short_key("KEEP_last") == HistoryPolicy.KEEP_LAST.value
    assert HistoryPolicy.KEEP_LAST.short_key == "keep_last"
    with pytest.raises(KeyError):
        ReliabilityPolicy.get_from_short_key("system_default")


def test_preset_profiles():
    # rclpy test/test_qos.py::test_preset_profiles
    assert QoSPresetProfiles.SYSTEM_DEFAULT.value == qos_profile_system_default
    assert QoSPresetProfiles.SYSTEM_DEFAULT.value == QoSPresetProfiles.get_from_short_key("system_default")
    assert QoSPresetProfiles.get_from_short_key("SENSOR_DATA") is qos_profile_sensor_data
    assert "parameter_events" in QoSPresetProfiles.short_keys()
    assert QoSPresetProfiles.ACTION_STATUS_DEFAULT.value.durability is DurabilityPolicy.TRANSIENT_LOCAL


async def test_zero_depth_keep_last_subscription_receives(runtime):
    got = []
    node = runtime.add_node(Node("n"))
    with pytest.warns(UserWarning, match="zero depth"):
        qos = QoSProfile(depth=0)
    node.create_subscription(Int32, "/x", got.append, qos)
    node.create_publisher(Int32, "/x", 10).publish(Int32(data=1))
    await settle(runtime)
    assert [m.data for m in got] == [1]


def test_policies_accept_rmw_integers():
    assert QoSProfile(reliability=2).reliability is ReliabilityPolicy.BEST_EFFORT
    with pytest.raises(ValueError, match="ReliabilityPolicy"):
        QoSProfile(reliability=7)


@pytest.mark.parametrize(
    ("pub", "sub", "policy"),
    [
        (QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT), QoSProfile(), "reliability"),
        (QoSProfile(), QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL), "durability"),
        (
            QoSProfile(deadline=Duration(seconds=2)),
            QoSProfile(deadline=Duration(seconds=1)),
            "deadline",
        ),
    ],
)
def test_subscription_stricter_than_publisher_is_incompatible(pub, sub, policy):
    reason = incompatibility(pub, sub)
    assert reason is not None and reason.startswith(policy)


@pytest.mark.parametrize(
    ("pub", "sub"),
    [
        (QoSProfile(), QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT)),
        (QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL), QoSProfile()),
        (QoSProfile(), QoSProfile()),
    ],
)
def test_publisher_stricter_than_subscription_connects(pub, sub):
    assert incompatibility(pub, sub) is None


def test_liveliness_policy_and_lease():
    # rclpy test/test_qos.py: policies accept their int values; rmw's liveliness values
    from aiorobot import LivelinessPolicy

    qos = QoSProfile(liveliness=3, liveliness_lease_duration=Duration(seconds=1))
    assert qos.liveliness is LivelinessPolicy.MANUAL_BY_TOPIC
    assert QoSProfile().liveliness is LivelinessPolicy.AUTOMATIC
    assert LivelinessPolicy.get_from_short_key("manual_by_topic") == 3
    with pytest.raises(ValueError, match="QoSProfile.liveliness_lease_duration: expected a Duration"):
        QoSProfile(liveliness_lease_duration=1.0)
    with pytest.raises(ValueError, match="QoSProfile.liveliness: expected a LivelinessPolicy"):
        QoSProfile(liveliness=2)


def test_zero_and_infinite_durations_mean_no_limit():
    from aiorobot import Infinite
    from aiorobot._core._qos import finite_ns

    assert finite_ns(None) is None and finite_ns(Duration()) is None and finite_ns(Infinite) is None
    assert finite_ns(Duration(seconds=2)) == 2_000_000_000
    # a requested deadline of zero (rmw's "default") is no request at all
    assert incompatibility(QoSProfile(), QoSProfile(deadline=Duration())) is None


def test_qos_policy_kind_values_and_names():
    # rclpy qos.py QoSPolicyKind (rmw/incompatible_qos_events_statuses.h) and qos_policy_name_from_kind
    from aiorobot import QoSPolicyKind, qos_policy_name_from_kind

    assert [int(k) for k in QoSPolicyKind] == [1 << i for i in range(10)]
    assert qos_policy_name_from_kind(QoSPolicyKind.DURABILITY) == "DURABILITY"
    assert qos_policy_name_from_kind(1 << 4) == "RELIABILITY"
