"""The ROS 2 project's own rclpy programs, unmodified, under ``aiorobot exec``.

Each runs as a subprocess; the other side of its conversation is a native aiorobot node
added to its graph with ``--node`` (a mixed graph), or the program's own second node.
Programs that run until Ctrl-C get a SIGINT once their output shows they work, and must
end with status 0 as under rclpy (the examples catch KeyboardInterrupt).
"""

from __future__ import annotations

import pytest

from ._run import Program

# (fixture, native nodes, lines expected (each at least `count` times), count, ends by itself)
CASES = [
    ("examples_rclpy_minimal_publisher/publisher_member_function.py", ("Listener",),
     ['Publishing: "Hello World: 1"', "native heard: Hello World: 1"], 1, False),
    ("examples_rclpy_minimal_publisher/publisher_local_function.py", ("Listener",),
     ['Publishing: "Hello World: 1"', "native heard: Hello World: 1"], 1, False),
    ("examples_rclpy_minimal_subscriber/subscriber_member_function.py", ("Talker",),
     ['I heard: "native'], 3, False),
    ("examples_rclpy_minimal_subscriber/subscriber_lambda.py", ("Talker",), ['I heard: "native'], 3, False),
    ("examples_rclpy_minimal_subscriber/subscriber_old_school.py", ("Talker",), ['I heard: "native'], 3, False),
    pytest.param("examples_rclpy_minimal_service/service.py", ("AddTwoIntsClient",),
     ["Incoming request", "native client got: 5"], 1, False),
    ("examples_rclpy_minimal_service/service_member_function.py", ("AddTwoIntsClient",),
     ["Incoming request", "native client got: 5"], 1, False),
    ("examples_rclpy_minimal_client/client.py", ("AddTwoIntsServer",),
     ["Result of add_two_ints: for 41 + 1 = 42"], 1, True),
    ("examples_rclpy_minimal_client/client_async.py", ("AddTwoIntsServer",),
     ["Result of add_two_ints: for 41 + 1 = 42"], 1, True),
    ("examples_rclpy_minimal_client/client_async_callback.py", ("AddTwoIntsServer",),
     ["Result of add_two_ints: for 41 + 1 = 42"], 1, True),
    ("examples_rclpy_minimal_client/client_async_member_function.py", ("AddTwoIntsServer",),
     ["Result of add_two_ints: for 41 + 1 = 42"], 1, True),
    ("examples_rclpy_minimal_action_server/server.py", ("FibonacciClient",),
     ["Publishing feedback: [0, 1, 1, 2]", "native action result: [0, 1, 1, 2] SUCCEEDED"], 1, False),
    ("examples_rclpy_minimal_action_client/client.py", ("FibonacciServer",),
     ["Goal accepted :)", "Goal succeeded! Result:"], 1, True),
    ("examples_rclpy_executors/composed.py", (), ['I heard: "Hello World: 1"'], 1, False),
    ("examples_rclpy_executors/callback_group.py", (), ['I heard: "Hello World: 2"'], 1, False),
    ("examples_rclpy_minimal_action_client/client_not_composable.py", ("FibonacciServer",),
     ["Goal accepted :)", "Goal succeeded! Result:"], 1, True),
    ("examples_rclpy_minimal_action_client/client_cancel.py", ("SlowFibonacciServer",),
     ["Goal accepted :)", "Canceling goal", "Goal successfully canceled"], 1, True),
    # its own asyncio loop drives rclpy.spin_once; two goals in parallel, then two in sequence
    ("examples_rclpy_minimal_action_client/client_asyncio.py", ("FibonacciServer",),
     ["unfinished: 0", "A) result", "B) result"], 1, True),
    ("examples_rclpy_minimal_action_server/server_defer.py", ("FibonacciClient",),
     ["Deferring execution...", "native action result: [0, 1, 1, 2] SUCCEEDED"], 1, False),
    ("examples_rclpy_minimal_action_server/server_not_composable.py", ("FibonacciClient",),
     ["native action result: [0, 1, 1, 2] SUCCEEDED"], 1, False),
    ("examples_rclpy_minimal_action_server/server_queue_goals.py", ("FibonacciClient",),
     ["native action result: [0, 1, 1, 2] SUCCEEDED"], 1, False),
    ("examples_rclpy_minimal_action_server/server_single_goal.py", ("FibonacciClient",),
     ["native action result: [0, 1, 1, 2] SUCCEEDED"], 1, False),
    ("examples_rclpy_executors/talker.py", ("Listener",),
     ['Publishing: "Hello World: 1"', "native heard: Hello World: 1"], 1, False),
    ("examples_rclpy_executors/listener.py", ("Talker",), ['I heard: "native'], 3, False),
    # a custom Executor whose spin_once takes work with wait_for_ready_callbacks
    ("examples_rclpy_executors/custom_executor.py", (), ['I heard: "Hello World: 1"'], 1, False),
    # sensor_msgs_py.point_cloud2.create_cloud: a 100 x 100 moving surface in z = +-0.5 m
    ("examples_rclpy_pointcloud_publisher/pointcloud_publisher.py", ("CloudListener",),
     ["native cloud: 10000x1 in map, x -2.0..2.0, |z| <= 0.5"], 3, False),
    ("demo_nodes_py/topics/talker.py", ("Listener",), ["Publishing: \"Hello World: 1\"", "native heard: Hello World: 1"], 1, False),
    ("demo_nodes_py/topics/listener.py", ("Talker",), ["I heard: [native"], 3, False),
    pytest.param("demo_nodes_py/services/add_two_ints_server.py", ("AddTwoIntsClient",), ["native client got: 5"], 1, False),
    ("demo_nodes_py/services/add_two_ints_client.py", ("AddTwoIntsServer",), ["Result of add_two_ints: 5"], 1, True),
    ("demo_nodes_py/services/add_two_ints_client_async.py", ("AddTwoIntsServer",), ["Result of add_two_ints: 5"], 1, True),
]


