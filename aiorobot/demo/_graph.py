"""The demo's graph: which nodes, on which loop, with which parameters.

Main loop: the simulator, the serial motor bridge (``drive = "serial"``), AMCL, the landmark
fixes or SLAM (no map given: the simulator's world map goes to ``/world/map``), perception's front
ends (ArUco in a worker process, lidar segmentation in the thread pool), the navigation server and
the navigator. Priority loop: the collision monitor (between the navigation server's /cmd_vel_nav
and the base's /cmd_vel), the mecanum base controller (serial
drive) and the EKFs (robot_localization's dual set-up, ``dual_ekf.yaml``, which
``examples/fusion_ekf.toml`` shares). The nodes and their fixed parameters are in ``graph.toml``
(:data:`GRAPH_FILE`); :func:`build_graph` picks those the options ask for and adds the run's own.

Time: at real-time factor 1 the graph runs on system time, as on a robot (the simulator stamps
with system time and publishes no ``/clock``; every timer keeps its own deadlines); at any other
factor, lock-step 0 included, the simulator owns sim time and every node follows ``/clock``.
"""

from __future__ import annotations

import importlib
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["CONTROLLERS", "DRIVES", "LOCALISATIONS", "ROBOT_RADIUS", "WORLD_MAP_TOPIC", "DemoGraph", "build_graph", "time_source_for"]

#: ``direct``: the simulator follows /cmd_vel (lock-step possible); ``serial``: the simulated
#: ESP32 firmware on a pty, through SerialMotorBridge and MecanumController (real time only).
DRIVES = ("direct", "serial")
#: ``amcl``: the particle filter on the lidar; ``landmarks``: ArUco fixes into the map-frame EKF;
#: ``slam``: no map given, SlamNode builds it (and localises on it) as the robot drives.
LOCALISATIONS = ("amcl", "landmarks", "slam")
#: where the simulator's world map goes under ``slam``: /map is SLAM's
WORLD_MAP_TOPIC = "/world/map"
#: the navigation server's ``controller``: Regulated Pure Pursuit or MPPI (nav2_mppi_controller)
CONTROLLERS = ("rpp", "mppi")
#: The simulated robot's footprint radius (m): the simulator's default, what a start or a waypoint must leave free.
ROBOT_RADIUS = 0.22
#: The demo's graph: every node it may run, with the parameters no option changes (build_graph picks and adds).
GRAPH_FILE = Path(__file__).with_name("graph.toml")
#: node name in GRAPH_FILE -> the DemoGraph attribute that holds it
_ROLES = {"simulator": "simulator", "mecanum_controller": "control_node", "ekf_local": "ekf_local",
          "landmark_fixes": "landmark_fixes", "aruco": "aruco", "scan_obstacles": "scan_obstacles",
          "navigation_server": "server", "collision_monitor": "collision_monitor", "slam_toolbox": "slam"}


@dataclass
class DemoGraph:
    """The nodes of one demo run, by role."""

    nodes: list[tuple[Any, str]] = field(default_factory=list)
    simulator: Any = None
    server: Any = None
    collision_monitor: Any = None
    control_node: Any = None
    aruco: Any = None
    ekf_local: Any = None
    scan_obstacles: Any = None
    landmark_fixes: Any = None
    slam: Any = None
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


