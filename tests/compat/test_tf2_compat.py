"""tf2_ros and tf2_geometry_msgs for rclpy programs under ``aiorobot exec``.

The tf2 tutorial programs (ros/geometry_tutorials, turtle_tf2_py) run unmodified, as ``ros2 run``
runs them (their console_scripts entry point), beside native aiorobot nodes that echo /tf and
/tf_static and look the transforms up in a native aiorobot.tf buffer. Small compat programs
written here check the blocking lookups (from a SingleThreadedExecutor's callback, a
MultiThreadedExecutor's pool and the main thread), the timeout exceptions, the futures and
``tf2_geometry_msgs``.
"""

from __future__ import annotations

import math
import re
import textwrap

import pytest

from ._run import Program

STATIC = "turtle_tf2_py.static_turtle_tf2_broadcaster:main"
FIXED = "turtle_tf2_py.fixed_frame_tf2_broadcaster:main"
DYNAMIC = "turtle_tf2_py.dynamic_frame_tf2_broadcaster:main"

_ECHO = re.compile(r"native tf echo (\S+) (\S+)->(\S+) t=\((\S+), (\S+), (\S+)\) q=\((\S+), (\S+), (\S+), (\S+)\)")


def _echoed(program: Program) -> list[tuple[str, str, str, tuple[float, ...], tuple[float, ...]]]:
    out = []
    for line in program.lines:
        m = _ECHO.search(line)
        if m:
            values = tuple(float(v) for v in m.groups()[3:])
            out.append((m[1], m[2], m[3], values[:3], values[3:]))
    return out


def _stop_cleanly(program: Program) -> None:
    code = program.stop()
    assert code == 0, f"exit status {code}; output:\n{program.output}"
    assert "Traceback" not in program.output, program.output


def _stop_as_under_rclpy(program: Program) -> None:
    """Ctrl-C. The tutorials catch KeyboardInterrupt and then call ``rclpy.shutdown()``, but Ctrl-C has
    already shut the context down: rclpy raises there (RCLError "rcl_shutdown already called"), so do we."""
    code = program.stop()
    out = program.output
    assert code == 1, f"exit status {code}; output:\n{out}"
    assert out.count("Traceback") == 1, out
    assert "in main\n    rclpy.shutdown()" in out, out
    assert out.rstrip().endswith(
        "RuntimeError: rclpy.shutdown: the context is already shut down (or was never initialized); "
        "rclpy.try_shutdown() does nothing in that case"
    ), out


# -- the tutorial programs -------------------------------------------------------------------------


def test_static_turtle_broadcaster_sends_the_tutorials_static_frame_on_tf_static():
    # the tutorial's command: ros2 run turtle_tf2_py static_turtle_tf2_broadcaster mystaticturtle 0 0 1 0 0 0
    program = Program(STATIC, "mystaticturtle", "0", "0", "1", "0", "0", "0", nodes=("TfEcho", "StaticTurtleLookup"))
    program.wait_for("native tf echo /tf_static world->mystaticturtle", "native lookup world<-mystaticturtle")
    _stop_as_under_rclpy(program)
    topic, parent, child, t, q = _echoed(program)[0]
    assert (topic, parent, child) == ("/tf_static", "world", "mystaticturtle")
    assert t == (0.0, 0.0, 1.0) and q == (0.0, 0.0, 0.0, 1.0)
    assert "native lookup world<-mystaticturtle t=(0.000, 0.000, 1.000) q=(0.000, 0.000, 0.000, 1.000)" in program.output


def test_static_turtle_broadcaster_turns_roll_pitch_yaw_into_the_quaternion():
    program = Program(STATIC, "turtle_up", "1", "2", "3", "0", "0", str(math.pi / 2), nodes=("TfEcho",))
    program.wait_for("native tf echo /tf_static world->turtle_up")
    _stop_as_under_rclpy(program)
    _topic, _parent, _child, t, q = _echoed(program)[0]
    assert t == (1.0, 2.0, 3.0)
    assert q == pytest.approx((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)), abs=1e-3)


@pytest.mark.parametrize(
    "args, code, message",
    [
        (("mystaticturtle", "0", "0", "1"), 1, "Invalid number of parameters"),
        (("world", "0", "0", "1", "0", "0", "0"), 2, 'Your static turtle name cannot be "world"'),
    ],
    ids=["wrong-count", "world"],
)
def test_static_turtle_broadcaster_refuses_bad_arguments_as_the_tutorial_says(args, code, message):
    program = Program(STATIC, *args)
    assert program.finish() == code, program.output
    assert message in program.output


