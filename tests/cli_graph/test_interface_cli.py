"""``aiorobot interface``: the types aiorobot.msgs knows, offline (no graph)."""

from __future__ import annotations

import pytest

from aiorobot.cli import main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["interface", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_show_expands_nested_types_and_splits_sections(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "show", "geometry_msgs/msg/TwistStamped")
    assert code == 0
    assert out.splitlines() == [
        "std_msgs/Header header",
        "\tbuiltin_interfaces/Time stamp",
        "\t\tint32 sec",
        "\t\tuint32 nanosec",
        "\tstring frame_id",
        "Twist twist",
        "\tVector3 linear",
        "\t\tfloat64 x",
        "\t\tfloat64 y",
        "\t\tfloat64 z",
        "\tVector3 angular",
        "\t\tfloat64 x",
        "\t\tfloat64 y",
        "\t\tfloat64 z",
    ]
    assert run(capsys, "show", "example_interfaces/srv/AddTwoInts")[1] == "int64 a\nint64 b\n---\nint64 sum\n"
    assert run(capsys, "show", "example_interfaces/action/Fibonacci")[1] == "int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n"
    assert run(capsys, "show", "action_msgs/msg/GoalStatus")[1].startswith("int8 STATUS_UNKNOWN=0\nint8 STATUS_ACCEPTED=1\n")


def test_list_and_package_use_ros2_interface_layout(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "list")
    lines = out.splitlines()
    assert code == 0 and lines[0] == "Messages:" and "    geometry_msgs/msg/Twist" in lines
    assert lines.index("Services:") < lines.index("    std_srvs/srv/Trigger") < lines.index("Actions:")
    assert lines[lines.index("Actions:") + 1] == "    action_tutorials_interfaces/action/Fibonacci"
    assert "    example_interfaces/action/Fibonacci" in lines[lines.index("Actions:"):]
    assert run(capsys, "package", "std_srvs")[1] == "std_srvs/srv/Empty\nstd_srvs/srv/SetBool\nstd_srvs/srv/Trigger\n"
    assert run(capsys, "package", "example_interfaces", "-a")[1] == "example_interfaces/action/Fibonacci\n"
    assert "geometry_msgs" in run(capsys, "packages")[1].splitlines()


def test_unknown_types_and_packages_give_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "show", "geometry_msgs/msg/Twst")
    assert code == 1 and out == ""
    assert err.splitlines() == [
        "aiorobot interface show: error: unknown interface type 'geometry_msgs/msg/Twst'; "
        "did you mean 'geometry_msgs/msg/Twist', 'geometry_msgs/msg/Pose', 'geometry_msgs/msg/TwistStamped'?"
    ]
    code, out, err = run(capsys, "package", "nope")
    assert code == 1 and len(err.splitlines()) == 1 and "unknown package 'nope'" in err
    assert run(capsys, "show")[0] == 2
