"""EkfNode and ComplementaryFilter with the runtime: topics, tf, services, diagnostics, bad input."""

from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest

from aiorobot import Node, Runtime, Time
from aiorobot.fusion import ComplementaryFilter, EkfNode
from aiorobot.msgs.diagnostic_msgs import DiagnosticArray
from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped, TransformStamped
from aiorobot.msgs.nav_msgs import Odometry
from aiorobot.msgs.sensor_msgs import Imu
from aiorobot.msgs.std_srvs import Empty, SetBool
from aiorobot.tf import Buffer, TransformBroadcaster, TransformListener

TWIST_CONFIG = [False] * 6 + [True, True, False, False, False, True] + [False] * 3
POSE_CONFIG = [True, True, False, False, False, True] + [False] * 9


async def until(predicate, timeout_sec: float = 30.0) -> None:
    async with asyncio.timeout(timeout_sec):
        while not predicate():
            await asyncio.sleep(0.005)


class Probe(Node):
    def __init__(self, **kw):
        super().__init__("probe", **kw)
        self.odom_pub = self.create_publisher(Odometry, "/odom", 50)
        self.imu_pub = self.create_publisher(Imu, "/imu/data", 50)
        self.fix_pub = self.create_publisher(PoseWithCovarianceStamped, "/fix", 10)
        self.set_pose_pub = self.create_publisher(PoseWithCovarianceStamped, "set_pose", 10)
        self.filtered: list[Odometry] = []
        self.fused: list[Imu] = []
        self.diagnostics: list[DiagnosticArray] = []
        self.create_subscription(Odometry, "odometry/filtered", self.filtered.append, 100)
        self.create_subscription(Imu, "/imu/fused", self.fused.append, 100)
        self.create_subscription(DiagnosticArray, "/diagnostics", self.diagnostics.append, 10)
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.broadcaster = TransformBroadcaster(self)

    def odom(self, stamp_sec, vx=0.5, wz=0.0, *, frame="odom", child="base_link", cov=None, value=None):
        msg = Odometry()
        sec = math.floor(stamp_sec)
        msg.header.stamp.sec, msg.header.stamp.nanosec = int(sec), int((stamp_sec - sec) * 1e9)
        msg.header.frame_id, msg.child_frame_id = frame, child
        msg.twist.twist.linear.x = vx if value is None else value
        msg.twist.twist.angular.z = wz
        msg.twist.covariance = (np.eye(6) * 1e-4 if cov is None else cov).reshape(36)
        msg.pose.covariance = (np.eye(6) * 1e-2).reshape(36)
        self.odom_pub.publish(msg)

    def fix(self, stamp_sec, x, y, yaw=0.0, frame="map"):
        msg = PoseWithCovarianceStamped()
        sec = math.floor(stamp_sec)
        msg.header.stamp.sec, msg.header.stamp.nanosec = int(sec), int((stamp_sec - sec) * 1e9)
        msg.header.frame_id = frame
        msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        msg.pose.covariance = (np.eye(6) * 1e-4).reshape(36)
        self.fix_pub.publish(msg)


def _now(rt) -> float:
    return rt.now().nanoseconds * 1e-9


def _odom_ekf(**extra):
    return EkfNode(
        parameter_overrides={
            "two_d_mode": True,
            "odom0": "/odom",
            "odom0_config": TWIST_CONFIG,
            "odom0_queue_size": 100,
            "frequency": 50.0,
            "sensor_timeout": 10.0,
            **extra,
        }
    )


async def test_ekf_node_on_priority_loop_integrates_odometry_and_publishes_tf():
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        ekf = rt.add_node(_odom_ekf(), executor="priority")
        t0 = _now(rt)
        for k in range(51):
            probe.odom(t0 + 0.02 * k, vx=0.5)
        await until(lambda: probe.filtered and probe.filtered[-1].header.stamp.sec + probe.filtered[-1].header.stamp.nanosec * 1e-9 >= t0 + 1.0 - 1e-6)
        last = probe.filtered[-1]
        assert last.header.frame_id == "odom" and last.child_frame_id == "base_link"
        assert last.pose.pose.position.x == pytest.approx(0.5, abs=0.02)
        assert last.twist.twist.linear.x == pytest.approx(0.5, abs=1e-3)
        assert np.all(np.isfinite(last.pose.covariance))
        await until(lambda: probe.buffer.can_transform("odom", "base_link", Time()))
        t = probe.buffer.lookup_transform("odom", "base_link", Time())
        assert t.transform.translation.x == pytest.approx(0.5, abs=0.02)
        assert ekf.rejected_total() == {}


