"""An rclpy action server answers the goal request before it starts executing (issue 26 item 10).

rclpy sends the goal response, then schedules the execute callback. ros2/demos'
fibonacci_action_server.py sleeps in its (plain) execute callback; started first, it held the
response back, so a client in another process logged "Goal accepted" only after every
feedback. Here the server's execute callback blocks until the test has seen the client log
"Goal accepted": before the fix that never happened (the response waited for execute).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

from ._run import Program
from .test_mixed_zenoh import router  # noqa: F401 - the zenoh router fixture


def _zenoh(endpoint: str, script: Path, *args: str) -> Program:
    return Program(
        str(script), *args, exec_args=("--transport", "zenoh"),
        extra_env={"ZENOH_CONFIG_OVERRIDE": f'connect/endpoints=["{endpoint}"]'},
    )

SERVER = textwrap.dedent("""
    import os, sys, time
    from example_interfaces.action import Fibonacci
    import rclpy
    from rclpy.action import ActionServer
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node

    GO = sys.argv[1]

    class SlowFibonacci(Node):
        def __init__(self):
            super().__init__('slow_fibonacci_server')
            self._server = ActionServer(self, Fibonacci, 'fibonacci', self.execute_callback)

        def execute_callback(self, goal_handle):
            self.get_logger().info('Executing goal...')
            while not os.path.exists(GO):  # blocks the executor, as the upstream server's sleep(1)
                time.sleep(0.01)
            feedback = Fibonacci.Feedback()
            feedback.sequence = [0, 1]
            for i in range(1, goal_handle.request.order):
                feedback.sequence.append(feedback.sequence[i] + feedback.sequence[i - 1])
                self.get_logger().info('Feedback: {0}'.format([int(x) for x in feedback.sequence]))
                goal_handle.publish_feedback(feedback)
            goal_handle.succeed()
            return Fibonacci.Result(sequence=feedback.sequence)

    try:
        with rclpy.init():
            rclpy.spin(SlowFibonacci())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
""")

CLIENT = textwrap.dedent("""
    from example_interfaces.action import Fibonacci
    import rclpy
    from rclpy.action import ActionClient
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node

    class Client(Node):
        def __init__(self):
            super().__init__('fibonacci_client')
            self._client = ActionClient(self, Fibonacci, 'fibonacci')

        def send_goal(self, order):
            self._client.wait_for_server()
            future = self._client.send_goal_async(Fibonacci.Goal(order=order))
            future.add_done_callback(self.goal_response_callback)

        def goal_response_callback(self, future):
            handle = future.result()
            self.get_logger().info('Goal accepted :)' if handle.accepted else 'Goal rejected :(')
            handle.get_result_async().add_done_callback(self.result_callback)

        def result_callback(self, future):
            self.get_logger().info('Result: {0}'.format([int(x) for x in future.result().result.sequence]))
            rclpy.shutdown()

    try:
        with rclpy.init():
            client = Client()
            client.send_goal(4)
            rclpy.spin(client)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
""")


def test_the_goal_response_reaches_another_process_before_execute_runs(router, tmp_path: Path):  # noqa: F811
    (tmp_path / "server.py").write_text(SERVER)
    (tmp_path / "client.py").write_text(CLIENT)
    go = tmp_path / "go"
    server = _zenoh(router, tmp_path / "server.py", str(go))
    try:
        client = _zenoh(router, tmp_path / "client.py")
        client.wait_for("Goal accepted :)")  # while the server's execute callback still blocks
        assert "Feedback:" not in server.output, server.output
        go.touch()
        client.wait_for("Result: [0, 1, 1, 2, 3]")
        assert client.finish() == 0, client.output
        server.wait_for("Feedback: [0, 1, 1, 2, 3]")
    finally:
        server.stop()
    assert "Traceback" not in server.output + client.output, server.output + client.output
