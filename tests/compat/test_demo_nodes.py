"""ros2/demos' demo_nodes_py programs, unmodified, under ``aiorobot exec`` (issue 17).

Each does what demo_nodes_py's README and source say; the other side of the conversation
is a native aiorobot node (``--node``) or the program itself.
"""

from __future__ import annotations

import re
import shutil

import pytest

from ._run import FIXTURES, Program

_HEARD = re.compile(r"I heard: \[native \d+\]")


def _ends_cleanly(program: Program) -> None:
    code = program.finish()
    assert code == 0, f"exit status {code}; output:\n{program.output}"
    assert "Traceback" not in program.output, program.output


@pytest.mark.parametrize("reliable", [False, True], ids=["best_effort", "reliable"])
def test_talker_qos_publishes_number_of_cycles_messages_then_ends(reliable):
    args = ("--reliable",) if reliable else ()
    program = Program("demo_nodes_py/topics/talker_qos.py", *args, "-n", "2", nodes=("BestEffortListener",))
    program.wait_for("native heard: Hello World: 1")
    _ends_cleanly(program)
    assert ("Reliable talker" if reliable else "Best effort talker") in program.output
    published = [line for line in program.lines if "Publishing:" in line]
    assert [line.split("Publishing: ")[1] for line in published] == ['"Hello World: 0"', '"Hello World: 1"']


@pytest.mark.parametrize("reliable", [False, True], ids=["best_effort", "reliable"])
def test_listener_qos_handles_exactly_number_of_cycles_messages(reliable):
    args = ("--reliable",) if reliable else ()
    program = Program("demo_nodes_py/topics/listener_qos.py", *args, "-n", "3", nodes=("Talker",))
    _ends_cleanly(program)
    assert ("Reliable listener" if reliable else "Best effort listener") in program.output
    heard = [line for line in program.lines if "I heard:" in line]
    assert len(heard) == 3 and all(_HEARD.search(line) for line in heard), program.output


def test_best_effort_talker_qos_does_not_reach_a_reliable_listener():
    # the README's point: a reliable subscription does not connect to a best-effort publisher
    program = Program("demo_nodes_py/topics/talker_qos.py", "-n", "2", nodes=("Listener",))
    _ends_cleanly(program)
    assert "Publishing: \"Hello World: 1\"" in program.output
    assert "native heard" not in program.output
    assert "publisher offers BEST_EFFORT, subscription requests RELIABLE" in program.output


def test_listener_serialized_gets_cdr_bytes():
    program = Program("demo_nodes_py/topics/listener_serialized.py", nodes=("Talker",))
    program.wait_for("I heard: \"b'", count=2)
    code = program.stop()
    assert code == 0, program.output
    # std_msgs/String "native N" as rmw gives it: the CDR_LE header, the length with its NUL, the text
    line = next(line for line in program.lines if "I heard:" in line)
    number = re.search(r"native (\d+)", line).group(1)
    size = len(f"native {number}") + 1
    expected = repr(b"\x00\x01\x00\x00" + size.to_bytes(4, "little") + f"native {number}\x00".encode())
    assert line.endswith(f'I heard: "{expected}"'), line
    assert "Traceback" not in program.output


def test_set_parameters_callback_pre_set_also_sets_param2():
    program = Program("demo_nodes_py/parameters/set_parameters_callback.py", nodes=("SetParam1Driver",))
    program.wait_for("native got:")
    code = program.stop()
    assert code == 0, program.output
    assert "native set param1: [(True, '')]" in program.output
    # the pre-set callback appended param2 = 4.0; the post-set callback saw both
    assert "native got: param1=1.0 param2=4.0" in program.output
    assert "Traceback" not in program.output


