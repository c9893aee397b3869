"""``aiorobot bag check`` / ``check_bag`` / ``bag_replay``: replay a recorded simulator run into EkfNode.

The bag is a real run: the simulator in lock-step (real_time_factor 0), a driver on /cmd_vel,
EkfNode fusing /odom and /imu/data, and the Recorder writing everything to MCAP. The replay
feeds the recorded /odom, /imu/data and /tf_static back into a fresh EkfNode and compares what
it publishes with the recorded /odometry/filtered, /tf and /diagnostics.
"""

from __future__ import annotations

import asyncio
import functools
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.bag import BagError, Recorder, check_bag
from aiorobot.cli import main
from aiorobot.fusion import DEFAULT_PROCESS_NOISE, EkfNode
from aiorobot.msgs.geometry_msgs import Twist

_OFF = [False] * 6
EKF = {
    "frequency": 50.0,
    "sensor_timeout": 0.1,
    "two_d_mode": True,
    "odom0": "/odom",
    "odom0_config": _OFF + [True, True, False, False, False, True] + [False] * 3,
    "imu0": "/imu/data",
    "imu0_config": _OFF + [False] * 5 + [True] + [False] * 3,
    "imu0_remove_gravitational_acceleration": True,
    "smooth_lagged_data": True,
    "history_length": 1.0,
}
PARAMS_YAML = """\
/**:
  ros__parameters:
    frequency: 50.0
    sensor_timeout: 0.1
    two_d_mode: true
    odom0: /odom
    odom0_config: [false, false, false, false, false, false, true, true, false, false, false, true, false, false, false]
    imu0: /imu/data
    imu0_config: [false, false, false, false, false, false, false, false, false, false, false, true, false, false, false]
    imu0_remove_gravitational_acceleration: true
    smooth_lagged_data: true
    history_length: 1.0
"""


def _perturbed() -> dict[str, Any]:
    """The same filter with the x process noise doubled: a one-line change to the node's tuning."""
    q = DEFAULT_PROCESS_NOISE.copy()
    q[0, 0] *= 2.0
    return {**EKF, "process_noise_covariance": q.reshape(-1).tolist()}


class _Driver(Node):
    def __init__(self) -> None:
        super().__init__("driver")
        self.pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_timer(0.1, self.tick)

    def tick(self) -> None:
        t = self.get_clock().now().nanoseconds / 1e9
        msg = Twist()
        msg.linear.x, msg.angular.z = 0.3, 0.5 if t > 0.8 else -0.3
        self.pub.publish(msg)


async def _record_run(path: Path, duration_sec: float) -> None:
    from aiorobot.sim import Simulator

    async with Runtime(use_sim_time=True, handle_signals=False) as rt:
        rt.add_node(Recorder(path=str(path), exclude="^/(camera|scan|map)"))
        rt.add_node(Simulator(parameter_overrides={"world": "box", "real_time_factor": 0.0, "duration_sec": duration_sec,
                                                   "camera_rate": 0.0, "scan_rate": 0.0, "seed": 7}))
        rt.add_node(_Driver())
        rt.add_node(EkfNode(parameter_overrides=EKF))
        await rt.spin(duration_sec=60.0)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("check") / "run"
    asyncio.run(_record_run(path, 1.5))
    return path


def _recorded(path: Path, topic: str) -> list[Any]:
    """The bag's messages on ``topic`` as rosbags (an independent reader) decodes them."""
    from rosbags.highlevel import AnyReader

    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        return [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=conns)]


async def test_unchanged_node_matches_the_recording_exactly(run: Path) -> None:
    result = await check_bag(str(run), [functools.partial(EkfNode, parameter_overrides=EKF)])
    assert result.passed, result.table()
    assert result.replay.inputs == ("/imu/data", "/odom", "/tf_static")
    assert result.replay.not_in_bag == ("/set_pose",)
    counts = {t.topic: (t.recorded, t.replayed, t.differing) for t in result.diff.topics}
    filtered = len(_recorded(run, "/odometry/filtered"))
    assert filtered > 100 and counts["/odometry/filtered"] == (filtered, filtered, 0)
    assert set(counts) == {"/diagnostics", "/odometry/filtered", "/tf"}
    assert result.table().splitlines()[-1] == "PASS: every output matches the recording"


