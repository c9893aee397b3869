"""SlamNode on sim time: /map (transient local) and map -> odom from scans and tf, bad input counted on
/diagnostics, and slam_toolbox's services: save the map, serialise the graph, reload it and go on."""

from __future__ import annotations

import asyncio
import math
from pathlib import Path

import numpy as np
import pytest

from aiorobot import Node
from aiorobot.sim import World
from aiorobot.sim._sensors import LidarModel

from aiorobot.demo._slam_figures import route_poses, wheel_odometry

#: a loop round the box world's pillar (about 12 m), 5 cm a step
BOX_START = (-1.5, -1.5, 0.0)
BOX_LOOP = [(1.5, -1.5), (1.5, 1.5), (-1.5, 1.5), (-1.5, -1.5), (0.0, -1.5)]


class ScriptedRobot(Node):
    """Every 0.1 s of sim time: the next pose of a scripted path, odom -> base_link on /tf (3 % scale
    error) and a simulated scan from laser (base_link -> laser static, 0.2 m up)."""

    def __init__(self, truth: np.ndarray, odom: np.ndarray) -> None:
        super().__init__("robot")
        from aiorobot.msgs.geometry_msgs import TransformStamped
        from aiorobot.msgs.sensor_msgs import LaserScan
        from aiorobot.tf import StaticTransformBroadcaster, TransformBroadcaster

        self.truth, self.odom, self.k = truth, odom, 0
        self.world, self.lidar, self.rng = World.load("box"), LidarModel(), np.random.default_rng(7)
        self.tf = TransformBroadcaster(self)
        static = TransformStamped()
        static.header.frame_id, static.child_frame_id = "base_link", "laser"
        static.transform.translation.z = 0.2
        StaticTransformBroadcaster(self).send_transform(static)
        self.scan_pub = self.create_publisher(LaserScan, "/scan", 10)
        self.create_timer(0.1, self.step)

    @property
    def done(self) -> bool:
        return self.k >= len(self.truth)

    def send_odom(self, pose: tuple[float, float, float]) -> None:
        from aiorobot.msgs.geometry_msgs import TransformStamped
        from aiorobot.nav._geometry import yaw_quaternion

        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = "odom", "base_link"
        t.header.stamp = self.now().to_msg()
        t.transform.translation.x, t.transform.translation.y = pose[0], pose[1]
        t.transform.rotation = yaw_quaternion(pose[2])
        self.tf.send_transform(t)

    def scan(self, ranges: np.ndarray | None = None, frame: str = "laser", odom: tuple[float, float, float] | None = None) -> None:
        """odom -> base_link (default: the current odometry) and a scan, both stamped now."""
        from aiorobot.msgs.sensor_msgs import LaserScan

        k = min(self.k, len(self.truth) - 1)
        self.send_odom(odom if odom is not None else tuple(self.odom[k]))
        if ranges is None:
            p = self.truth[k]
            ranges = self.lidar.measure(self.world, p[0], p[1], p[2], self.rng)
        msg = LaserScan(angle_min=self.lidar.angle_min, angle_increment=self.lidar.angle_increment,
                        range_min=self.lidar.range_min, range_max=self.lidar.range_max, ranges=np.asarray(ranges, np.float32))
        msg.header.frame_id = frame
        msg.header.stamp = self.now().to_msg()
        self.scan_pub.publish(msg)

    def step(self) -> None:
        if self.done:
            return
        self.scan()
        self.k += 1


async def _drive(sim, robot: ScriptedRobot) -> None:  # type: ignore[no-untyped-def]
    while not robot.done:
        await sim.advance(0.5, step_sec=0.1)
    await sim.advance(0.5, step_sec=0.1)


@pytest.fixture
async def mapped(sim_runtime):  # type: ignore[no-untyped-def]
    from aiorobot.nav import SlamNode
    from aiorobot.testing import SimClock

    sim = SimClock(sim_runtime)
    await sim.start()
    truth = route_poses(BOX_START, BOX_LOOP)
    robot = sim_runtime.add_node(ScriptedRobot(truth, wheel_odometry(truth, 0.03, 0.01, seed=3)))
    slam = sim_runtime.add_node(SlamNode(parameter_overrides={"map_start_pose": list(BOX_START), "map_update_interval": 1.0,
                                                              "max_laser_range": 8.0}))
    await _drive(sim, robot)
    return sim, robot, slam, truth


async def test_slam_node_publishes_the_map_and_map_to_odom(mapped, sim_runtime) -> None:  # type: ignore[no-untyped-def]
    from aiorobot import Time
    from aiorobot.msgs.nav_msgs import OccupancyGrid
    from aiorobot.nav import OccupancyMap
    from aiorobot.nav._geometry import transform_to_xyyaw
    from aiorobot.nav._map_server import MAP_QOS
    from aiorobot.nav._slam_graph import compose
    from aiorobot.testing import wait_for_message
    from aiorobot.tf import Buffer, TransformListener

    sim, robot, slam, truth = mapped
    probe = sim_runtime.add_node(Node("probe"))
    buffer = Buffer()
    listener = TransformListener(buffer, probe)
    waiting = asyncio.ensure_future(wait_for_message(probe, OccupancyGrid, "/map", timeout_sec=10, qos=MAP_QOS))
    await sim.advance(1.5, step_sec=0.1)
    grid = OccupancyMap.from_msg(await waiting)  # a late subscriber still gets it: transient local
    # map -> odom is stamped at the last scan + transform_timeout, as slam_toolbox stamps it
    m2o = transform_to_xyyaw(buffer.lookup_transform("map", "odom", Time()))
    x, y, _ = compose(m2o, tuple(robot.odom[-1]))
    assert math.hypot(x - truth[-1, 0], y - truth[-1, 1]) < 0.05
    del listener
    s = slam.slam.statistics()
    assert s.nodes >= 20 and s.beams_invalid == 0 and slam.scans_without_transform == 0