def test_async_param_client_drives_parameter_blackboard(tmp_path):
    # an ament prefix with demo_nodes_py's share directory, as its setup.py installs params.yaml
    index = tmp_path / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "demo_nodes_py").touch()
    (tmp_path / "share" / "demo_nodes_py").mkdir()
    shutil.copy(FIXTURES / "demo_nodes_py/parameters/params.yaml", tmp_path / "share/demo_nodes_py/params.yaml")
    program = Program(
        "demo_nodes_py/parameters/async_param_client.py", nodes=("ParameterBlackboard",),
        extra_env={"AMENT_PREFIX_PATH": str(tmp_path)},
    )
    _ends_cleanly(program)
    out = [line.split("]: ", 1)[1] for line in program.lines if "[/async_param_client]" in line]
    start = out.index("Getting parameters:")
    assert out[start + 1:start + 4] == [
        "    - int_parameter: 10", "    - bool_parameter: False", "    - string_parameter: Fee Fi Fo Fum",
    ], program.output
    listed = out[out.index("Listing Parameters:") + 1:start]
    assert listed == ["    - int_parameter", "    - bool_parameter", "    - string_parameter"], program.output
    loaded = out[out.index("Loading parameters: ") + 1:out.index("Deleting parameters: ")]
    assert "        value: I smell the blood of an Englishman" in loaded, program.output
    assert loaded.count("        successful: True") == 5, program.output
    deleted = out[out.index("Deleting parameters: ") + 1:]
    assert deleted.count("        successful: True") == 3, program.output


def test_use_logger_service_changes_the_remote_node_level():
    program = Program("demo_nodes_py/logging/use_logger_service.py")
    _ends_cleanly(program)
    out = program.lines
    levels = [line.split("Current logger level: ")[1] for line in out if "Current logger level: " in line]
    assert levels == ["0", "10", "30", "40"], program.output

    def shown(n: int) -> list[str]:
        return [line.split("] ")[0] + "]" for line in out if f"Output {n} with" in line]

    # unset: the default INFO; then DEBUG, WARN and ERROR set through ~/set_logger_levels
    assert shown(1) == ["[INFO]", "[WARN]", "[ERROR]"], program.output
    assert shown(2) == ["[DEBUG]", "[INFO]", "[WARN]", "[ERROR]"], program.output
    assert shown(3) == ["[WARN]", "[ERROR]"], program.output
    assert shown(4) == ["[ERROR]"], program.output


def test_introspection_publishes_client_contents_and_service_metadata():
    program = Program(
        "demo_nodes_py/services/introspection.py", "--ros-args", "-p", "client_configure_introspection:=contents",
        "-p", "service_configure_introspection:=metadata", nodes=("ServiceEventEcho",),
    )
    program.wait_for("Result of add_two_ints: 5", count=2)
    code = program.stop()
    assert code == 0, program.output
    events = [line for line in program.lines if line.startswith("native event:") and " seq=1 " in line]
    # REQUEST_SENT and RESPONSE_RECEIVED (client, contents), REQUEST_RECEIVED and RESPONSE_SENT (service, metadata)
    assert [line.split(" gid=")[0] for line in events] == [f"native event: type={t} seq=1" for t in range(4)], program.output
    assert [line.split(" request=")[1] for line in events] == [
        "[(2, 3)] response=[]", "[] response=[]", "[] response=[]", "[] response=[5]",
    ], program.output
    assert len({line.split(" gid=")[1].split()[0] for line in events}) == 1, program.output  # the client's GID
    assert "Traceback" not in program.output


def test_introspection_disabled_by_default_publishes_nothing():
    program = Program("demo_nodes_py/services/introspection.py", nodes=("ServiceEventEcho",))
    program.wait_for("Result of add_two_ints: 5", count=2)
    assert program.stop() == 0, program.output
    assert "native event" not in program.output


def test_matched_event_detect_logs_each_connection_as_it_is_made_and_broken():
    # the program's own comments give what MatchedEventDetectNode prints after each step under rclpy
    program = Program("demo_nodes_py/events/matched_event_detect.py")
    _ends_cleanly(program)
    logged = [line.split("]: ", 1)[1] for line in program.lines if "]: " in line]
    sub, pub = "connected subscription", "connected publisher"
    assert logged == [
        "Create a new subscription.", "First subscription is connected.",
        "Create a new subscription.", f"The changed number of {sub} is 1 and current number of {sub} is 2",
        "Destroy a subscription.", f"The changed number of {sub} is -1 and current number of {sub} is 1",
        "Destroy a subscription.", "Last subscription is disconnected.",
        "Create a new publisher.", "First publisher is connected.",
        "Create a new publisher.", f"The changed number of {pub} is 1 and current number of {pub} is 2",
        "Destroy a publisher.", f"The changed number of {pub} is -1 and current number of {pub} is 1",
        "Destroy a publisher.", "Last publisher is disconnected.",
    ], program.output
    detector = [line for line in program.lines if "is connected." in line or "disconnected." in line]
    assert all("[/matched_event_detection_node]" in line for line in detector), program.output