async def test_bad_input_is_rejected_counted_and_reported_on_diagnostics(caplog):
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        ekf = rt.add_node(
            _odom_ekf(odom1="/odom_off", odom1_config=[False] * 15, print_diagnostics=True), executor="priority"
        )
        off = probe.create_publisher(Odometry, "/odom_off", 10)
        t0 = _now(rt)
        probe.odom(t0, vx=0.5)
        probe.odom(t0 + 0.02, value=float("nan"))
        probe.odom(t0 + 0.03, value=float("inf"))
        asym = np.eye(6) * 1e-4
        asym[0, 1] = 1.0
        probe.odom(t0 + 0.04, cov=asym)
        probe.odom(t0 + 0.05, cov=-np.eye(6))
        probe.odom(t0 + 0.06, child="imu_link")
        probe.odom(t0 + 100.0)
        off.publish(Odometry())
        probe.odom(t0 + 0.1, vx=0.5)
        await until(lambda: ekf.received["odom0"] == 8 and ekf.received["odom1"] == 1)
        await until(lambda: probe.diagnostics and any("rejected" in kv.key for kv in probe.diagnostics[-1].status[0].values))
        reasons = {why: n for (src, why), n in ekf.rejected_total().items() if n}
        assert reasons == {
            "odom0 twist has NaN or inf": 2,
            "odom0 twist covariance is not symmetric": 1,
            "odom0 twist covariance is not positive semi-definite": 1,
            'twist frame is "imu_link", expected "base_link"': 1,
            "stamp more than future_tolerance_sec=1.0 s ahead of the clock": 1,
            "odom1_config selects no state member": 1,
        }
        assert np.all(np.isfinite(ekf.ekf.state)) and np.all(np.isfinite(ekf.ekf.covariance))
        assert ekf.ekf.state[6] == pytest.approx(0.5, abs=1e-3)
        status = probe.diagnostics[-1].status[0]
        values = {kv.key: kv.value for kv in status.values}
        assert values["odom0 rejected: odom0 twist has NaN or inf"] == "2"
        assert status.level == status.WARN
        warnings = [r.getMessage() for r in caplog.records if "rejected a message" in r.getMessage()]
        assert warnings and len(warnings) < 7  # throttled
        assert "odom0" in warnings[0]


async def test_map_instance_publishes_map_to_odom_through_odom_to_base_link():
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        ekf = rt.add_node(
            EkfNode(
                parameter_overrides={
                    "two_d_mode": True,
                    "world_frame": "map",
                    "pose0": "/fix",
                    "pose0_config": POSE_CONFIG,
                    "pose0_rejection_threshold": 5.0,
                    "sensor_timeout": 10.0,
                }
            ),
            executor="priority",
        )
        t0 = _now(rt)
        odom_base = TransformStamped()
        odom_base.header.stamp = rt.now().to_msg()
        odom_base.header.frame_id, odom_base.child_frame_id = "odom", "base_link"
        odom_base.transform.translation.x = 1.0
        odom_base.transform.rotation.w = 1.0
        probe.broadcaster.send_transform(odom_base)
        await until(lambda: ekf._tf_buffer.can_transform("odom", "base_link", Time()))
        probe.fix(t0, 3.0, 2.0, yaw=math.pi / 2)
        await until(lambda: probe.buffer.can_transform("map", "odom", Time()))
        t = probe.buffer.lookup_transform("map", "odom", Time())
        # map->base = (3, 2, 90 deg); odom->base = (1, 0, 0): map->odom = map->base * (odom->base)^-1
        assert t.transform.translation.x == pytest.approx(3.0, abs=1e-6)
        assert t.transform.translation.y == pytest.approx(1.0, abs=1e-6)
        assert 2 * math.atan2(t.transform.rotation.z, t.transform.rotation.w) == pytest.approx(math.pi / 2, abs=1e-6)
        # a 2 m jump is refused by the Mahalanobis threshold and counted
        probe.fix(t0 + 0.5, 5.0, 2.0, yaw=math.pi / 2)
        await until(lambda: sum(ekf.timeline.rejected.values()) == 1)
        assert ekf.ekf.state[0] == pytest.approx(3.0, abs=1e-3)


async def test_set_pose_toggle_and_reset():
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        ekf = rt.add_node(_odom_ekf(), executor="priority")
        t0 = _now(rt)
        probe.odom(t0, vx=0.5)
        await until(lambda: ekf.timeline.initialized)
        msg = PoseWithCovarianceStamped()
        msg.header.stamp = rt.now().to_msg()
        msg.pose.pose.position.x = 7.0
        msg.pose.pose.orientation.w = 1.0
        msg.pose.covariance = (np.eye(6) * 0.01).reshape(36)
        probe.set_pose_pub.publish(msg)
        await until(lambda: ekf.ekf.state[0] == 7.0)
        toggle = probe.create_client(SetBool, "toggle")
        await toggle.wait_for_service(5.0)
        assert (await toggle.call(SetBool.Request(data=False), timeout_sec=5.0)).success
        probe.odom(_now(rt) + 0.01, vx=1.0)
        await until(lambda: ekf.received["odom0"] == 2)
        assert ekf.ekf.state[6] == 0.0  # disabled: ignored
        await toggle.call(SetBool.Request(data=True), timeout_sec=5.0)
        reset = probe.create_client(Empty, "reset")
        await reset.call(Empty.Request(), timeout_sec=5.0)
        assert not ekf.timeline.initialized and ekf.ekf.state[0] == 0.0


