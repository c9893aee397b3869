"""``aiorobot exec --interfaces DIR`` / AIOROBOT_INTERFACES: a program's own interface packages.

The packages are written by the tests (tests/msgs/_workspace.py): one with a message, one
with a message, service and action using it. Imports of what is missing end in one line
at the program's line.
"""

from __future__ import annotations

import os
from pathlib import Path

from tests.msgs._workspace import write_workspace

from ._run import Program

_USE_PACKAGES = """\
import rclpy
from rclpy.node import Node
from {robot}.msg import Status
from {robot}.srv import GetStatus
from {robot}.action import Count
from {base}.msg import Pair

rclpy.init()
node = Node("custom_types")
heard = rclpy.task.Future()
node.create_subscription(Status, "status", lambda msg: heard.set_result(msg), 10)
pub = node.create_publisher(Status, "status", 10)
node.create_service(GetStatus, "get_status", lambda req, resp: GetStatus.Response(ok=req.name == "r2"))
client = node.create_client(GetStatus, "get_status")
pub.publish(Status(offset=Pair(x=1.5), note="from the program"))
rclpy.spin_until_future_complete(node, heard, timeout_sec=10.0)
answer = client.call_async(GetStatus.Request(name="r2"))
rclpy.spin_until_future_complete(node, answer, timeout_sec=10.0)
print("heard", heard.result().offset.x, heard.result().offset.y, heard.result().note)
print("answered", answer.result().ok, "goal", Count.Goal(order=4).order, Status.MODE_RUN)
node.destroy_node()
rclpy.shutdown()
"""


def _program(tmp_path: Path, tag: str) -> tuple[Path, Path]:
    base, robot = write_workspace(tmp_path / "ws" / "src", tag)
    script = tmp_path / "use_packages.py"
    script.write_text(_USE_PACKAGES.format(base=base, robot=robot))
    return tmp_path / "ws", script


def _check_ran(program: Program) -> None:
    assert program.finish() == 0, program.output
    assert "heard 1.5 2.5 from the program" in program.output
    assert "answered True goal 4 1" in program.output


def test_a_program_uses_message_service_and_action_types_of_its_packages(tmp_path: Path) -> None:
    workspace, script = _program(tmp_path, "ex1")
    _check_ran(Program(str(script), exec_args=("--interfaces", str(workspace))))


def test_aiorobot_interfaces_lists_package_folders(tmp_path: Path) -> None:
    workspace, script = _program(tmp_path, "ex2")
    folders = os.pathsep.join(str(p) for p in sorted((workspace / "src").iterdir()))
    _check_ran(Program(str(script), extra_env={"AIOROBOT_INTERFACES": folders}))


def test_a_package_not_given_ends_in_one_line_naming_the_option(tmp_path: Path) -> None:
    _, script = _program(tmp_path, "ex3")
    program = Program(str(script))
    assert program.finish() == 1
    assert program.output == (
        f"aiorobot exec: {script}:3: no interface package 'ex3_robot': aiorobot has ROS 2 Jazzy's standard "
        "ones; pass the folder of ex3_robot (its package.xml, msg/, srv/, action/) with "
        "`aiorobot exec --interfaces DIR` or in AIOROBOT_INTERFACES")


def test_a_missing_dependency_package_is_refused_before_the_program_starts(tmp_path: Path) -> None:
    workspace, script = _program(tmp_path, "ex4")
    program = Program(str(script), exec_args=("--interfaces", str(workspace / "src" / "ex4_robot")))
    assert program.finish() == 2
    status = workspace / "src" / "ex4_robot" / "msg" / "Status.msg"
    assert program.output == (
        f"aiorobot exec: error: --interfaces: {status}: ex4_robot/msg/Status uses ex4_geometry/msg/Pair, "
        "which is unknown; add the folder of package 'ex4_geometry' too (or register that type first)")


def test_a_missing_interface_name_ends_in_one_line_and_is_an_import_error(tmp_path: Path) -> None:
    script = tmp_path / "nav.py"
    script.write_text(
        "import rclpy\n"
        "from nav2_msgs.action import NavigateToPose, Spin, BackUp, DockRobot\n"
        "from nav2_msgs.srv import ClearEntireCostmap\n"
        "from tf2_msgs.srv import FrameGraph\n"
        "from composition_interfaces.srv import LoadNode\n"
        "try:\n"
        "    from nav2_msgs.msg import NoSuchThing\n"
        "except ImportError as err:\n"
        "    print('caught:', type(err).__name__)\n"
        "print('imported', Spin.Goal().__msgtype__, LoadNode.Request().__msgtype__)\n"
        "from nav2_msgs.action import NavigateToPoze\n"
        "print('not reached')\n"
    )
    program = Program(str(script))
    assert program.finish() == 1
    assert program.lines == [
        "caught: MissingInterfaceError",
        "imported nav2_msgs/action/Spin_Goal composition_interfaces/srv/LoadNode_Request",
        f"aiorobot exec: {script}:11: cannot import name 'NavigateToPoze' from 'nav2_msgs.action': aiorobot "
        "has no nav2_msgs/action/NavigateToPoze (did you mean NavigateToPose, NavigateThroughPoses?); for "
        "your own or a newer nav2_msgs, pass its folder with --interfaces DIR",
    ]


def test_an_ordinary_missing_module_keeps_pythons_traceback(tmp_path: Path) -> None:
    script = tmp_path / "plain.py"
    script.write_text("import rclpy\nimport no_such_module_here\n")
    program = Program(str(script))
    assert program.finish() == 1
    assert "ModuleNotFoundError: No module named 'no_such_module_here'" in program.output
    assert "Traceback" in program.output
