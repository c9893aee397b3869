"""The demo mission: build the graph, send the waypoints, watch, summarise."""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

__all__ = ["MISSIONS", "DemoSummary", "parse_waypoints", "run_demo"]

_PI = math.pi
#: The shipped missions: (x, y, yaw) waypoints per built-in world.
MISSIONS: dict[str, list[tuple[float, float, float]]] = {
    "warehouse": [
        (-5.0, -5.0, 0.0),          # across the south-west room
        (-1.5, -5.0, _PI / 2),      # through the door into the hall
        (4.75, -1.75, _PI / 2),     # into the gap between the shelf rows
        (4.75, 5.25, _PI),          # up the aisle to the north wall
        (-1.5, 5.0, _PI),           # back west along the north side
        (-6.5, 2.5, -_PI / 2),      # through the north door into the north-west room
        (-6.5, -2.0, -_PI / 2),     # through the inner door, home to the south-west room
    ],
    "box": [(2.0, 0.0, _PI / 2), (2.0, 2.0, _PI), (-2.0, 2.0, -_PI / 2), (-2.0, -2.0, 0.0), (0.0, 0.0, 0.0)],
}


def parse_waypoints(text: str) -> list[tuple[float, float, float]]:
    """``"x,y[,yaw];x,y..."`` -> waypoints; ValueError naming the bad entry."""
    out = []
    for i, item in enumerate(p for p in text.split(";") if p.strip()):
        parts = [s.strip() for s in item.split(",")]
        try:
            values = [float(v) for v in parts]
        except ValueError:
            raise ValueError(f"waypoint {i + 1}: expected x,y or x,y,yaw numbers, found {item.strip()!r}") from None
        if len(values) not in (2, 3) or not all(math.isfinite(v) for v in values):
            raise ValueError(f"waypoint {i + 1}: expected x,y or x,y,yaw numbers, found {item.strip()!r}")
        out.append((values[0], values[1], values[2] if len(values) == 3 else 0.0))
    if not out:
        raise ValueError("expected at least one waypoint, such as '1,0;1,1,1.57'")
    return out


@dataclass
class DemoSummary:
    """The demo's figures (``--json`` writes these keys)."""

    world: str
    waypoints_reached: int = 0
    waypoints_total: int = 0
    collisions: int = 0
    localisation_rmse_m: float = float("nan")
    localisation_max_m: float = float("nan")
    path_length_m: float = 0.0
    recoveries: int = 0
    sim_sec: float = 0.0
    wall_sec: float = 0.0
    real_time_factor: float = 0.0
    control_period_p99_ms: float | None = None
    control_period_max_ms: float | None = None
    perception_fps: float | None = None
    cpu_pct: float = 0.0
    status: str = "UNKNOWN"
    missed: list[int] = field(default_factory=list)
    truth: list[tuple[float, float]] = field(default_factory=list, repr=False)
    estimate: list[tuple[float, float]] = field(default_factory=list, repr=False)
    plans: list[list[tuple[float, float]]] = field(default_factory=list, repr=False)

    @property
    def succeeded(self) -> bool:
        return self.waypoints_total > 0 and self.waypoints_reached == self.waypoints_total and self.collisions == 0

    def figures(self) -> dict[str, Any]:
        d = asdict(self)
        for k in ("truth", "estimate", "plans"):
            d.pop(k)
        return d


class _Monitor:
    """Collects ground truth, the localisation estimate and plans while the mission runs."""

    def __init__(self, node: Any, summary: DemoSummary) -> None:
        from aiorobot.msgs.nav_msgs import Odometry, Path
        from aiorobot.tf import Buffer, TransformListener

        self.node = node
        self.summary = summary
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, node)
        self.truth_xy: tuple[float, float] | None = None
        self.errors: list[float] = []
        node.create_subscription(Odometry, "/ground_truth/odom", self._on_truth, 10)
        node.create_subscription(Path, "/plan", self._on_plan, 10)
        node.create_timer(0.2, self._sample)
        self._last_xy: tuple[float, float] | None = None

    def _on_truth(self, msg: Any) -> None:
        xy = (float(msg.pose.pose.position.x), float(msg.pose.pose.position.y))
        if self._last_xy is not None:
            self.summary.path_length_m += math.hypot(xy[0] - self._last_xy[0], xy[1] - self._last_xy[1])
        self._last_xy = self.truth_xy = xy

    def _on_plan(self, msg: Any) -> None:
        plan = [(float(p.pose.position.x), float(p.pose.position.y)) for p in msg.poses[::5]]
        if not self.summary.plans or plan[-1:] != self.summary.plans[-1][-1:]:
            self.summary.plans.append(plan)

    def _sample(self) -> None:
        from aiorobot import Time
        from aiorobot.tf import TransformException

        if self.truth_xy is None:
            return
        try:
            t = self.buffer.lookup_transform("map", "base_link", Time())
        except TransformException:
            return
        est = (float(t.transform.translation.x), float(t.transform.translation.y))
        self.errors.append(math.hypot(est[0] - self.truth_xy[0], est[1] - self.truth_xy[1]))
        self.summary.truth.append(self.truth_xy)
        self.summary.estimate.append(est)

    def finish(self) -> None:
        if self.errors:
            e = np.asarray(self.errors)
            self.summary.localisation_rmse_m = float(np.sqrt(np.mean(e * e)))
            self.summary.localisation_max_m = float(e.max())


