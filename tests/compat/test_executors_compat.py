"""rclpy's executor protocol on aiorobot: spin_once runs one callback, custom executors and groups."""

from __future__ import annotations

from ._run import Program

CUSTOM_EXECUTOR = '''
import threading
from concurrent.futures import ThreadPoolExecutor

import rclpy
from rclpy.executors import Executor, TimeoutException
from std_msgs.msg import String


class PoolExecutor(Executor):
    def __init__(self):
        super().__init__()
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="custom-pool")

    def spin_once(self, timeout_sec=None):
        handler, entity, node = self.wait_for_ready_callbacks(timeout_sec=timeout_sec)
        print("ready:", type(entity).__name__, node.get_name(), flush=True)
        self.pool.submit(handler)


rclpy.init()
node = rclpy.create_node("custom")
pub = node.create_publisher(String, "t", 10)
node.create_subscription(String, "t", lambda m: print("heard", m.data, "in", threading.current_thread().name, flush=True), 10)
executor = PoolExecutor()
executor.add_node(node)
try:
    executor.spin_once(timeout_sec=0.05)
except TimeoutException:
    print("nothing ready: TimeoutException", flush=True)
node.create_timer(0.05, lambda: pub.publish(String(data="hi")))
for _ in range(6):
    executor.spin_once()
executor.pool.shutdown(wait=True)
rclpy.shutdown()
'''

SPIN_ONCE = '''
import rclpy
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node("one_at_a_time")
pub = node.create_publisher(String, "t", 10)
heard = []
node.create_subscription(String, "t", lambda m: heard.append(m.data), 10)
for i in range(5):
    pub.publish(String(data=str(i)))
for expected in range(1, 6):
    rclpy.spin_once(node, timeout_sec=5.0)
    print("after spin_once:", len(heard), flush=True)
rclpy.spin_once(node, timeout_sec=0.05)
print("nothing left:", heard, flush=True)
rclpy.shutdown()
'''


def test_a_custom_executor_takes_callbacks_with_wait_for_ready_callbacks_and_runs_them_in_its_pool(tmp_path):
    script = tmp_path / "custom_executor.py"
    script.write_text(CUSTOM_EXECUTOR)
    program = Program(str(script))
    assert program.finish() == 0, program.output
    assert "nothing ready: TimeoutException" in program.output
    assert "ready: Timer custom" in program.output and "ready: Subscription custom" in program.output
    heard = [line for line in program.lines if line.startswith("heard hi")]
    assert heard and all(line.endswith("in custom-pool_0") for line in heard), program.output


def test_spin_once_runs_one_callback_per_call_as_rclpy(tmp_path):
    """Five queued messages: each spin_once delivers exactly one (listener_qos' --number_of_cycles)."""
    script = tmp_path / "spin_once.py"
    script.write_text(SPIN_ONCE)
    program = Program(str(script))
    assert program.finish() == 0, program.output
    counts = [int(line.rsplit(":", 1)[1]) for line in program.lines if line.startswith("after spin_once:")]
    assert counts == [1, 2, 3, 4, 5], program.output
    assert "nothing left: ['0', '1', '2', '3', '4']" in program.output


WAIT_FOR_MESSAGE = '''
import rclpy
from rclpy.wait_for_message import wait_for_message
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node("waiter")
heard = []
node.create_subscription(String, "/chatter", lambda m: heard.append(m.data), 10)
ok, msg = wait_for_message(String, node, "/chatter", time_to_wait=20.0)
print("got:", ok, msg.data if ok else None, "| callbacks meanwhile:", len(heard), flush=True)
ok, msg = wait_for_message(String, node, "/nobody_publishes_this", time_to_wait=0.1)
print("nothing:", ok, msg, flush=True)
rclpy.shutdown()
'''


def test_wait_for_message_returns_the_next_message_or_false_after_its_time(tmp_path):
    script = tmp_path / "wait_for_message.py"
    script.write_text(WAIT_FOR_MESSAGE)
    program = Program(str(script), nodes=("Talker",))
    assert program.finish() == 0, program.output
    # as rclpy's wait set: the message, and the program's own callbacks did not run meanwhile
    assert "got: True native" in program.output and "| callbacks meanwhile: 0" in program.output, program.output
    assert "nothing: False None" in program.output


ENDPOINT_INFO = '''
import rclpy
from rclpy.qos import ReliabilityPolicy
from rclpy.topic_endpoint_info import TopicEndpointTypeEnum
from std_msgs.msg import String

rclpy.init()
node = rclpy.create_node("inspector", namespace="/robot")
node.create_subscription(String, "/chatter", lambda m: None, 10)
rclpy.spin_once(node, timeout_sec=0.5)
for p in node.get_publishers_info_by_topic("/chatter"):
    print("publisher:", p.node_namespace, p.node_name, p.topic_type, p.endpoint_type.name,
          p.qos_profile.reliability == ReliabilityPolicy.RELIABLE, p.topic_type_hash.startswith("RIHS01_"), flush=True)
for s in node.get_subscriptions_info_by_topic("/chatter"):
    print("subscription:", s.node_namespace, s.node_name, s.endpoint_type is TopicEndpointTypeEnum.SUBSCRIPTION, flush=True)
print("unknown topic:", node.get_publishers_info_by_topic("/nothing"), flush=True)
rclpy.shutdown()
'''


def test_get_publishers_and_subscriptions_info_by_topic_describe_the_graph(tmp_path):
    script = tmp_path / "endpoint_info.py"
    script.write_text(ENDPOINT_INFO)
    program = Program(str(script), nodes=("Talker",))
    assert program.finish() == 0, program.output
    assert "publisher: / native_talker std_msgs/msg/String PUBLISHER True True" in program.output, program.output
    assert "subscription: /robot inspector True" in program.output
    assert "unknown topic: []" in program.output
