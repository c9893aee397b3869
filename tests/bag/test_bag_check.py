"""``aiorobot bag check`` / ``check_bag`` / ``bag_replay``: replay a recorded simulator run into EkfNode.

The bag is a real run (the ``ekf_run`` fixture): the simulator in lock-step (real_time_factor 0), a driver on /cmd_vel,
EkfNode fusing /odom and /imu/data, and the Recorder writing everything to MCAP. The replay
feeds the recorded /odom, /imu/data and /tf_static back into a fresh EkfNode and compares what
it publishes with the recorded /odometry/filtered, /tf and /diagnostics.
"""

from __future__ import annotations

import functools
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aiorobot.bag import BagError, check_bag
from aiorobot.cli import main
from aiorobot.fusion import DEFAULT_PROCESS_NOISE, EkfNode

from .conftest import EKF, PARAMS_YAML

def _perturbed() -> dict[str, Any]:
    """The same filter with the x process noise doubled: a one-line change to the node's tuning."""
    q = DEFAULT_PROCESS_NOISE.copy()
    q[0, 0] *= 2.0
    return {**EKF, "process_noise_covariance": q.reshape(-1).tolist()}


def _recorded(path: Path, topic: str) -> list[Any]:
    """The bag's messages on ``topic`` as rosbags (an independent reader) decodes them."""
    from rosbags.highlevel import AnyReader

    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        return [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=conns)]


async def test_unchanged_node_matches_the_recording_exactly(ekf_run: Path) -> None:
    result = await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides=EKF)])
    assert result.passed, result.table()
    assert result.replay.inputs == ("/imu/data", "/odom", "/tf_static")
    assert result.replay.not_in_bag == ("/set_pose",)
    assert result.replay.not_recorded == ()
    counts = {t.topic: (t.recorded, t.replayed, t.differing) for t in result.diff.topics}
    filtered = len(_recorded(ekf_run, "/odometry/filtered"))
    assert filtered > 100 and counts["/odometry/filtered"] == (filtered, filtered, 0)
    assert set(counts) == {"/diagnostics", "/odometry/filtered", "/tf"}
    assert result.table().splitlines()[-1] == "PASS: every output matches the recording"


async def test_two_replays_give_identical_outputs(ekf_run: Path) -> None:
    first = await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    second = await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    assert first.replay.outputs == second.replay.outputs
    assert first.replay.steps == second.replay.steps and first.replay.played == second.replay.played


async def test_perturbed_process_noise_fails_with_the_first_differing_message(ekf_run: Path) -> None:
    result = await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides=_perturbed())])
    assert not result.passed
    topic = {t.topic: t for t in result.diff.topics}["/odometry/filtered"]
    recorded = _recorded(ekf_run, "/odometry/filtered")
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


async def test_a_tolerance_covering_the_change_passes(ekf_run: Path) -> None:
    result = await check_bag(
        str(ekf_run), [functools.partial(EkfNode, parameter_overrides=_perturbed())], tolerances=["/odometry/filtered.pose.covariance=1"]
    )
    assert result.passed, result.table()
    assert result.diff.topics[1].max_error["pose.covariance[0]"] > 0  # reported, within tolerance
    assert "(1)" in result.table()


async def test_outputs_the_bag_lacks_are_named_not_dropped_silently(ekf_run: Path) -> None:
    renamed = {**EKF, "publish_tf": False}
    result = await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides=renamed, remappings={"odometry/filtered": "/odom_new"})])
    assert result.replay.not_recorded == ("/odom_new",)
    assert "published but not in the bag, so not compared: /odom_new" in result.table()


async def test_nodes_that_take_nothing_from_the_bag_are_one_clear_error(ekf_run: Path) -> None:
    with pytest.raises(BagError, match=r"the nodes subscribe to .*the bag holds none of these \(it holds /clock, /cmd_vel"):
        await check_bag(str(ekf_run), [functools.partial(EkfNode, parameter_overrides={"odom0": "/wheel"})])


async def test_bag_replay_fixture_is_a_three_line_regression_test(ekf_run: Path, bag_replay: Any) -> None:
    await bag_replay.assert_matches(ekf_run, functools.partial(EkfNode, parameter_overrides=EKF))
    with pytest.raises(AssertionError, match=r"FAIL: the outputs differ"):
        await bag_replay.assert_matches(ekf_run, functools.partial(EkfNode, parameter_overrides=_perturbed()))


def test_cli_exit_status_is_0_when_equal_and_1_with_the_first_difference(
    ekf_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    params = tmp_path / "ekf.yaml"
    params.write_text(PARAMS_YAML)
    argv = ["bag", "check", str(ekf_run), "--node", "aiorobot.fusion:EkfNode", "--params", str(params)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "PASS" in out and "/odometry/filtered" in out
    q = DEFAULT_PROCESS_NOISE.copy()
    q[0, 0] *= 2.0
    # the failing case as a user runs it: a real process, its exit status and its table
    changed = subprocess.run([sys.executable, "-m", "aiorobot.cli", *argv, "-p", f"process_noise_covariance:={np.diag(q).tolist()}"],
                             capture_output=True, text=True, timeout=50)
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
def test_bad_arguments_are_one_line_and_status_2(ekf_run: Path, argv: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "check", str(ekf_run), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_a_missing_bag_is_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "check", str(tmp_path / "nope"), "--node", "aiorobot.fusion:EkfNode"]) == 2
    assert capsys.readouterr().err == f"aiorobot bag check: error: {tmp_path / 'nope'}: no such bag directory\n"
