"""Log-odds mapping with known poses rebuilds a room from scans."""

from __future__ import annotations

import math

import numpy as np

from aiorobot.nav._mapping import OccupancyMapper

from .test_amcl import RES, _box_world, _scan


def test_scans_from_known_poses_rebuild_the_walls_and_the_free_space() -> None:
    occ, origin = _box_world()
    mapper = OccupancyMapper((6.4, 6.4), RES, origin)
    rng = np.random.default_rng(0)
    for i in range(12):
        a = i * 2 * math.pi / 12
        pose = (1.5 * math.cos(a), 1.5 * math.sin(a), a)
        ranges, amin, inc = _scan(occ, origin, pose, beams=360, rng=rng)
        mapper.integrate(pose, ranges, amin, inc, 0.1, 12.0)
    built = mapper.to_map().data
    walls = occ.copy()
    walls[:3, :] = walls[-3:, :] = walls[:, :3] = walls[:, -3:] = False  # only the inner faces are seen
    inner_face = np.zeros_like(occ)
    inner_face[3, 4:-4] = inner_face[-4, 4:-4] = inner_face[4:-4, 3] = inner_face[4:-4, -4] = True
    seen_wall = (built[inner_face] == 100).mean()
    assert seen_wall > 0.9
    interior = np.zeros_like(occ)
    interior[20:-20, 20:-20] = True
    interior &= ~occ
    interior[70:100, 20:46] = False  # around the pillar, partly shadowed
    assert (built[interior] == 0).mean() > 0.95
    assert (built[~occ & interior] == 100).sum() == 0


def test_map_save_without_a_map_says_so(capsys) -> None:  # type: ignore[no-untyped-def]
    from aiorobot.cli import main

    assert main(["map", "save", "/tmp/never", "--transport", "local", "--timeout", "0.2"]) == 1
    assert "no map on /map within 0.2 s" in capsys.readouterr().err


async def test_mapping_node_publishes_the_map_it_builds(sim_runtime) -> None:  # type: ignore[no-untyped-def]
    from aiorobot import Node
    from aiorobot.msgs.geometry_msgs import TransformStamped
    from aiorobot.msgs.nav_msgs import OccupancyGrid
    from aiorobot.msgs.sensor_msgs import LaserScan
    from aiorobot.nav import OccupancyMap
    from aiorobot.nav._map_server import MAP_QOS
    from aiorobot.nav._mapping import MappingNode
    from aiorobot.tf import StaticTransformBroadcaster
    from aiorobot.testing import SimClock, wait_for_message
    import asyncio

    sim = SimClock(sim_runtime)
    await sim.start()
    mapper = sim_runtime.add_node(MappingNode(parameter_overrides={"size_x": 6.4, "size_y": 6.4, "origin_x": -3.2, "origin_y": -3.2}))
    src = sim_runtime.add_node(Node("scanner"))
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = "map", "laser"
    StaticTransformBroadcaster(src).send_transform(t)
    occ, origin = _box_world()
    ranges, amin, inc = _scan(occ, origin, (0.0, 0.0, 0.0), beams=360)
    pub = src.create_publisher(LaserScan, "/scan", 5)
    probe = sim_runtime.add_node(Node("probe"))
    waiting = asyncio.ensure_future(wait_for_message(probe, OccupancyGrid, "/map", timeout_sec=10, qos=MAP_QOS))
    await sim.advance(0.1, step_sec=0.05)
    scan = LaserScan(angle_min=amin, angle_increment=inc, range_min=0.1, range_max=12.0, ranges=ranges.astype(np.float32))
    scan.header.frame_id = "laser"
    for _ in range(4):  # one scan leaves free cells at p = 0.4 (unknown); four make them free
        scan.header.stamp = sim_runtime.now().to_msg()
        pub.publish(scan)
        await sim.advance(0.1, step_sec=0.05)
    await sim.advance(1.0, step_sec=0.1)
    grid = OccupancyMap.from_msg(await waiting)
    assert mapper.mapper.scans == 4
    assert (grid.data == 100).sum() > 300 and (grid.data == 0).sum() > 5000
