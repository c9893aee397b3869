"""The demo mission: build the graph, send the waypoints, watch, summarise."""

from __future__ import annotations

import asyncio
import gc
import logging
import math
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

__all__ = ["MISSIONS", "DemoSetupError", "DemoSummary", "mission_for", "parse_waypoints", "run_demo"]

_PI = math.pi
#: how long the demo waits for its perception workers to come up before starting the simulator
PERCEPTION_START_TIMEOUT_SEC = 60.0
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


class DemoSetupError(ValueError):
    """The demo cannot start with what it was given (world, start, waypoints, options); nothing was started."""


def mission_for(world: str) -> list[tuple[float, float, float]] | None:
    """The shipped mission of a built-in world named by its bare name; None for anything else.

    A path is a path: a map file that happens to be called ``warehouse.yaml`` (Nav2 ships one)
    is not the built-in warehouse and has no mission.
    """
    from aiorobot.sim import BUILTIN_WORLDS

    return list(MISSIONS[world]) if world in BUILTIN_WORLDS and world in MISSIONS else None


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

    #: the built-in world's name or the map YAML's path, as given
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
    drive: str = "direct"
    localisation: str = "amcl"
    #: the navigation server's path follower: ``rpp`` or ``mppi``
    controller: str = "rpp"
    #: ``sim`` (the simulator's /clock) or ``system`` (system-time stamps, at real-time factor 1)
    time_source: str = "sim"
    #: the priority loop's control timer whose periods are measured (wall clock x rtf; None in lock-step)
    control_loop: str = ""
    control_period_nominal_ms: float | None = None
    control_period_p50_ms: float | None = None
    control_period_p99_ms: float | None = None
    control_period_max_ms: float | None = None
    control_periods: int = 0
    #: the same periods of a bare Python thread sleeping to the same deadlines in the same run: what the machine,
    #: its other load and the GIL give any thread of this process (the baseline the control figures compare to)
    baseline_period_p99_ms: float | None = None
    baseline_period_max_ms: float | None = None
    #: the priority loop's thread runs SCHED_FIFO (``--realtime``, where the OS permits it)
    realtime: bool = False
    #: ArUco frames processed by the worker per wall second, over the whole run
    perception_fps: float | None = None
    perception_frames: int = 0
    perception_dropped: int = 0
    landmark_fixes: int = 0
    #: of those, the fixes from two or more markers in one image, which measured the heading too
    landmark_heading_fixes: int = 0
    #: ``slam``: graph nodes and loop closures, and the built map against the world (see map_agreement)
    slam_nodes: int | None = None
    slam_loop_closures: int | None = None
    slam_map_precision: float | None = None
    slam_map_recall: float | None = None
    #: CPU of the main process (its loops and threads) and of the perception workers, % of one core
    cpu_pct: float = 0.0
    workers_cpu_pct: float = 0.0
    record: str | None = None
    status: str = "UNKNOWN"
    #: where the robot started (x, y, yaw in map)
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    #: the sim-time bound of the run (``--duration``), and whether the run ended on it: not a failure
    duration_sec: float | None = None
    stopped_by_duration: bool = False
    #: nodes that failed to start or whose callbacks raised ("/fqn: entity raised N times")
    failures: list[str] = field(default_factory=list)
    missed: list[int] = field(default_factory=list)
    truth: list[tuple[float, float]] = field(default_factory=list, repr=False)
    estimate: list[tuple[float, float]] = field(default_factory=list, repr=False)
    plans: list[list[tuple[float, float]]] = field(default_factory=list, repr=False)
    #: ``slam``: the map SLAM built (an OccupancyMap), for ``--plot``
    slam_map: Any = field(default=None, repr=False)

    @property
    def succeeded(self) -> bool:
        """Every waypoint reached without collision."""
        return self.waypoints_total > 0 and self.waypoints_reached == self.waypoints_total and self.collisions == 0

    @property
    def passed(self) -> bool:
        """What the exit status says: the mission succeeded, or the run reached its ``--duration`` first;
        either way without collision and without a failed node."""
        return (self.succeeded or self.stopped_by_duration) and self.collisions == 0 and not self.failures

    def figures(self) -> dict[str, Any]:
        d = asdict(self)
        for k in ("truth", "estimate", "plans", "slam_map"):
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

    def distance_left(self, waypoints: list[tuple[float, float, float]], index: int) -> float:
        """Along the latest plan to the current waypoint, then straight between the remaining ones."""
        if self.truth_xy is None:
            return float("nan")
        x, y = self.truth_xy
        plan = self.summary.plans[-1] if self.summary.plans else []
        wx, wy = waypoints[index][:2]
        if plan and math.hypot(plan[-1][0] - wx, plan[-1][1] - wy) < 0.3:
            pts = np.asarray(plan)
            near = int(np.argmin(np.hypot(pts[:, 0] - x, pts[:, 1] - y)))
            rest = pts[near:]
            left = math.hypot(rest[0][0] - x, rest[0][1] - y) + float(np.hypot(*np.diff(rest, axis=0).T).sum())
        else:
            left = math.hypot(wx - x, wy - y)
        for (ax, ay, _), (bx, by, _) in zip(waypoints[index:], waypoints[index + 1:]):
            left += math.hypot(bx - ax, by - ay)
        return left

    def finish(self) -> None:
        if self.errors:
            e = np.asarray(self.errors)
            self.summary.localisation_rmse_m = float(np.sqrt(np.mean(e * e)))
            self.summary.localisation_max_m = float(e.max())