async def run_demo(
    world: str = "warehouse",
    waypoints: list[tuple[float, float, float]] | None = None,
    *,
    rtf: float = 0.0,
    seed: int = 1,
    timeout_sim_sec: float = 600.0,
    progress: Callable[[str], None] | None = None,
) -> DemoSummary:
    """Run the mission; return its summary. ``rtf = 0`` runs as fast as the machine allows."""
    from aiorobot import Node, Runtime
    from aiorobot.nav import AmclNode, NavigationServer, Navigator, TaskResult, pose_stamped
    from aiorobot.sim import Simulator, World

    loaded = World.load(world)
    if waypoints is None:
        if loaded.name not in MISSIONS:
            raise ValueError(f"world {world!r} has no shipped mission; give one with --waypoints 'x,y[,yaw];...'")
        waypoints = MISSIONS[loaded.name]
    summary = DemoSummary(world=loaded.name, waypoints_total=len(waypoints), real_time_factor=rtf)
    sx, sy, syaw = loaded.start
    wall0, cpu0 = time.perf_counter(), time.process_time()
    # The simulator compiles its Numba kernels when it starts: seconds on the main loop, on purpose.
    async with Runtime(use_sim_time=True, stall_threshold=10.0) as rt:
        sim = rt.add_node(Simulator(parameter_overrides={
            "world": world, "robot": "mecanum", "seed": seed, "real_time_factor": rtf,
            "publish_odom_tf": True, "camera_rate": 0.0,
        }))
        rt.add_node(AmclNode(parameter_overrides={
            "robot_model_type": "omnidirectional", "set_initial_pose": True,
            "initial_pose.x": sx, "initial_pose.y": sy, "initial_pose.yaw": syaw,
            "update_min_d": 0.1, "update_min_a": 0.1, "min_particles": 300, "max_particles": 1000, "seed": seed,
            "alpha1": 0.05, "alpha2": 0.05, "alpha3": 0.05, "alpha4": 0.05, "alpha5": 0.05, "sigma_hit": 0.1,
        }))
        server = rt.add_node(NavigationServer(parameter_overrides={"desired_linear_vel": 0.5, "stop_on_failure": False,
                                                                   "movement_time_allowance": 15.0}))
        nav = rt.add_node(Navigator())
        monitor = _Monitor(rt.add_node(Node("demo_monitor")), summary)
        poses = [pose_stamped(x, y, yaw) for x, y, yaw in waypoints]
        started = asyncio.ensure_future(nav.follow_waypoints(poses))
        last = 0.0
        try:
            while not (started.done() and nav.is_task_complete()):
                await asyncio.sleep(0.05)
                now = rt.now().nanoseconds / 1e9
                if now > timeout_sim_sec:
                    await nav.cancel_task()
                    break
                if progress is not None and time.perf_counter() - last > 0.5:
                    last = time.perf_counter()
                    fb = nav.get_feedback()
                    err = monitor.errors[-1] if monitor.errors else float("nan")
                    wp = int(fb.current_waypoint) + 1 if fb is not None else 0
                    progress(f"sim {now:6.1f} s  waypoint {wp}/{len(waypoints)}  localisation error {err * 100:5.1f} cm  "
                             f"recoveries {server.recoveries}  collisions {sim.body.collisions}")
            if started.done() and not started.result():
                summary.status = "REJECTED"
        finally:
            monitor.finish()
            result = nav.result
            summary.missed = [int(m.index) for m in result.missed_waypoints] if result is not None else []
            status = nav.get_result()
            summary.status = status.name if summary.status != "REJECTED" else summary.status
            if status is TaskResult.SUCCEEDED:
                summary.waypoints_reached = len(waypoints) - len(summary.missed)
            summary.collisions = sim.body.collisions
            summary.recoveries = server.recoveries
            summary.sim_sec = rt.now().nanoseconds / 1e9
    summary.wall_sec = time.perf_counter() - wall0
    summary.cpu_pct = 100.0 * (time.process_time() - cpu0) / max(summary.wall_sec, 1e-9)
    summary.real_time_factor = summary.sim_sec / max(summary.wall_sec, 1e-9)
    return summary