async def test_two_replays_give_identical_outputs(run: Path) -> None:
    first = await check_bag(str(run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    second = await check_bag(str(run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    assert first.replay.outputs == second.replay.outputs
    assert first.replay.steps == second.replay.steps and first.replay.played == second.replay.played


async def test_perturbed_process_noise_fails_with_the_first_differing_message(run: Path) -> None:
    result = await check_bag(str(run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    assert not result.passed
    topic = {t.topic: t for t in result.diff.topics}["/odometry/filtered"]
    recorded = _recorded(run, "/odometry/filtered")
    first = topic.first
    assert first is not None
    # message 0 is the first correction (no time elapsed, no process noise added): equal; the next
    # one predicts over 10 ms, and x's variance (covariance[0], the entry changed) is the first field off
    assert (first.index, first.field) == (1, "pose.covariance[0]")
    stamp = recorded[1].header.stamp
    assert first.stamp_ns == stamp.sec * 1_000_000_000 + stamp.nanosec
    assert first.recorded == recorded[1].pose.covariance[0] and first.now != first.recorded
    assert topic.recorded == topic.replayed == len(recorded)
    assert {t.topic: t.passed for t in result.diff.topics} == {"/diagnostics": True, "/odometry/filtered": False, "/tf": True}
    assert "#1 stamp" in result.table() and "FAIL" in result.table()


async def test_a_tolerance_covering_the_change_passes(run: Path) -> None:
    result = await check_bag(
        str(run), [functools.partial(EkfNode, parameter_overrides=_perturbed())], tolerances=["/odometry/filtered.pose.covariance=1"]
    )
    assert result.passed, result.table()
    assert result.diff.topics[1].max_error["pose.covariance[0]"] > 0  # reported, within tolerance
    assert "(1)" in result.table()


async def test_nodes_that_take_nothing_from_the_bag_are_one_clear_error(run: Path) -> None:
    with pytest.raises(BagError, match=r"the nodes subscribe to .*the bag holds none of these \(it holds /clock, /cmd_vel"):
        await check_bag(str(run), [functools.partial(EkfNode, parameter_overrides={"odom0": "/wheel"})])


async def test_bag_replay_fixture_is_a_three_line_regression_test(run: Path, bag_replay: Any) -> None:
    await bag_replay.assert_matches(run, functools.partial(EkfNode, parameter_overrides=EKF))
    with pytest.raises(AssertionError, match=r"FAIL: the outputs differ"):
        await bag_replay.assert_matches(run, functools.partial(EkfNode, parameter_overrides=_perturbed()))


def test_cli_exit_status_is_0_when_equal_and_1_with_the_first_difference(run: Path, tmp_path: Path) -> None:
    params = tmp_path / "ekf.yaml"
    params.write_text(PARAMS_YAML)
    cmd = [sys.executable, "-m", "aiorobot.cli", "bag", "check", str(run), "--node", "aiorobot.fusion:EkfNode", "--params", str(params)]
    same = subprocess.run(cmd, capture_output=True, text=True, timeout=50)
    assert same.returncode == 0, same.stderr
    assert "PASS" in same.stdout and "/odometry/filtered" in same.stdout
    q = DEFAULT_PROCESS_NOISE.copy()
    q[0, 0] *= 2.0
    changed = subprocess.run([*cmd, "-p", f"process_noise_covariance:={np.diag(q).tolist()}"], capture_output=True, text=True, timeout=50)
    assert changed.returncode == 1, changed.stderr
    row = next(line for line in changed.stdout.splitlines() if line.startswith("/odometry/filtered "))
    assert "#1 stamp 0.020000000: pose.covariance[0] recorded" in row


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--node", "fusion"], "argument --node: expected module:Class such as aiorobot.fusion:EkfNode, found 'fusion'"),
        (["--node", "aiorobot.fusion:EkfNode", "--tolerance", "/odom.x=lots"], "expected a number after '=', found 'lots'"),
        (["--node", "aiorobot.fusion:EkfNode", "--params", "/no/such.yaml"], "--params: no such file '/no/such.yaml'"),
        (["--node", "aiorobot.fusion:Nope"], 'module "aiorobot.fusion" has no class "Nope"'),
    ],
)
def test_bad_arguments_are_one_line_and_status_2(run: Path, argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "check", str(run), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_a_missing_bag_is_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "check", str(tmp_path / "nope"), "--node", "aiorobot.fusion:EkfNode"]) == 2
    assert capsys.readouterr().err == f"aiorobot bag check: error: {tmp_path / 'nope'}: no such bag directory\n"