class _SleepBaseline:
    """A bare Python thread waking at absolute deadlines of ``period_sec`` (wall), recording its wake times.

    Nothing of aiorobot runs in it: its lateness is the machine's scheduling and the GIL's, measured
    beside the control timer in the same run (a baseline, as every figure here has one).
    """

    def __init__(self, period_sec: float) -> None:
        self.period_sec = period_sec
        self.stamps: list[int] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._main, name="aiorobot-demo-baseline", daemon=True)
        self._thread.start()

    def _main(self) -> None:
        period_ns = int(self.period_sec * 1e9)
        deadline = time.perf_counter_ns() + period_ns
        while not self._stop.is_set():
            delay = deadline - time.perf_counter_ns()
            if delay > 0:
                time.sleep(delay / 1e9)
            self.stamps.append(time.perf_counter_ns())
            deadline += period_ns

    def stop(self) -> np.ndarray:
        """Stop; the periods between wakes, in ms."""
        self._stop.set()
        self._thread.join()
        return np.diff(np.asarray(self.stamps, dtype=np.int64)) / 1e6


class _PeriodProbe:
    """Wall-clock start times of one timer's callbacks (on whichever loop the timer runs)."""

    def __init__(self, timer: Any) -> None:
        self.stamps: list[int] = []
        self.period_sec = timer.timer_period_ns / 1e9
        inner = timer.callback
        stamps = self.stamps

        def probed(*args: Any, **kwargs: Any) -> Any:
            stamps.append(time.perf_counter_ns())
            return inner(*args, **kwargs)

        timer.callback = probed

    def periods_ms(self, since: int = 0) -> np.ndarray:
        return np.diff(np.asarray(self.stamps[since:], dtype=np.int64)) / 1e6


def _children_cpu_sec() -> float:
    """CPU seconds of this process's live descendants (the perception workers, a forkserver), from /proc."""
    import os

    tick = os.sysconf("SC_CLK_TCK")
    parent: dict[str, str] = {}
    cpu: dict[str, float] = {}
    try:
        pids = [d for d in os.listdir("/proc") if d.isdigit()]
    except OSError:
        return 0.0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parent[pid] = fields[1]
        cpu[pid] = (int(fields[11]) + int(fields[12])) / tick  # utime + stime
    me = str(os.getpid())
    total = 0.0
    for pid, seconds in cpu.items():
        p, hops = parent.get(pid), 0
        while p is not None and p != me and p != "0" and hops < 64:
            p, hops = parent.get(p), hops + 1
        if p == me:
            total += seconds
    return total


