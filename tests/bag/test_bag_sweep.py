"""``aiorobot bag sweep``: parameter variants of a node replayed from one bag in worker processes, with figures."""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aiorobot.bag import odometry_rmse, sweep, topic_figures, variants_from_params
from aiorobot.cli import main
from aiorobot.cli._bag_sweep import build_variant_nodes
from aiorobot.msgs.nav_msgs import Odometry

from .conftest import PARAMS_YAML

_S = 1_000_000_000


def _odom(t_sec: float, x: float, y: float, yaw: float) -> tuple[int, Any]:
    msg = Odometry()
    ns = round(t_sec * _S)
    msg.header.stamp.sec, msg.header.stamp.nanosec = ns // _S, ns % _S
    msg.pose.pose.position.x, msg.pose.pose.position.y = x, y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return ns, msg


def test_rmse_is_measured_in_the_estimate_frame_aligned_at_its_first_pose() -> None:
    # the truth drives along +y from (5, 2) facing +y; the odometry frame starts at 0 facing +x
    truth = [_odom(t, 5.0, 2.0 + t, math.pi / 2) for t in np.arange(0.0, 2.01, 0.1)]
    exact = [_odom(t, t, 0.0, 0.0) for t in np.arange(0.05, 2.0, 0.1)]
    assert odometry_rmse(exact, truth) == pytest.approx(0.0, abs=1e-12)
    off = [_odom(t, t, 0.3 if i else 0.0, 0.0) for i, t in enumerate(np.arange(0.05, 2.0, 0.1))]
    n = len(off)
    assert odometry_rmse(off, truth) == pytest.approx(math.sqrt((n - 1) * 0.09 / n))
    assert math.isnan(odometry_rmse([_odom(9.0, 0, 0, 0)], truth))  # outside the reference's span


def test_figures_count_rate_and_latency() -> None:
    msgs = [(ns + 2_000_000, m) for ns, m in (_odom(t, 0, 0, 0) for t in (0.1, 0.2, 0.3, 0.4))]
    f = topic_figures("/odometry/filtered", msgs, "nav_msgs/msg/Odometry", 2 * _S, None)
    assert (f.messages, f.rate_hz, f.latency_sec) == (4, 2.0, pytest.approx(0.002)) and math.isnan(f.rmse_m)


def test_a_name_given_twice_is_swept_and_the_rest_is_shared() -> None:
    assert variants_from_params(["a:=1", "b:=x", "a:=2"]) == [("a:=1", "b:=x"), ("a:=2", "b:=x")]
    assert variants_from_params([]) == [()]
    with pytest.raises(ValueError, match=r"^-p: expected NAME:=VALUE, found 'a=1'$"):
        variants_from_params(["a=1"])


def test_sweep_runs_each_variant_in_a_worker_and_reports_in_order(ekf_run: Path, tmp_path: Path) -> None:
    params = tmp_path / "ekf.yaml"
    params.write_text(PARAMS_YAML)
    build = functools.partial(build_variant_nodes, ("aiorobot.fusion:EkfNode",), ("--params-file", str(params)))
    # the second variant fuses no wheel odometry: it never moves, so it is further from the truth
    variants = [(), ("odom0_config:=[false, false, false, false, false, false, false, false, false, false, false, true, "
                     "false, false, false]",)]
    # one worker process (a spawned interpreter costs seconds on a loaded machine); the CLI's default is one per core
    results = sweep(str(ekf_run), build, variants, outputs=["/odometry/filtered"], jobs=1)
    assert [r.params for r in results] == variants
    fused, yaw_only = results
    assert not fused.error and not yaw_only.error
    (f1,), (f2,) = fused.figures, yaw_only.figures
    assert f1.topic == f2.topic == "/odometry/filtered" and f1.messages > 100 and f1.rate_hz > 50
    assert f1.latency_sec == 0.0  # published when the measurement is applied, at its stamp
    assert 0 <= f1.rmse_m < f2.rmse_m


def test_a_failing_variant_is_a_row_with_its_reason(ekf_run: Path) -> None:
    """What a worker runs, here in-process: a variant that cannot be built reports why instead of ending the sweep."""
    from aiorobot.bag._sweep import _run_variant

    build = functools.partial(build_variant_nodes, ("aiorobot.fusion:EkfNode",), ())
    bad = _run_variant(str(ekf_run), build, ("frequency:=oops",), None, "/ground_truth/odom")
    assert bad.params == ("frequency:=oops",) and bad.figures == ()
    assert bad.error.startswith("_UsageError: parameter 'frequency': expected double, found string 'oops'")


def test_cli_bad_parameter_is_one_line_before_any_worker(ekf_run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "sweep", str(ekf_run), "--node", "aiorobot.fusion:EkfNode", "-p", "frequency:=oops", "-p", "frequency:=5.0"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("aiorobot bag sweep: error: ") and err.count("\n") == 1 and "frequency" in err