def _construct(spec: Any, run_parameters: dict[str, Any], remappings: dict[str, str] | None = None) -> Any:
    """Construct the node of one ``[[nodes]]`` table of :data:`GRAPH_FILE` with the run's parameters added.

    As ``aiorobot run`` builds a node (the table's name, namespace and remappings, its parameters over its
    parameters_file), without wrapping the node's own errors: the demo reports those as they are.
    """
    module_name, _, class_name = spec.use.partition(":")
    cls = getattr(importlib.import_module(module_name), class_name)
    parameters = {k: list(v) if isinstance(v, tuple) else v for k, v in spec.parameters.items()}
    parameters.update(run_parameters)
    kwargs: dict[str, Any] = {
        "parameter_overrides": parameters,
        "remappings": {"__node": spec.name, **spec.remap, **(remappings or {})},
    }
    if spec.namespace:
        kwargs["namespace"] = spec.namespace
    if spec.parameters_file:
        kwargs["cli_args"] = ["--ros-args", "--params-file", spec.parameters_file]
    node = cls(**kwargs)
    unclaimed = sorted(node.unclaimed_parameter_overrides())
    if unclaimed:
        raise ValueError(f"{GRAPH_FILE}: {spec.key}.parameters: expected parameters {spec.use} declares, "
                         f"found {', '.join(unclaimed)}")
    return node


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
    controller: str = "rpp",
) -> DemoGraph:
    """Construct the demo's nodes (not yet added to a runtime) for ``world`` (a loaded World).

    ``start`` (x, y, yaw in map) is where the robot starts and where localisation begins; None
    takes :func:`~aiorobot.sim.resolve_start`'s choice (the world's start, or the free cell
    nearest it). ``controller`` is the navigation server's (:data:`CONTROLLERS`).

    ``time_source`` (``sim`` or ``system``, the simulator's parameter) defaults to
    :func:`time_source_for` ``(rtf)``; the runtime must use sim time exactly when it is ``sim``.
    """
    from aiorobot import load_config
    from aiorobot.sim import builtin_world_path, resolve_start

    if drive not in DRIVES:
        raise ValueError(f"drive: expected one of {', '.join(DRIVES)}, found {drive!r}")
    if controller not in CONTROLLERS:
        raise ValueError(f"controller: expected one of {', '.join(CONTROLLERS)}, found {controller!r}")
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
    sx, sy, syaw = start
    run: dict[str, dict[str, Any]] = {
        "simulator": {
            "world": world_ref, "seed": seed, "real_time_factor": rtf, "camera_rate": 15.0 if perception else 0.0,
            "drive": "serial" if drive == "serial" else "cmd_vel", "time_source": g.time_source,
            "start": list(start), "robot_radius": ROBOT_RADIUS,
        },
        "ekf_local": {},
        "navigation_server": {"controller": controller},
        "collision_monitor": {},
    }
    if drive == "serial":
        g.port_link = os.path.join(tempfile.gettempdir(), f"aiorobot-demo-motors-{os.getpid()}")
        run["simulator"]["port_link"] = g.port_link
        run["serial_motor_bridge"] = {"port": g.port_link}
        run["mecanum_controller"] = {}
    remaps: dict[str, dict[str, str]] = {}
    if localisation == "amcl":
        run["amcl"] = {"initial_pose.x": sx, "initial_pose.y": sy, "initial_pose.yaw": syaw, "seed": seed}
    elif localisation == "slam":
        run["slam_toolbox"] = {"map_start_pose": [sx, sy, syaw]}  # the map frame is the world's
        remaps["simulator"] = {"/map": WORLD_MAP_TOPIC}
    else:
        from aiorobot.nav import landmark_map_path

        run["landmark_fixes"] = {"landmark_map": str(landmark_map_path(world.path or builtin_world_path(world.name)))}
        run["ekf_global"] = {"initial_state": [sx, sy, 0.0, 0.0, 0.0, syaw] + [0.0] * 9}
    if perception:
        run["aruco"] = {}
        run["scan_obstacles"] = {}
    if record is not None:
        from aiorobot.bag import Recorder

        # first, so it taps every topic from its first message; raw camera frames (0.9 MB each) stay out
        g.recorder = g.add(Recorder(path=record, all_topics=True, exclude=r"^/camera/image_raw$"))
    for spec in load_config(GRAPH_FILE).nodes:
        if spec.name in run:
            node = g.add(_construct(spec, run[spec.name], remaps.get(spec.name)), spec.executor)
            if spec.name in _ROLES:
                setattr(g, _ROLES[spec.name], node)
    if g.control_node is None:  # direct drive: the odometry EKF's timer is the priority loop's control timer
        g.control_node = g.ekf_local
    return g
