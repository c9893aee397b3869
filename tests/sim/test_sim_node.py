"""The Simulator node: lock-step sim time, sensors on topics, cmd_vel, determinism, bad parameters."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import aiorobot
from aiorobot import Node, Runtime
from aiorobot.msgs import serialize
from aiorobot.msgs.geometry_msgs import Twist
from aiorobot.msgs.nav_msgs import OccupancyGrid, Odometry
from aiorobot.msgs.sensor_msgs import CameraInfo, Image, Imu, JointState, LaserScan
from aiorobot.sim import Simulator

TOPICS = {
    "/odom": Odometry,
    "/joint_states": JointState,
    "/imu/data": Imu,
    "/scan": LaserScan,
    "/camera/image_raw": Image,
    "/camera/camera_info": CameraInfo,
    "/ground_truth/odom": Odometry,
}


class Driver(Node):
    """Publishes ``speed`` on /cmd_vel from a 20 Hz sim-time timer until ``stop_sec``; records everything."""

    def __init__(self, speed: float = 0.2, stop_sec: float = 5.0, nan_at_sec: float | None = None) -> None:
        super().__init__("driver")
        self.speed, self.stop_ns, self.nan_at_ns = speed, round(stop_sec * 1e9), nan_at_sec
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.timer = self.create_timer(0.05, self.tick)
        self.ticks: list[int] = []
        self.log: list[tuple[str, bytes]] = []
        self.last: dict[str, Any] = {}
        for topic, msg_type in TOPICS.items():
            self.create_subscription(msg_type, topic, self._recorder(topic), 100)

    def _recorder(self, topic: str) -> Any:
        def record(msg: Any) -> None:
            self.log.append((topic, serialize(msg)))
            self.last[topic] = msg

        return record

    def tick(self) -> None:
        now = self.now().nanoseconds
        self.ticks.append(now)
        msg = Twist()
        msg.linear.x = self.speed if now <= self.stop_ns else 0.0
        if self.nan_at_ns is not None and abs(now - self.nan_at_ns * 1e9) < 1:
            msg.linear.x = math.nan
        self.pub.publish(msg)


async def _run(duration_sec: float, driver: Driver, **parameters: Any) -> Simulator:
    params = {"real_time_factor": 0.0, "duration_sec": duration_sec, **parameters}
    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = rt.add_node(Simulator(parameter_overrides=params))
        rt.add_node(driver)
        await rt.spin(duration_sec=60.0)
        assert sim.time_ns == round(duration_sec * 1e9)
    return sim


async def test_driving_0_2_m_s_for_5_s_moves_ground_truth_1_m_and_odometry_drifts_as_configured() -> None:
    driver = Driver(0.2, 5.0)
    sim = await _run(6.0, driver, odom_scale_error=0.05, odom_noise_std=0.0, camera_rate=0.0)
    truth = driver.last["/ground_truth/odom"].pose.pose.position
    odom = driver.last["/odom"].pose.pose.position
    assert truth.x == pytest.approx(1.0, rel=0.02) and abs(truth.y) < 1e-9
    assert odom.x == pytest.approx(1.05 * truth.x, rel=1e-3)
    assert sim.body.collisions == 0
    # the driver's 20 Hz timer fired on every deadline of sim time, in lock-step
    assert driver.ticks[:3] == [50_000_000, 100_000_000, 150_000_000]
    assert len(driver.ticks) == 120


async def test_sensor_streams_have_their_rates_frames_and_geometry() -> None:
    driver = Driver(0.0, 0.0)
    await _run(1.0, driver)
    counts = {topic: sum(1 for t, _ in driver.log if t == topic) for topic in TOPICS}
    assert counts == {"/odom": 50, "/joint_states": 50, "/imu/data": 100, "/scan": 10,
                      "/camera/image_raw": 15, "/camera/camera_info": 15, "/ground_truth/odom": 50}
    scan = driver.last["/scan"]
    assert scan.header.frame_id == "laser" and len(scan.ranges) == 360
    assert scan.range_min == pytest.approx(0.1) and scan.range_max == pytest.approx(12.0)
    assert scan.ranges[180] == pytest.approx(3.0, abs=5 * 0.01)  # forward beam, 5 sigma of the noise model
    imu = driver.last["/imu/data"]
    assert imu.header.frame_id == "imu_link" and imu.orientation_covariance[0] == -1.0
    assert imu.linear_acceleration.z == pytest.approx(9.80665, abs=0.1)
    assert driver.last["/odom"].header.frame_id == "odom" and driver.last["/odom"].child_frame_id == "base_link"
    assert driver.last["/ground_truth/odom"].header.frame_id == "map"
    assert list(driver.last["/joint_states"].name) == [
        "front_left_wheel_joint", "front_right_wheel_joint", "rear_left_wheel_joint", "rear_right_wheel_joint"]
    info = driver.last["/camera/camera_info"]
    assert info.k.tolist() == [500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0] and not np.any(info.d)
    image = driver.last["/camera/image_raw"]
    assert (image.encoding, image.width, image.height, image.header.frame_id) == ("rgb8", 640, 480, "camera_optical_frame")
    frame = np.asarray(image.data).reshape(480, 640, 3)
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    _, ids, _ = cv2.aruco.ArucoDetector(dictionary).detectMarkers(frame)
    assert ids is not None and ids.ravel().tolist() == [0]  # facing +x at the origin


async def test_static_frames_map_and_tf_lookups() -> None:
    from aiorobot.tf import Buffer, TransformListener

    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = rt.add_node(Simulator(parameter_overrides={"real_time_factor": 0.0, "duration_sec": 0.2,
                                                          "publish_odom_tf": True, "camera_rate": 0.0}))
        probe = rt.add_node(Node("probe"))
        buffer = Buffer()
        TransformListener(buffer, probe)
        maps: list[OccupancyGrid] = []
        probe.create_subscription(OccupancyGrid, "/map", maps.append,
                                  aiorobot.QoSProfile(depth=1, durability=aiorobot.DurabilityPolicy.TRANSIENT_LOCAL))
        await rt.spin(duration_sec=60.0)
        assert sim.time_ns == 200_000_000
    optical = buffer.lookup_transform("base_link", "camera_optical_frame", aiorobot.Time())
    assert (optical.transform.translation.x, optical.transform.translation.z) == pytest.approx((0.10, 0.25))
    for frame in ("laser", "imu_link"):
        assert buffer.can_transform("base_link", frame, aiorobot.Time())
    assert buffer.can_transform("odom", "laser", aiorobot.Time())
    assert len(maps) == 1 and maps[0].info.width == 140 and maps[0].info.resolution == pytest.approx(0.05)


async def test_nan_in_cmd_vel_is_ignored_with_a_warning(caplog: pytest.LogCaptureFixture) -> None:
    driver = Driver(0.2, 2.0, nan_at_sec=1.0)
    sim = await _run(2.5, driver, camera_rate=0.0)
    assert sim.commands_ignored == 1
    assert all(math.isfinite(v) for v in sim.body.pose)
    assert any("ignoring /cmd_vel with non-finite values" in r.getMessage() for r in caplog.records)


async def test_stops_when_cmd_vel_times_out() -> None:
    driver = Driver(0.2, 1.0)
    driver.timer.cancel()
    sim = await _run(0.5, driver, camera_rate=0.0)
    assert sim.body.distance_m == 0.0


async def test_same_seed_gives_identical_bytes_and_another_seed_does_not() -> None:
    runs = []
    for seed in (4, 4, 5):
        driver = Driver(0.3, 1.5)
        await _run(2.0, driver, seed=seed)
        runs.append(driver.log)
    assert len(runs[0]) > 500
    assert runs[0] == runs[1]
    assert runs[0] != runs[2]


@pytest.mark.parametrize(
    ("parameters", "message"),
    [
        ({"scan_rate": -1.0}, r'nodes\[0\]\.parameters\.scan_rate'),
        ({"gyro_noise_std": -0.1}, r'nodes\[0\]\.parameters\.gyro_noise_std'),
        ({"world": "nowhere.yaml"}, r"nowhere\.yaml: world file not found"),
        ({"robot": "tank"}, r"robot: expected 'diff' or 'mecanum', found 'tank'"),
        ({"time_source": "wall"}, r"time_source: expected one of 'sim', 'system', found 'wall'"),
        ({"time_source": "system", "real_time_factor": 2.0},
         r"time_source = 'system' needs real_time_factor = 1 .*found real_time_factor = 2\.0"),
        ({"time_source": "system", "real_time_factor": 0.0}, r"found real_time_factor = 0\.0; use time_source = 'sim'"),
    ],
)
def test_bad_parameters_give_one_config_error_and_nothing_starts(tmp_path: Path, parameters: dict[str, Any], message: str) -> None:
    from aiorobot.launch import ConfigError, build_nodes, load_config

    items = ", ".join(f"{k} = {v!r}".replace("'", '"') for k, v in parameters.items())
    path = tmp_path / "sim.toml"
    path.write_text(f'[runtime]\nuse_sim_time = true\n[[nodes]]\nuse = "aiorobot.sim:Simulator"\nparameters = {{ {items} }}\n')
    with pytest.raises(ConfigError, match=message):
        build_nodes(load_config(path))


async def test_system_time_source_stamps_with_system_time_per_step_and_publishes_no_clock() -> None:
    import time

    from aiorobot.msgs.rosgraph_msgs import Clock
    from aiorobot.msgs.tf2_msgs import TFMessage

    stamps: dict[str, list[int]] = {"/imu/data": [], "/scan": [], "/ground_truth/odom": [], "/clock": [], "/tf_static": []}
    types = {"/imu/data": Imu, "/scan": LaserScan, "/ground_truth/odom": Odometry, "/clock": Clock, "/tf_static": TFMessage}
    before = time.time_ns()
    async with Runtime(handle_signals=False) as rt:  # the system clock: no use_sim_time
        sim = rt.add_node(Simulator(parameter_overrides={"real_time_factor": 1.0, "time_source": "system",
                                                         "duration_sec": 0.3, "camera_rate": 0.0}))
        probe = rt.add_node(Node("probe"))
        for topic, msg_type in types.items():
            def record(msg: Any, topic: str = topic) -> None:
                stamp = msg.clock if topic == "/clock" else (msg.transforms[0].header if topic == "/tf_static" else msg.header).stamp
                stamps[topic].append(stamp.sec * 1_000_000_000 + stamp.nanosec)
            probe.create_subscription(msg_type, topic, record, 100)
        await rt.spin(duration_sec=30.0)  # the simulator shuts the runtime down after 0.3 s of sim time
    after = time.time_ns()
    assert sim.time_ns == 300_000_000 and stamps["/clock"] == []
    assert before <= sim.stamp_origin_ns and sim.stamp_origin_ns + sim.time_ns <= after
    for topic in ("/imu/data", "/scan", "/ground_truth/odom"):
        got = stamps[topic]
        assert got and got == sorted(got) and before <= got[0] and got[-1] <= after, topic
        # physics is the same per step: a stamp is the origin plus the step's sim time
        assert {(t - sim.stamp_origin_ns) % 10_000_000 for t in got} == {0}, topic
    assert len(stamps["/imu/data"]) == 30 and stamps["/tf_static"] == [sim.stamp_origin_ns]


def test_example_config_builds() -> None:
    from aiorobot.launch import build_nodes, load_config

    config = load_config(Path(__file__).parents[2] / "examples" / "sim.toml")
    nodes = build_nodes(config)
    assert [type(n).__name__ for n, _ in nodes] == ["Simulator"]
    assert config.runtime.use_sim_time


async def test_statistics_report_sim_time_collisions_and_commands_as_a_frozen_snapshot() -> None:
    import dataclasses

    from aiorobot.sim import SimulatorStatistics

    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        sim = rt.add_node(Simulator(parameter_overrides={"world": "box", "real_time_factor": 0.0, "duration_sec": 0.5,
                                                         "camera_rate": 0.0}))
        await rt.spin(duration_sec=60.0)
    stats = sim.statistics()
    assert isinstance(stats, SimulatorStatistics)
    assert stats.sim_time_ns == 500_000_000 and stats.sim_sec == 0.5 and stats.steps == sim.steps > 0
    assert (stats.collisions, stats.distance_m, stats.commands_received) == (0, 0.0, 0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        stats.collisions = 1  # type: ignore[misc]
