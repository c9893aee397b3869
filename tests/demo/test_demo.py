"""The whole robot on sim time: simulator + AMCL + navigation server + BasicNavigator (issue 15's end-to-end test)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from aiorobot.cli import main
from aiorobot.demo import parse_waypoints, run_demo
from aiorobot.demo._graph import time_source_for

pytestmark = pytest.mark.timeout(300)


async def test_a_short_mission_in_the_box_reaches_every_waypoint_without_collision() -> None:
    summary = await run_demo("box", [(1.5, 0.0, math.pi / 2), (1.5, 1.5, math.pi)], seed=3, timeout_sim_sec=120.0)
    assert summary.waypoints_reached == 2 and summary.collisions == 0, summary.figures()
    assert summary.succeeded
    assert summary.localisation_rmse_m < 0.15  # AMCL against ground truth (the shipped mission's target is 5 cm)
    assert summary.path_length_m > 2.5
    assert summary.sim_sec < 120.0


def test_waypoints_parse_and_bad_ones_are_named() -> None:
    assert parse_waypoints("1,2;3,4,1.5") == [(1.0, 2.0, 0.0), (3.0, 4.0, 1.5)]
    with pytest.raises(ValueError, match=r"waypoint 2: expected x,y or x,y,yaw numbers, found '3,a'"):
        parse_waypoints("1,2;3,a")
    with pytest.raises(ValueError, match="at least one waypoint"):
        parse_waypoints(" ; ")


def test_cli_refuses_a_waypoint_in_a_wall_before_starting(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--world", "box", "--waypoints", "3.0,0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "waypoint 1 (3, 0) is outside the map or inside an obstacle of box" in err
    assert main(["demo", "--world", "nowhere"]) == 2
    assert "nowhere" in capsys.readouterr().err
    # the pty runs on the wall clock: no serial drive in lock-step
    assert main(["demo", "--world", "box", "--drive", "serial", "--rtf", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--drive serial needs --rtf > 0" in err
    assert main(["demo", "--localisation", "landmarks", "--no-perception"]) == 2
    assert "needs perception" in capsys.readouterr().err
    # system time only at real time: the stamps are the system clock's
    assert main(["demo", "--world", "box", "--time-source", "system", "--rtf", "2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--time-source system needs --rtf 1 (stamps are system time), found --rtf 2" in err


def test_cli_writes_the_summary_json_a_plot_and_a_bag_that_rosbags_reads(tmp_path: Path) -> None:
    out, png, bag = tmp_path / "summary.json", tmp_path / "demo.png", tmp_path / "bag"
    status = main(["demo", "--world", "box", "--waypoints", "1.0,0,0", "--seed", "2", "--json", str(out), "--plot", str(png),
                   "--record", str(bag)])
    figures = json.loads(out.read_text())
    assert status == 0, figures
    for key in ("waypoints_reached", "waypoints_total", "collisions", "localisation_rmse_m", "control_period_p99_ms",
                "control_period_max_ms", "perception_fps", "sim_sec", "wall_sec", "cpu_pct", "workers_cpu_pct"):
        assert key in figures
    assert figures["waypoints_reached"] == figures["waypoints_total"] == 1
    assert figures["drive"] == "direct" and figures["control_period_p99_ms"] is None  # lock-step: no wall-clock periods
    assert figures["perception_frames"] > 0 and figures["perception_fps"] > 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the bag, read back by an independent reader
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        topics = {c.topic for c in reader.connections}
        assert {"/scan", "/tf", "/imu/data", "/odom", "/cmd_vel", "/plan", "/ground_truth/odom",
                "/local/odometry/filtered", "/detections/markers"} <= topics, topics
        assert "/camera/image_raw" not in topics  # raw frames are left out on purpose
        truth = [c for c in reader.connections if c.topic == "/ground_truth/odom"]
        last = None
        for conn, _, raw in reader.messages(connections=truth):
            last = reader.deserialize(raw, conn.msgtype)
    # the goal tolerance (0.25 m) holds for the estimate; the true pose is within it plus the localisation error
    assert last is not None and math.hypot(last.pose.pose.position.x - 1.0, last.pose.pose.position.y) < 0.4


def test_aiorobot_run_without_a_file_runs_the_demo(capsys: pytest.CaptureFixture[str]) -> None:
    # two sim seconds of the warehouse mission: the demo runs, stops at its --duration, says so; not a failure
    assert main(["run", "--duration", "2"]) == 0
    out = capsys.readouterr()
    assert "aiorobot demo: warehouse, 7 waypoints" in out.err
    assert "aiorobot demo — warehouse" in out.out and "stopped after --duration: 0 / 7 waypoints" in out.out


async def test_landmark_localisation_reaches_the_waypoints_on_aruco_fixes() -> None:
    summary = await run_demo("box", [(1.0, 0.0, math.pi / 2), (1.0, 1.0, math.pi)], seed=4, timeout_sim_sec=90.0,
                             localisation="landmarks")
    assert summary.succeeded, summary.figures()
    assert summary.landmark_fixes > 20 and summary.perception_frames > 0
    assert summary.localisation_rmse_m < 0.2  # map -> odom from the map-frame EKF on the fixes, against ground truth


def _fifo_permitted() -> bool:
    import os
    import threading

    if not hasattr(os, "sched_setscheduler"):
        return False
    result: list[bool] = []

    def probe() -> None:  # a throwaway thread: its policy dies with it
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
            result.append(True)
        except OSError:
            result.append(False)

    thread = threading.Thread(target=probe)
    thread.start()
    thread.join()
    return result[0]


async def test_at_real_time_the_whole_graph_runs_on_system_time_and_reaches_its_waypoint(tmp_path: Path) -> None:
    import time

    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    assert (time_source_for(1.0), time_source_for(0.0), time_source_for(2.0)) == ("system", "sim", "sim")
    bag = tmp_path / "bag"
    before = time.time_ns()
    summary = await run_demo("box", [(1.0, 0.0, 0.0)], rtf=1.0, seed=2, timeout_sim_sec=60.0, perception=False,
                             record=str(bag), realtime=True)
    after = time.time_ns()
    assert summary.time_source == "system" and summary.drive == "serial"
    assert summary.succeeded, summary.figures()
    assert 0 < summary.sim_sec < 60.0 and summary.control_periods > 0
    # the priority loop ran SCHED_FIFO exactly when this OS lets a thread have it (else a warning, run goes on)
    assert summary.realtime == _fifo_permitted()
    # the same run's baseline: a bare thread on the same deadlines, its periods around the nominal 20 ms
    assert summary.baseline_period_p99_ms is not None and summary.baseline_period_max_ms >= summary.baseline_period_p99_ms >= 19.0
    # every stamp in the graph is system time: the simulator's sensors, the base controller's odometry (on the
    # priority loop), the EKF's output and tf, AMCL's pose; and no /clock
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        assert "/clock" not in {c.topic for c in reader.connections}
        wanted = ("/scan", "/imu/data", "/odom", "/local/odometry/filtered", "/amcl_pose", "/tf")
        seen: dict[str, int] = {}
        for conn, log_ns, raw in reader.messages(connections=[c for c in reader.connections if c.topic in wanted]):
            msg = reader.deserialize(raw, conn.msgtype)
            header = msg.transforms[0].header if conn.topic == "/tf" else msg.header
            stamp = header.stamp.sec * 1_000_000_000 + header.stamp.nanosec
            # AMCL post-dates map -> odom by its transform_tolerance (1 s), as nav2_amcl does
            assert before <= stamp <= after + 1_100_000_000 and before <= log_ns <= after, (conn.topic, stamp)
            seen[conn.topic] = seen.get(conn.topic, 0) + 1
    assert set(seen) == set(wanted), seen


def test_system_time_needs_real_time_factor_1() -> None:
    from aiorobot.demo._graph import build_graph
    from aiorobot.sim import World

    with pytest.raises(ValueError, match=r"^time_source 'system' needs a real-time factor of exactly 1 .*found 0\.5"):
        build_graph(World.load("box"), rtf=0.5, seed=1, drive="direct", localisation="amcl", perception=False,
                    time_source="system")