async def test_bad_scans_are_ignored_and_counted_on_diagnostics(mapped, sim_runtime) -> None:  # type: ignore[no-untyped-def]
    from aiorobot.msgs.diagnostic_msgs import DiagnosticArray, DiagnosticStatus

    sim, robot, slam, _ = mapped
    before = slam.slam.statistics()
    map_before = slam.slam.occupancy_map().data.copy()
    n = robot.lidar.beams
    nan_scan = robot.lidar.measure(robot.world, *robot.truth[-1], robot.rng)
    nan_scan[::3] = np.nan
    for ranges, frame in ((nan_scan, "laser"),  # a third NaN: the rest is used
                          (np.full(n, np.inf), "laser"),  # every beam beyond range: empty
                          (np.full(n, np.nan), "laser"),  # every beam NaN: empty
                          (None, "no_such_frame")):  # no transform to odom
        robot.scan(ranges, frame)
        await sim.advance(0.1, step_sec=0.1)
    await sim.advance(0.5, step_sec=0.1)
    robot.scan(odom=tuple(np.asarray(robot.odom[-1]) - (3.0, 0.0, 0.0)))  # odometry leaps 3 m back
    await sim.advance(0.1, step_sec=0.1)
    probe = sim_runtime.add_node(Node("probe"))
    got: list = []
    probe.create_subscription(DiagnosticArray, "/diagnostics", got.append, 10)
    await sim.advance(1.5, step_sec=0.1)
    s = slam.slam.statistics()
    assert s.beams_invalid == len(range(0, n, 3)) + n
    assert s.scans_empty - before.scans_empty == 2
    assert slam.scans_without_transform == 1
    assert s.odometry_jumps - before.odometry_jumps == 1
    assert s.nodes == before.nodes  # nothing moved: no node, no change to the map
    np.testing.assert_array_equal(slam.slam.occupancy_map().data, map_before)
    status = got[-1].status[0]
    assert status.level == DiagnosticStatus.WARN
    values = {kv.key: kv.value for kv in status.values}
    assert values["scans_without_transform"] == "1" and values["odometry_jumps"] == "1" and values["scans_empty"] == "2"
    assert "1 scans without transform" in status.message
    # the pose did not jump with the odometry: map -> base_link stays where the robot is
    assert math.hypot(slam.slam.pose[0] - robot.truth[-1, 0], slam.slam.pose[1] - robot.truth[-1, 1]) < 0.05


async def test_save_map_serialise_and_reload_continue_mapping(mapped, sim_runtime, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    from aiorobot.msgs.geometry_msgs import Pose2D
    from aiorobot.msgs.slam_toolbox import DeserializePoseGraph, SaveMap, SerializePoseGraph
    from aiorobot.msgs.std_msgs import String
    from aiorobot.nav import SlamNode, load_map

    sim, robot, slam, truth = mapped
    client = sim_runtime.add_node(Node("client"))
    save = client.create_client(SaveMap, "/slam_toolbox/save_map")
    result = await save.call(SaveMap.Request(name=String(data=str(tmp_path / "box"))))
    assert result.result == SaveMap.Response.RESULT_SUCCESS
    saved, _ = load_map(tmp_path / "box.yaml")
    assert (saved.data == 100).sum() > 300
    serialize = client.create_client(SerializePoseGraph, "/slam_toolbox/serialize_map")
    assert (await serialize.call(SerializePoseGraph.Request(filename=str(tmp_path / "box")))).result == 0
    assert (tmp_path / "box.posegraph").exists()
    bad = await serialize.call(SerializePoseGraph.Request(filename=str(tmp_path / "missing" / "dir" / "g")))
    assert bad.result == SerializePoseGraph.Response.RESULT_FAILED_TO_WRITE_FILE

    # a second SLAM node (another namespace) reloads the graph at the robot's pose and keeps mapping
    other = sim_runtime.add_node(SlamNode(namespace="again", parameter_overrides={"transform_publish_period": 0.0}))
    load = client.create_client(DeserializePoseGraph, "/again/slam_toolbox/deserialize_map")
    here = truth[-1]
    await load.call(DeserializePoseGraph.Request(filename=str(tmp_path / "box.posegraph"), match_type=DeserializePoseGraph.Request.START_AT_GIVEN_POSE,
                                                 initial_pose=Pose2D(x=float(here[0]), y=float(here[1]), theta=float(here[2]))))
    nodes = len(slam.slam.graph)
    assert len(other.slam.graph) == nodes
    # odometry restarts from zero on the second run; the robot drives on from where it stood
    more = route_poses(tuple(here), [(0.0, 0.0), (1.0, 0.5)])
    robot.truth, robot.odom, robot.k = more, wheel_odometry(more, 0.03, 0.01, seed=4), 0
    await _drive(sim, robot)
    s = other.slam.statistics()
    assert len(other.slam.graph) > nodes
    assert s.nodes > nodes and s.matches_failed == 0
    new = other.slam.graph.poses[nodes:]
    assert math.hypot(other.slam.pose[0] - more[-1, 0], other.slam.pose[1] - more[-1, 1]) < 0.05
    assert len(new) >= 3
