"""``aiorobot plot``: field paths, errors that name the field, and a PNG drawn from a bag."""

from __future__ import annotations

from pathlib import Path

import pytest

from aiorobot.bag import BagWriter
from aiorobot.cli import main
from aiorobot.cli._plot import PlotError, field_value, split_series
from aiorobot.msgs import serialize
from aiorobot.msgs.nav_msgs import Odometry
from aiorobot.msgs.sensor_msgs import JointState


def test_field_paths_reach_nested_fields_and_array_elements() -> None:
    odom = Odometry()
    odom.pose.pose.position.x = 1.25
    assert field_value(odom, "pose.pose.position.x") == 1.25
    assert field_value(JointState(position=[0.5, -2.0]), "position[1]") == -2.0


def test_a_wrong_field_names_the_type_and_its_fields() -> None:
    with pytest.raises(PlotError, match=r"Pose at pose.pose has no field 'positon' \(fields: position, orientation\)"):
        field_value(Odometry(), "pose.pose.positon.x")
    with pytest.raises(PlotError, match="pose.pose.position is a Point, not a number"):
        field_value(Odometry(), "pose.pose.position")


def test_the_topic_is_the_longest_known_prefix() -> None:
    assert split_series("/odom/filtered.pose.pose.position.x", ["/odom", "/odom/filtered"]) == ("/odom/filtered", "pose.pose.position.x")
    with pytest.raises(PlotError, match="no topic of the source is a prefix"):
        split_series("/nope.x", ["/odom"])


def test_plot_from_a_bag_writes_a_png(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "odom"
    with BagWriter(bag) as writer:
        writer.add_topic("/odom", "nav_msgs/msg/Odometry")
        for i in range(50):
            msg = Odometry()
            msg.pose.pose.position.x = i * 0.02
            msg.pose.pose.position.y = (i * 0.02) ** 2
            writer.write("/odom", i * 20_000_000, serialize(msg))
    out = tmp_path / "xy.png"
    assert main(["plot", "/odom.pose.pose.position.x", "/odom.pose.pose.position.y", "--bag", str(bag), "-o", str(out)]) == 0
    assert "2 series, 100 points" in capsys.readouterr().out
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 5000
    assert main(["plot", "/odom.pose.pose.positon.x", "--bag", str(bag), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "has no field 'positon'" in err
