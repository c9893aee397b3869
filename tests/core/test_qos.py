import pytest

from aiorobot import (
    DurabilityPolicy,
    Duration,
    HistoryPolicy,
    QoSProfile,
    ReliabilityPolicy,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from aiorobot._qos import incompatibility, to_qos_profile


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


def test_keep_last_needs_depth_at_least_one():
    with pytest.raises(ValueError, match="at least 1"):
        QoSProfile(depth=0)
    assert QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=0).queue_limit is None


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
