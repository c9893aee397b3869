"""nav2_simple_commander's sync BasicNavigator under ``aiorobot exec``: a program written as Nav2's
example programs are (the same calls: setInitialPose, waitUntilNav2Active, getPath, smoothPath,
followPath, goToPose, followWaypoints, isTaskComplete, getFeedback, getResult, getTaskError,
lifecycleShutdown) runs as a real subprocess against the navigation server, a map server and a
kinematic robot added to its graph with ``--node``."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import cv2
import numpy as np
import pytest

pytestmark = pytest.mark.timeout(120)

STACK = '''
from aiorobot.nav import MapServer, NavigationServer
from tests.nav.test_navigation_e2e import KinematicRobot

MAP = {map!r}


class Robot(KinematicRobot):
    """The e2e tests' kinematic robot, saying where it is on amcl_pose too, as a perfect AMCL would."""

    def __init__(self):
        super().__init__()
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        self.estimate = self.create_publisher(PoseWithCovarianceStamped, "amcl_pose", 10)

    def step(self):
        from aiorobot.msgs.geometry_msgs import PoseWithCovarianceStamped

        super().step()
        m = PoseWithCovarianceStamped()
        m.header.frame_id = "map"
        m.pose.pose.position.x, m.pose.pose.position.y = self.pose[0], self.pose[1]
        m.pose.covariance = [0.0025 if i in (0, 7) else 0.01 if i == 35 else 0.0 for i in range(36)]
        self.estimate.publish(m)


class Map(MapServer):
    def __init__(self):
        super().__init__(yaml_filename=MAP)


class Nav(NavigationServer):
    def __init__(self):
        super().__init__(parameter_overrides={{"desired_linear_vel": 0.8}})
'''

PROGRAM = '''
import rclpy
from geometry_msgs.msg import PoseStamped
from nav2_simple_commander.robot_navigator import BasicNavigator, TaskResult


def pose(navigator, x, y):
    p = PoseStamped()
    p.header.frame_id = "map"
    p.header.stamp = navigator.get_clock().now().to_msg()
    p.pose.position.x, p.pose.position.y, p.pose.orientation.w = x, y, 1.0
    return p


def wait(navigator, task):
    i = 0
    while not navigator.isTaskComplete(task=task):
        i += 1
        feedback = navigator.getFeedback(task=task)
        if feedback and i % 5 == 0:
            print("feedback", type(feedback).__name__)
    return navigator.getResult()


def main():
    rclpy.init()
    navigator = BasicNavigator()
    start = pose(navigator, 0.0, 0.0)
    navigator.setInitialPose(start)
    navigator.waitUntilNav2Active()
    # example_follow_path's calls (every goal straight ahead: the test stays short)
    path = navigator.getPath(start, pose(navigator, 0.6, 0.0))
    smoothed = navigator.smoothPath(path)
    print("path", len(path.poses), "smoothed", len(smoothed.poses))
    print("follow_path", wait(navigator, navigator.followPath(smoothed)).name)
    # example_nav_to_pose's
    print("go_to_pose", wait(navigator, navigator.goToPose(pose(navigator, 1.1, 0.0))).name)
    # example_waypoint_follower's
    task = navigator.followWaypoints([pose(navigator, 1.5, 0.0), pose(navigator, 1.9, 0.0)])
    print("waypoints", wait(navigator, task).name, navigator.getFeedback().current_waypoint)
    # a goal in the wall fails with Nav2's code
    print("wall", wait(navigator, navigator.goToPose(pose(navigator, 2.9, 0.0))).name, navigator.getTaskError())
    navigator.lifecycleShutdown()
    exit(0)


if __name__ == "__main__":
    main()
'''


def test_a_program_written_as_nav2s_examples_reaches_its_goals_under_aiorobot_exec(tmp_path: Path) -> None:
    img = np.full((60, 80), 254, np.uint8)  # 4 m x 3 m at 5 cm, origin (-1, -1.5)
    img[:2, :] = img[-2:, :] = img[:, :2] = img[:, -2:] = 0
    cv2.imwrite(str(tmp_path / "room.pgm"), img)
    (tmp_path / "room.yaml").write_text("image: room.pgm\nresolution: 0.05\norigin: [-1.0, -1.5, 0.0]\n"
                                        "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    (tmp_path / "stack.py").write_text(STACK.format(map=str(tmp_path / "room.yaml")))
    (tmp_path / "program.py").write_text(textwrap.dedent(PROGRAM))
    root = Path(__file__).resolve().parents[2]  # the stack reuses tests.nav.test_navigation_e2e's robot
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(root), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-m", "aiorobot.cli", "exec", "--node", "stack:Robot", "--node", "stack:Map",
                           "--node", "stack:Nav", str(tmp_path / "program.py")],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=110)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    out = proc.stdout
    assert "follow_path SUCCEEDED" in out and "go_to_pose SUCCEEDED" in out and "waypoints SUCCEEDED 1" in out, out
    assert "wall FAILED (206, 'the goal (2.90, 0.00) is in or too close to an obstacle" in out, out
    assert "Nav2 is ready for use!" in proc.stderr