def test_unknown_robot_localization_parameter_suggests_the_nearest_name():
    with pytest.raises(ValueError, match=r'^unknown robot_localization parameter "odom0_cofnig"; did you mean "odom0_config"\?$'):
        EkfNode(parameter_overrides={"odom0": "/odom", "odom0_cofnig": TWIST_CONFIG})
    with pytest.raises(ValueError, match=r'^unknown robot_localization parameter "imu0_remove_gravity_acceleration"; did you mean "imu0_remove_gravitational_acceleration"\?$'):
        EkfNode(parameter_overrides={"imu0": "/imu", "imu0_remove_gravity_acceleration": True})


def _imu(stamp_sec, gz, ax=0.0, ay=0.0, az=9.81):
    msg = Imu()
    sec = math.floor(stamp_sec)
    msg.header.stamp.sec, msg.header.stamp.nanosec = int(sec), int(round((stamp_sec - sec) * 1e9))
    msg.header.frame_id = "imu_link"
    msg.angular_velocity.z = gz
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = ax, ay, az
    return msg


async def test_complementary_filter_publishes_fused_orientation_with_the_imu_stamp():
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        node = rt.add_node(ComplementaryFilter(parameter_overrides={"alpha": 0.98}), executor="priority")
        for k in range(11):
            probe.imu_pub.publish(_imu(100.0 + 0.01 * k, gz=1.0))
        await until(lambda: len(probe.fused) == 11)
        last = probe.fused[-1]
        assert (last.header.stamp.sec, last.header.stamp.nanosec) == (100, 100_000_000)
        yaw = 2 * math.atan2(last.orientation.z, last.orientation.w)
        assert yaw == pytest.approx(0.1, abs=1e-9)  # no odometry yet: the gyro alone
        assert node.estimator.steps == 11


async def test_example_config_builds_both_filters_on_the_priority_loop_and_fuses_odometry(tmp_path):
    from pathlib import Path

    from aiorobot.launch import build_nodes, load_config

    example = Path(__file__).resolve().parents[2] / "examples" / "fusion_ekf.toml"
    built = build_nodes(load_config(example))
    assert [(type(n).__name__, ex) for n, ex in built] == [("EkfNode", "priority"), ("EkfNode", "priority")]
    async with Runtime() as rt:
        probe = rt.add_node(Probe())
        local: list[Odometry] = []
        probe.create_subscription(Odometry, "/local/odometry/filtered", local.append, 100)
        for node, executor in built:
            rt.add_node(node, executor=executor)
        t0 = _now(rt)
        for k in range(5):
            probe.odom(t0 + 0.02 * k, vx=0.5)
        await until(lambda: len(local) >= 5)
        assert local[-1].twist.twist.linear.x == pytest.approx(0.5, abs=1e-3)
        assert local[-1].header.frame_id == "odom"


def test_config_with_a_misspelt_parameter_names_the_nearest_valid_one(tmp_path):
    from aiorobot.launch import ConfigError, build_nodes, load_config

    path = tmp_path / "bad.toml"
    path.write_text(
        '[[nodes]]\nuse = "aiorobot.fusion:EkfNode"\nexecutor = "priority"\n'
        'parameters = { odom0 = "/odom", odom0_confg = [true, true] }\n'
    )
    with pytest.raises(ConfigError, match=r'unknown robot_localization parameter "odom0_confg"; did you mean "odom0_config"\?'):
        build_nodes(load_config(path))


async def test_sensor_timeout_is_measured_on_the_node_clock_so_it_follows_sim_time():
    # robot_localization compares ROS time: on sim time, half a second of /clock without input is half a
    # second, however little wall time it took (the wall clock here made the filter never predict alone).
    from aiorobot.testing import SimClock

    async with Runtime(use_sim_time=True) as rt:
        sim = SimClock(rt, start_sec=100.0, step_sec=0.01)
        await sim.start()
        probe = rt.add_node(Probe())
        quiet = rt.add_node(EkfNode("quiet", parameter_overrides={
            "two_d_mode": True, "odom0": "/odom", "odom0_config": TWIST_CONFIG, "frequency": 50.0,
            "sensor_timeout": 0.1, "odom_frame": "odom", "base_link_frame": "base_link",
        }))
        probe.odom(100.0, vx=0.5)
        await sim.advance(0.5)
        stamps = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in probe.filtered]
        assert quiet.timeline.initialized
        assert stamps and max(stamps) >= 100.45  # predicted alone, on sim time, after 0.1 s without input
        assert probe.filtered[-1].pose.pose.position.x == pytest.approx(0.5 * (max(stamps) - 100.0), abs=0.01)