async def run_demo(
    world: str = "warehouse",
    waypoints: list[tuple[float, float, float]] | None = None,
    *,
    rtf: float = 0.0,
    seed: int = 1,
    timeout_sim_sec: float = 600.0,
    progress: Callable[[str], None] | None = None,
    drive: str | None = None,
    localisation: str = "amcl",
    perception: bool = True,
    record: str | None = None,
    time_source: str | None = None,
    realtime: bool = False,
    start: tuple[float, float, float] | None = None,
    duration_sim_sec: float | None = None,
    controller: str = "rpp",
) -> DemoSummary:
    """Run the mission; return its summary. ``rtf = 0`` runs as fast as the machine allows.

    ``time_source`` is the simulator's: ``"system"`` (needs ``rtf = 1``; the runtime then runs
    on the system clock, as on a robot) or ``"sim"`` (every node follows the simulator's
    ``/clock``); None picks system at ``rtf == 1`` and sim otherwise. Timeout, ``sim_sec`` and
    the progress line count the simulator's own elapsed time either way.

    ``drive`` is ``"serial"`` (the simulated ESP32 firmware on a pty; needs ``rtf > 0``) or
    ``"direct"`` (the simulator follows /cmd_vel); None picks serial when ``rtf > 0``.
    ``localisation`` is ``"amcl"`` or ``"landmarks"`` (ArUco fixes into the map-frame EKF).
    ``controller`` is the navigation server's path follower, ``"rpp"`` or ``"mppi"``.
    ``record`` is a directory for a rosbag2/MCAP bag of the run's topics (raw images excluded).
    ``realtime`` runs the priority loop's thread SCHED_FIFO where the OS permits it (as ros2_control's
    controller manager does); otherwise a warning, and the run goes on.

    ``world`` is a built-in name or a map YAML path; only a built-in name has a shipped mission
    (:func:`mission_for`), so a path needs ``waypoints``. ``start`` (x, y, yaw) is where the robot
    starts; None takes the world's start, or the free cell nearest it with a logged warning (a
    Nav2 map's origin is often blocked). ``duration_sim_sec`` ends the run after that much sim
    time: ``stopped_by_duration``, which is not a failure; ``timeout_sim_sec`` ends it as one.
    """
    from aiorobot import Node, Runtime
    from aiorobot.nav import Navigator, TaskResult, pose_stamped
    from aiorobot.sim import World, resolve_start

    from ._graph import ROBOT_RADIUS, build_graph

    world = str(world)
    if drive is None:
        drive = "serial" if rtf > 0 else "direct"
    try:  # everything that can refuse the input, before anything starts
        loaded = World.load(world)
        choice = resolve_start(loaded, start, ROBOT_RADIUS)
        if waypoints is None:
            waypoints = mission_for(world)
            if waypoints is None:
                raise ValueError(no_mission_message(world))
            if localisation == "slam":
                waypoints.append(choice.pose)  # home: SLAM closes the loop where it began
        graph = build_graph(loaded, rtf=rtf, seed=seed, drive=drive, localisation=localisation, perception=perception,
                            record=record, time_source=time_source, start=choice.pose, controller=controller)
    except ValueError as err:  # WorldError and the nodes' parameter errors among them
        raise DemoSetupError(str(err)) from err
    if choice.warning is not None:
        logging.getLogger("aiorobot.demo").warning(choice.warning)
    summary = DemoSummary(world=world, waypoints_total=len(waypoints), real_time_factor=rtf, drive=drive,
                          localisation=localisation, controller=controller, time_source=graph.time_source, start=choice.pose,
                          duration_sec=duration_sim_sec)
    # What exists now (imported modules, Numba's and the simulator's start-up objects: most of the heap) is
    # left out of the cyclic collector's full passes: such a pass stops every thread, the priority loop's
    # included, for as long as it walks the heap (66 ms seen in the warehouse at --rtf 1; ~1 ms after this).
    gc.collect()
    gc.freeze()
    wall0, cpu0, child0 = time.perf_counter(), time.process_time(), _children_cpu_sec()
    probe = _PeriodProbe(graph.control_node.timers[0])
    summary.control_loop = f"{graph.control_node.get_name()} {1.0 / probe.period_sec:g} Hz on the priority loop"
    sim, server = graph.simulator, graph.server
    baseline: _SleepBaseline | None = None
    async with Runtime(use_sim_time=graph.time_source == "sim", stall_threshold=10.0, priority_realtime=realtime) as rt:
        # the simulator last, once the perception workers are up: at --rtf 0 a short mission can be over
        # before a loaded machine has started them, and every frame until then is dropped
        rt.add_nodes([(node, executor) for node, executor in graph.nodes if node is not sim])
        if graph.aruco is not None:
            try:
                async with asyncio.timeout(PERCEPTION_START_TIMEOUT_SEC):
                    await graph.aruco.pipeline.wait_ready()
            except TimeoutError:
                logging.getLogger("aiorobot.demo").warning(
                    f"the perception workers did not come up within {PERCEPTION_START_TIMEOUT_SEC:g} s; "
                    "starting without them")
        rt.add_nodes([(node, executor) for node, executor in graph.nodes if node is sim])
        nav = rt.add_node(Navigator())
        monitor = _Monitor(rt.add_node(Node("demo_monitor")), summary)
        poses = [pose_stamped(x, y, yaw) for x, y, yaw in waypoints]
        started = asyncio.ensure_future(nav.follow_waypoints(poses))
        probe_from = len(probe.stamps)
        summary.realtime = rt.priority_loop is not None and "SCHED_FIFO" in rt.priority_loop.applied
        if rtf > 0:
            baseline = _SleepBaseline(probe.period_sec / rtf)
        last, last_frames, child_cpu = 0.0, 0, 0.0
        try:
            while not (started.done() and nav.is_task_complete()):
                await asyncio.sleep(0.05)
                now = sim.statistics().sim_sec  # the simulator's elapsed time, on either time source
                if duration_sim_sec is not None and now >= duration_sim_sec and duration_sim_sec <= timeout_sim_sec:
                    summary.stopped_by_duration = True
                    await nav.cancel_task()
                    break
                if now > timeout_sim_sec:
                    await nav.cancel_task()
                    break
                if time.perf_counter() - last > 0.5:
                    child_cpu = max(child_cpu, _children_cpu_sec() - child0)  # workers are gone after shutdown
                    frames = graph.aruco.pipeline.statistics().processed if graph.aruco is not None else 0
                    fps = (frames - last_frames) / max(time.perf_counter() - last, 1e-9) if last else float("nan")
                    last, last_frames = time.perf_counter(), frames
                    if progress is not None:
                        progress(_progress_line(now, nav, monitor, waypoints, probe, rtf, fps, sim, server))
            if started.done() and not started.result():
                summary.status = "REJECTED"
        finally:
            monitor.finish()
            child_cpu = max(child_cpu, _children_cpu_sec() - child0)
            result = nav.result
            summary.missed = [int(m.index) for m in result.missed_waypoints] if result is not None else []
            status = nav.get_result()
            summary.status = status.name if summary.status != "REJECTED" else summary.status
            if status is TaskResult.SUCCEEDED:
                summary.waypoints_reached = len(waypoints) - len(summary.missed)
            elif nav.get_feedback() is not None:  # stopped on the way: the waypoints before the current one
                current = int(nav.get_feedback().current_waypoint)
                summary.waypoints_reached = current - sum(1 for m in summary.missed if m < current)
            sim_stats = sim.statistics()
            summary.collisions = sim_stats.collisions
            summary.recoveries = server.statistics().recoveries
            summary.sim_sec = sim_stats.sim_sec
            wall = time.perf_counter() - wall0
            if graph.aruco is not None:
                stats = graph.aruco.pipeline.statistics()
                summary.perception_fps = stats.processed / max(wall, 1e-9)
                summary.perception_frames = stats.processed
                summary.perception_dropped = stats.dropped_queue
            if graph.landmark_fixes is not None:
                summary.landmark_fixes = graph.landmark_fixes.fixes
                summary.landmark_heading_fixes = graph.landmark_fixes.heading_fixes
            if graph.slam is not None:
                _slam_figures(summary, graph.slam, loaded)
            periods = probe.periods_ms(probe_from)
            if rtf > 0 and periods.size:
                # sim-time periods: the wall period scaled by the real-time factor
                sim_periods = periods * rtf
                summary.control_period_nominal_ms = probe.period_sec * 1e3
                summary.control_period_p50_ms = float(np.percentile(sim_periods, 50))
                summary.control_period_p99_ms = float(np.percentile(sim_periods, 99))
                summary.control_period_max_ms = float(sim_periods.max())
                summary.control_periods = int(sim_periods.size)
            if baseline is not None:
                base = baseline.stop() * rtf
                if base.size:
                    summary.baseline_period_p99_ms = float(np.percentile(base, 99))
                    summary.baseline_period_max_ms = float(base.max())
    gc.unfreeze()
    summary.failures = _failures(rt)
    if summary.stopped_by_duration:
        summary.status = "STOPPED"
    summary.wall_sec = time.perf_counter() - wall0
    summary.cpu_pct = 100.0 * (time.process_time() - cpu0) / max(summary.wall_sec, 1e-9)
    summary.workers_cpu_pct = 100.0 * child_cpu / max(summary.wall_sec, 1e-9)
    summary.real_time_factor = summary.sim_sec / max(summary.wall_sec, 1e-9)
    if graph.recorder is not None:
        summary.record = graph.recorder.path
    return summary


