"""The demo's graph: which nodes, on which loop, with which parameters.

Main loop: the simulator, the serial motor bridge (``drive = "serial"``), AMCL or the landmark
fixes, perception's front ends (ArUco in a worker process, lidar segmentation in the thread pool),
the navigation server and the navigator. Priority loop: the mecanum base controller (serial
drive) and the EKFs (robot_localization's dual set-up, ``examples/fusion_ekf.toml``).

Time: at real-time factor 1 the graph runs on system time, as on a robot (the simulator stamps
with system time and publishes no ``/clock``; every timer keeps its own deadlines); at any other
factor, lock-step 0 included, the simulator owns sim time and every node follows ``/clock``.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from typing import Any

__all__ = ["DRIVES", "LOCALISATIONS", "ROBOT_RADIUS", "DemoGraph", "build_graph", "time_source_for"]

#: ``direct``: the simulator follows /cmd_vel (lock-step possible); ``serial``: the simulated
#: ESP32 firmware on a pty, through SerialMotorBridge and MecanumController (real time only).
DRIVES = ("direct", "serial")
#: ``amcl``: the particle filter on the lidar; ``landmarks``: ArUco fixes into the map-frame EKF.
LOCALISATIONS = ("amcl", "landmarks")
#: The simulated robot's footprint radius (m): the simulator's default, what a start or a waypoint must leave free.
ROBOT_RADIUS = 0.22
#: Rate of the priority loop's control timer (the base controller, or the odom EKF with direct drive).
CONTROL_HZ = 50.0

_TWIST_XY_YAW = [False] * 6 + [True, True, False, False, False, True] + [False] * 3
_YAW_RATE = [False] * 11 + [True] + [False] * 3
#: landmark fixes: x, y, and yaw (measured by fixes from two or more markers; a one-marker fix's yaw
#: carries a variance of 1e6, so it adds nothing)
_POSE_XY_YAW = [True, True] + [False] * 3 + [True] + [False] * 9
_PROCESS_NOISE = [1e-4, 1e-4, 0.06, 0.03, 0.03, 1e-4, 0.025, 0.025, 0.04, 0.01, 0.01, 0.02, 0.01, 0.01, 0.015]


@dataclass
class DemoGraph:
    """The nodes of one demo run, by role."""

    nodes: list[tuple[Any, str]] = field(default_factory=list)
    simulator: Any = None
    server: Any = None
    control_node: Any = None
    aruco: Any = None
    scan_obstacles: Any = None
    landmark_fixes: Any = None
    recorder: Any = None
    port_link: str | None = None
    #: the simulator's ``time_source``: ``system`` -> run the runtime with ``use_sim_time = False``
    time_source: str = "sim"

    def add(self, node: Any, executor: str = "main") -> Any:
        self.nodes.append((node, executor))
        return node


def time_source_for(rtf: float) -> str:
    """``system`` at exactly real time (rtf 1), as a robot on hardware runs; ``sim`` otherwise."""
    return "system" if rtf == 1.0 else "sim"


def _ekf_parameters(world_frame: str, *, pose: bool, start: tuple[float, float, float]) -> dict[str, Any]:
    params: dict[str, Any] = {
        "frequency": CONTROL_HZ, "sensor_timeout": 0.1, "two_d_mode": True, "publish_tf": True,
        "map_frame": "map", "odom_frame": "odom", "base_link_frame": "base_link", "world_frame": world_frame,
        "odom0": "/odom", "odom0_config": _TWIST_XY_YAW, "odom0_queue_size": 10,
        "imu0": "/imu/data", "imu0_config": _YAW_RATE, "imu0_queue_size": 20,
        "imu0_remove_gravitational_acceleration": True,
        "smooth_lagged_data": True, "history_length": 1.0, "process_noise_covariance": _PROCESS_NOISE,
    }
    if pose:
        x, y, yaw = start
        params.update({
            "pose0": "/landmark_pose", "pose0_config": _POSE_XY_YAW, "pose0_rejection_threshold": 5.0,
            "initial_state": [x, y, 0.0, 0.0, 0.0, yaw] + [0.0] * 9,
        })
    return params


def build_graph(
    world: Any,
    *,
    rtf: float,
    seed: int,
    drive: str,
    localisation: str,
    perception: bool,
    record: str | None = None,
    time_source: str | None = None,
    start: tuple[float, float, float] | None = None,
) -> DemoGraph:
    """Construct the demo's nodes (not yet added to a runtime) for ``world`` (a loaded World).

    ``start`` (x, y, yaw in map) is where the robot starts and where localisation begins; None
    takes :func:`~aiorobot.sim.resolve_start`'s choice (the world's start, or the free cell
    nearest it).

    ``time_source`` (``sim`` or ``system``, the simulator's parameter) defaults to
    :func:`time_source_for` ``(rtf)``; the runtime must use sim time exactly when it is ``sim``.
    """
    from aiorobot.fusion import EkfNode
    from aiorobot.nav import AmclNode, LandmarkFixNode, NavigationServer
    from aiorobot.sim import Simulator, resolve_start

    if drive not in DRIVES:
        raise ValueError(f"drive: expected one of {', '.join(DRIVES)}, found {drive!r}")
    if localisation not in LOCALISATIONS:
        raise ValueError(f"localisation: expected one of {', '.join(LOCALISATIONS)}, found {localisation!r}")
    if drive == "serial" and rtf == 0.0:
        raise ValueError("drive 'serial' needs a real-time factor > 0 (the pty runs on the wall clock); "
                         "use --rtf 1, or --drive direct with --rtf 0")
    if localisation == "landmarks" and not perception:
        raise ValueError("localisation 'landmarks' needs perception (the ArUco detections)")
    if time_source not in (None, "sim", "system"):
        raise ValueError(f"time_source: expected 'sim' or 'system', found {time_source!r}")
    if time_source == "system" and rtf != 1.0:
        raise ValueError(f"time_source 'system' needs a real-time factor of exactly 1 (stamps are system time), "
                         f"found {rtf:g}; use time_source 'sim'")
    start = resolve_start(world, start, ROBOT_RADIUS).pose  # checked whether given or not
    g = DemoGraph(time_source=time_source_for(rtf) if time_source is None else time_source)
    world_ref = str(world.path) if world.path else world.name
    sim_params: dict[str, Any] = {
        "world": world_ref, "robot": "mecanum", "seed": seed, "real_time_factor": rtf,
        "publish_odom_tf": False, "camera_rate": 15.0 if perception else 0.0,
        "drive": "serial" if drive == "serial" else "cmd_vel", "time_source": g.time_source,
        "start": list(start), "robot_radius": ROBOT_RADIUS,
    }
    if drive == "serial":
        g.port_link = os.path.join(tempfile.gettempdir(), f"aiorobot-demo-motors-{os.getpid()}")
        sim_params["port_link"] = g.port_link
    if record is not None:
        from aiorobot.bag import Recorder

        # first, so it taps every topic from its first message; raw camera frames (0.9 MB each) stay out
        g.recorder = g.add(Recorder(path=record, all_topics=True, exclude=r"^/camera/image_raw$"))
    g.simulator = g.add(Simulator(parameter_overrides=sim_params))
    if drive == "serial":
        from aiorobot.control import MecanumController, SerialMotorBridge

        g.add(SerialMotorBridge(parameter_overrides={"port": g.port_link, "reconnect_period_sec": 0.2}))
        g.control_node = g.add(MecanumController(parameter_overrides={
            "publish_tf": False, "rate_hz": CONTROL_HZ, "max_linear_x": 0.6, "max_linear_y": 0.6}), "priority")
    ekf_local = g.add(EkfNode("ekf_local", namespace="local",
                              parameter_overrides=_ekf_parameters("odom", pose=False, start=start)), "priority")
    if g.control_node is None:
        g.control_node = ekf_local
    if localisation == "amcl":
        sx, sy, syaw = start
        g.add(AmclNode(parameter_overrides={
            "robot_model_type": "omnidirectional", "set_initial_pose": True,
            "initial_pose.x": sx, "initial_pose.y": sy, "initial_pose.yaw": syaw,
            "update_min_d": 0.05, "update_min_a": 0.05, "min_particles": 300, "max_particles": 1000, "seed": seed,
            "alpha1": 0.05, "alpha2": 0.05, "alpha3": 0.05, "alpha4": 0.05, "alpha5": 0.05, "sigma_hit": 0.1,
        }))
    else:
        from aiorobot.nav import landmark_map_path
        from aiorobot.sim import builtin_world_path

        landmark_map = str(landmark_map_path(world.path or builtin_world_path(world.name)))
        g.landmark_fixes = g.add(LandmarkFixNode(parameter_overrides={"landmark_map": landmark_map, "max_range_m": 6.0}))
        g.add(EkfNode("ekf_global", namespace="global",
                      parameter_overrides=_ekf_parameters("map", pose=True, start=start)), "priority")
    if perception:
        from aiorobot.perception import ArucoNode, ScanObstacleNode

        g.aruco = g.add(ArucoNode(parameter_overrides={
            "workers": 1, "queue": 1, "policy": "latest", "marker_length": 0.2, "dictionary": "DICT_4X4_50"}))
        g.scan_obstacles = g.add(ScanObstacleNode(parameter_overrides={
            "break_distance": 0.2, "min_points": 3, "max_radius": 1.0}))
    g.server = g.add(NavigationServer(parameter_overrides={
        "desired_linear_vel": 0.5, "stop_on_failure": False, "movement_time_allowance": 15.0}))
    return g