def test_fixed_frame_broadcaster_puts_carrot1_two_metres_left_of_turtle1_on_tf():
    program = Program(FIXED, nodes=("TfEcho", "CarrotLookup"))
    program.wait_for("native tf echo /tf turtle1->carrot1", count=3)
    program.wait_for("native lookup turtle1<-carrot1")
    _stop_as_under_rclpy(program)
    echoed = _echoed(program)
    assert {(topic, parent, child) for topic, parent, child, _t, _q in echoed} == {("/tf", "turtle1", "carrot1")}
    assert all(t == (0.0, 2.0, 0.0) and q == (0.0, 0.0, 0.0, 1.0) for *_f, t, q in echoed)
    assert "native lookup turtle1<-carrot1 t=(0.000, 2.000, 0.000) q=(0.000, 0.000, 0.000, 1.000)" in program.output


def test_dynamic_frame_broadcaster_moves_carrot1_on_a_ten_metre_circle_around_turtle1():
    program = Program(DYNAMIC, nodes=("TfEcho", "CarrotLookup"))
    # x = 10 sin(pi s), y = 10 cos(pi s) with s the whole seconds: a new position every second
    program.wait_for("native tf echo /tf turtle1->carrot1", count=25)
    program.wait_for("native lookup turtle1<-carrot1")
    _stop_as_under_rclpy(program)
    echoed = _echoed(program)
    assert {(topic, parent, child) for topic, parent, child, _t, _q in echoed} == {("/tf", "turtle1", "carrot1")}
    for *_f, t, _q in echoed:
        assert math.hypot(t[0], t[1]) == pytest.approx(10.0, abs=2e-3) and t[2] == 0.0
    assert len({t for *_f, t, _q in echoed}) >= 2, "carrot1 never moved"


# -- compat programs using tf2_ros.Buffer + TransformListener ----------------------------------------

_HEADER = """
import sys
import threading

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time

import tf2_ros
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener
"""

_TIMER_PROGRAM = _HEADER + """

class Looker(Node):
    def __init__(self):
        super().__init__('looker')
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.timer = self.create_timer(0.1, self.on_timer)
        self.step = 0

    def on_timer(self):
        self.step += 1
        if self.step == 1:
            # stamped 0.5 s from now: found only if the listener keeps receiving while this callback waits
            when = self.get_clock().now() + Duration(seconds=0.5)
            t = self.tf_buffer.lookup_transform('odom', 'base_link', when, timeout=Duration(seconds=10.0))
            print(f'future lookup ok at {Time.from_msg(t.header.stamp) == when} '
                  f'x={t.transform.translation.x:.3f} in {threading.current_thread().name}', flush=True)
        elif self.step == 2:
            try:
                self.tf_buffer.lookup_transform('odom', 'nowhere', Time(), timeout=Duration(seconds=0.3))
            except tf2_ros.LookupException as e:
                print(f'timeout raised LookupException: {e}', flush=True)
        elif self.step == 3:
            later = self.get_clock().now() + Duration(seconds=60)
            try:
                self.tf_buffer.lookup_transform('odom', 'base_link', later, timeout=Duration(seconds=0.3))
            except tf2_ros.ExtrapolationException as e:
                print(f'timeout raised ExtrapolationException: {e}', flush=True)
            ok = self.tf_buffer.can_transform('odom', 'nowhere', Time(), timeout=Duration(seconds=0.2))
            print(f'can_transform after timeout: {ok}', flush=True)
            print('done', flush=True)


def main():
    rclpy.init()
    node = Looker()
    executor = rclpy.executors.MultiThreadedExecutor() if 'multi' in sys.argv else None
    try:
        rclpy.spin(node, executor)
    except KeyboardInterrupt:
        pass
    rclpy.try_shutdown()


if __name__ == '__main__':
    main()
"""


@pytest.mark.parametrize("executor", ["single", "multi"])
def test_lookup_transform_with_timeout_in_a_timer_callback_waits_while_the_listener_receives(tmp_path, executor):
    script = tmp_path / "looker.py"
    script.write_text(textwrap.dedent(_TIMER_PROGRAM))
    program = Program(str(script), executor, nodes=("OdomBroadcaster",))
    program.wait_for("done")
    _stop_cleanly(program)
    out = program.output
    assert "future lookup ok at True x=1.000" in out
    thread = "MainThread" if executor == "single" else "rclpy-executor"
    assert re.search(rf"future lookup ok .* in {thread}", out), out
    assert 'timeout raised LookupException: "nowhere" passed to lookup_transform argument source_frame does not exist' in out
    assert "timeout raised ExtrapolationException: Lookup would require extrapolation into the future" in out
    assert "can_transform after timeout: False" in out