def _slam_figures(summary: DemoSummary, node: Any, world: Any) -> None:
    """The SLAM run's figures: nodes, loop closures, and the built map against the world along the route."""
    from ._slam_figures import map_agreement

    stats = node.slam.statistics()
    summary.slam_nodes, summary.slam_loop_closures = stats.nodes, stats.loop_closures
    if stats.nodes:
        summary.slam_map = node.slam.occupancy_map(node.map_frame)
        route = np.asarray(summary.truth[::5], dtype=np.float64).reshape(-1, 2)  # 1 Hz of the 5 Hz samples
        agreement = map_agreement(summary.slam_map, world, route)
        summary.slam_map_precision, summary.slam_map_recall = agreement.precision, agreement.recall


def no_mission_message(world: str) -> str:
    """The one line for a world without a shipped mission and no waypoints given."""
    from aiorobot.sim import BUILTIN_WORLDS

    return (f"world {world!r} has no shipped mission (only the built-in worlds {', '.join(BUILTIN_WORLDS)}, named "
            "without a path, have one); give the waypoints with --waypoints 'x,y[,yaw];...'")


def _failures(rt: Any) -> list[str]:
    """One line per node that failed to start or whose callbacks raised (as ``aiorobot run`` reports them)."""
    stats = rt.statistics()
    lines = [f"{fqn}: failed to start (on_start raised)" for fqn in stats["failed_starts"]]
    for (fqn, entity), count in sorted(stats["failures"].items()):
        if entity == "on_start" and fqn in stats["failed_starts"]:
            continue
        lines.append(f"{fqn}: {entity} raised {count} time{'s' if count != 1 else ''}")
    return lines


def _progress_line(now: float, nav: Any, monitor: _Monitor, waypoints: list[Any], probe: _PeriodProbe, rtf: float,
                   fps: float, sim: Any, server: Any) -> str:
    fb = nav.get_feedback()
    err = monitor.errors[-1] if monitor.errors else float("nan")
    wp = min(int(fb.current_waypoint) + 1, len(waypoints)) if fb is not None else 0
    left = monitor.distance_left(waypoints, wp - 1) if wp else float("nan")
    if rtf > 0:
        recent = probe.periods_ms(max(len(probe.stamps) - 100, 0)) * rtf
        jitter = f"{np.abs(recent - probe.period_sec * 1e3).max():4.1f} ms" if recent.size else "  -  "
    else:
        jitter = "n/a (lock-step)"
    fps_text = f"{fps:4.1f}" if math.isfinite(fps) else "  - "
    return (f"sim {now:6.1f} s  waypoint {wp}/{len(waypoints)}  {left:5.1f} m left  loc. error {err * 100:5.1f} cm  "
            f"jitter {jitter}  perception {fps_text} fps  recoveries {server.statistics().recoveries}  "
            f"collisions {sim.statistics().collisions}")