@pytest.mark.parametrize("script, nodes, needles, count, ends", CASES, ids=[(c.values if hasattr(c, "values") else c)[0] for c in CASES])
def test_upstream_program_runs_unmodified(script, nodes, needles, count, ends):
    program = Program(script, nodes=nodes)
    program.wait_for(*needles, count=count)
    code = program.finish() if ends else program.stop()
    assert code == 0, f"exit status {code}; output:\n{program.output}"
    assert "Traceback" not in program.output, program.output


def test_guard_condition_callback_runs_in_the_next_spin_once_as_in_rclpy():
    """trigger_guard_condition.py: the timer's spin_once ends; the next one runs the guard's callback."""
    program = Program("examples_rclpy_guard_conditions/trigger_guard_condition.py")
    assert program.finish() == 0, program.output
    lines = [line.split("]: ", 1)[-1] for line in program.lines if "]: " in line]
    assert lines == [
        "waiting for 'spin_once' to finish...",
        "timer callback triggered guard condition",
        "...'spin_once' finished!",
        "waiting for 'spin_once' to finish...",
        "guard callback called shutdown",
        "...'spin_once' finished!",
    ], program.output


def _stamps(program: Program, needle: str) -> list[float]:
    return [float(line.split("] [")[1]) for line in program.lines if needle in line]


def test_a_custom_callback_group_throttles_its_timer_as_in_rclpy():
    """custom_callback_group.py: a token bucket of 10 lets the 10 Hz timer burst, then refill at 2 Hz."""
    program = Program("examples_rclpy_executors/custom_callback_group.py", nodes=("Listener",))
    program.wait_for('Publishing: "Hello World: 14"')
    assert program.stop() == 0, program.output
    stamps = _stamps(program, 'Publishing: "Hello World:')
    burst = (stamps[9] - stamps[0]) / 9  # the bucket's 10 tokens: one per 0.1 s timer period
    throttled = (stamps[14] - stamps[11]) / 3  # then one token per 0.5 s refill
    assert throttled > 2.5 * burst, (burst, throttled, program.output)
    assert "native heard: Hello World: 12" in program.output


def test_a_missing_rclpy_name_fails_at_that_name_with_the_docs_link(tmp_path):
    script = tmp_path / "uses_type_support.py"
    script.write_text("import rclpy\nfrom rclpy.type_support import check_for_type_support\n")
    program = Program(str(script))
    code = program.finish()
    assert code == 1
    assert "aiorobot does not provide rclpy.type_support yet; see https://" in program.output
    # one line, naming the program's own line that reached the name; no traceback
    assert f"{script}:2: aiorobot does not provide" in program.output
    assert "Traceback" not in program.output


def test_a_missing_node_method_fails_where_the_program_calls_it(tmp_path):
    script = tmp_path / "uses_waitables.py"
    script.write_text("import rclpy\nrclpy.init()\nnode = rclpy.create_node('n')\nnode.add_waitable(None)\n")
    program = Program(str(script))
    assert program.finish() == 1
    assert f"{script}:4: aiorobot does not provide rclpy.node.Node.add_waitable yet" in program.output
    assert "Traceback" not in program.output