_MAIN_THREAD_PROGRAM = _HEADER + """
from geometry_msgs.msg import PointStamped, PoseStamped, PoseWithCovarianceStamped, Vector3Stamped
import tf2_geometry_msgs

rclpy.init()
node = rclpy.create_node('main_looker')
buffer = Buffer()
listener = TransformListener(buffer, node, spin_thread=True)

# the main thread blocks: the listener receives meanwhile
t = buffer.lookup_transform('odom', 'base_link', Time(), timeout=Duration(seconds=10.0))
print(f'main lookup x={t.transform.translation.x:.3f} frames {t.header.frame_id}<-{t.child_frame_id}')

point = PointStamped()
point.header.frame_id = 'base_link'
point.point.x = 1.0
p = tf2_geometry_msgs.do_transform_point(point, t)
print(f'do_transform_point {p.header.frame_id} ({p.point.x:.3f}, {p.point.y:.3f}, {p.point.z:.3f})')

p = buffer.transform(point, 'odom', timeout=Duration(seconds=1.0))
print(f'buffer.transform point {p.header.frame_id} ({p.point.x:.3f}, {p.point.y:.3f}, {p.point.z:.3f})')

vector = Vector3Stamped()
vector.header.frame_id = 'base_link'
vector.vector.x = 1.0
v = buffer.transform(vector, 'odom')
print(f'buffer.transform vector ({v.vector.x:.3f}, {v.vector.y:.3f}, {v.vector.z:.3f})')

pose = PoseStamped()
pose.header.frame_id = 'base_link'
pose.pose.orientation.w = 1.0
q = buffer.transform(pose, 'odom').pose
print(f'buffer.transform pose ({q.position.x:.3f}, {q.position.y:.3f}) yaw-quat z={q.orientation.z:.3f} w={q.orientation.w:.3f}')

cov = PoseWithCovarianceStamped()
cov.header.frame_id = 'base_link'
cov.pose.pose.orientation.w = 1.0
values = [0.0] * 36
values[0] = 4.0  # variance along base_link x: along odom y after the 90 degree turn
cov.pose.covariance = values
c = buffer.transform(cov, 'odom').pose.covariance
print(f'buffer.transform covariance xx={c[0]:.3f} yy={c[7]:.3f}')

fut = buffer.wait_for_transform_async('odom', 'base_link', Time())
rclpy.spin_until_future_complete(node, fut, timeout_sec=10.0)
print(f'wait_for_transform_async done={fut.done()} child={fut.result().child_frame_id}')


async def lookup():
    return await buffer.lookup_transform_async('odom', 'base_link', Time())

task = rclpy.get_global_executor().create_task(lookup)
rclpy.spin_until_future_complete(node, task, timeout_sec=10.0)
print(f'lookup_transform_async x={task.result().transform.translation.x:.3f}')

try:
    buffer.transform(point, 'nowhere', timeout=Duration(seconds=0.2))
except tf2_ros.TransformException as e:
    print(f'transform to a missing frame raised {type(e).__name__}')

class Unregistered:
    pass

try:
    buffer.transform(Unregistered(), 'odom')
except tf2_ros.TypeException as e:
    print(f'TypeException: {e}')
rclpy.shutdown()
"""


def test_main_thread_lookup_blocks_while_receiving_and_tf2_geometry_msgs_transforms(tmp_path):
    script = tmp_path / "main_looker.py"
    script.write_text(textwrap.dedent(_MAIN_THREAD_PROGRAM))
    program = Program(str(script), nodes=("OdomBroadcaster",))
    code = program.finish()
    out = program.output
    assert code == 0 and "Traceback" not in out, out
    # odom <- base_link: 1 m along x, turned 90 degrees: base_link's x axis is odom's y axis
    assert "main lookup x=1.000 frames odom<-base_link" in out
    assert "do_transform_point odom (1.000, 1.000, 0.000)" in out
    assert "buffer.transform point odom (1.000, 1.000, 0.000)" in out
    assert "buffer.transform vector (0.000, 1.000, 0.000)" in out
    assert "buffer.transform pose (1.000, 0.000) yaw-quat z=0.707 w=0.707" in out
    assert "buffer.transform covariance xx=0.000 yy=4.000" in out
    assert "wait_for_transform_async done=True child=base_link" in out
    assert "lookup_transform_async x=1.000" in out
    assert "transform to a missing frame raised LookupException" in out
    assert "TypeException: Type Unregistered is not loaded or supported; import tf2_geometry_msgs" in out
