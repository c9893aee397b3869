"""``aiorobot demo``: the simulated mecanum robot navigating a waypoint mission, with a summary.

``--world`` is a built-in name (``warehouse``, ``box``: each has a shipped mission) or a map
YAML path (a Nav2 map, say: a path is always a path, whatever its name, and needs
``--waypoints``). Exit status: 0 when every waypoint was reached, or the run reached its
``--duration``, without collision or failed node; 1 otherwise; 2 for bad arguments or a bad
world; 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ._parser import accept_negative_number_lists, positive_seconds
from ._sim import start_pose

__all__ = ["add_arguments", "main", "run_as_default"]


def _rtf(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a real-time factor >= 0 (0 = as fast as possible), found {text!r}") from None
    if not value >= 0 or not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a real-time factor >= 0 (0 = as fast as possible), found {text!r}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "The simulated mecanum robot follows a waypoint mission: simulator (lidar, IMU, wheel odometry), AMCL "
        "localisation on the map, costmap + A* + Regulated Pure Pursuit navigation with recoveries. Prints progress "
        "and a summary against ground truth; exit status 0 when every waypoint was reached, or the run reached its "
        "--duration, without collision or failed node."
    )
    parser.add_argument("--world", default="warehouse", metavar="NAME|PATH",
                        help="built-in world (warehouse, box) or a map YAML path, such as a Nav2 map (needs --waypoints)")
    parser.add_argument("--waypoints", metavar="'x,y[,yaw];...'",
                        help="a mission of your own (default: a built-in world's shipped one)")
    parser.add_argument("--start", type=start_pose, metavar="X,Y[,YAW]",
                        help="start pose in map (m, m, rad); default: the world's start, or on a map whose start is "
                        "blocked (a Nav2 map's origin) the free cell nearest to it, with a warning")
    parser.add_argument("--duration", type=positive_seconds, metavar="SIM_SEC",
                        help="stop after this much sim time; a run stopped so, without collision, is not a failure")
    parser.add_argument("--rtf", type=_rtf, default=0.0, help="real-time factor (default 0: as fast as the machine allows)")
    parser.add_argument("--time-source", choices=("sim", "system"), default=None,
                        help="system: the simulator stamps with system time and every node runs on the system clock, "
                        "as on a robot (needs --rtf 1); sim: every node follows the simulator's /clock "
                        "(default: system at --rtf 1, else sim)")
    parser.add_argument("--seed", type=int, default=1, help="seed of every noise model (default 1)")
    parser.add_argument("--timeout", type=float, default=600.0, metavar="SIM_SEC",
                        help="give up after this much sim time, a failure (default 600)")
    parser.add_argument("--drive", choices=("serial", "direct"), default=None,
                        help="serial: the mecanum base through the simulated ESP32 firmware on a pty (SerialMotorBridge + "
                        "MecanumController), which runs on the wall clock and so needs --rtf > 0; direct: the simulator "
                        "follows /cmd_vel, which can run in lock-step (default: serial when --rtf > 0, else direct)")
    parser.add_argument("--localisation", choices=("amcl", "landmarks"), default="amcl",
                        help="amcl: the particle filter on the lidar (default); landmarks: ArUco fixes from the "
                        "perception worker into the map-frame EKF")
    parser.add_argument("--slam", action="store_true",
                        help="no map given: SLAM (aiorobot.nav.SlamNode) builds it as the robot drives the waypoints and "
                        "localises on it; the planner plans on the growing map (unknown space allowed). The summary "
                        "adds the map's agreement with the world and the loop closures; --plot draws the built map "
                        "over the true one")
    parser.add_argument("--controller", choices=("rpp", "mppi"), default="rpp",
                        help="the navigation server's path follower: rpp, Regulated Pure Pursuit (default); mppi, "
                        "nav2_mppi_controller's sampling controller")
    parser.add_argument("--no-perception", dest="perception", action="store_false",
                        help="leave out the camera, ArUco and lidar-obstacle perception (needs --localisation amcl)")
    parser.add_argument("--realtime", action="store_true",
                        help="run the priority loop's thread SCHED_FIFO (as ros2_control's controller manager does; needs "
                        "root or CAP_SYS_NICE, else a warning and the run goes on)")
    parser.add_argument("--record", type=Path, metavar="DIR",
                        help="record the run's topics (raw camera frames excluded) into a rosbag2 directory with MCAP storage")
    parser.add_argument("--json", type=Path, metavar="FILE", help="write the summary's figures as JSON")
    parser.add_argument("--plot", type=Path, metavar="FILE.png", help="draw the map with true, estimated and planned paths")
    accept_negative_number_lists(parser)


def run_as_default(duration_sec: float | None = None) -> int:
    """``aiorobot run`` without a file: the demo with its defaults (``duration_sec`` is its ``--duration``)."""
    parser = argparse.ArgumentParser(prog="aiorobot demo")
    add_arguments(parser)
    return main(parser.parse_args([] if duration_sec is None else ["--duration", repr(float(duration_sec))]))


def main(args: argparse.Namespace) -> int:
    import aiorobot
    from aiorobot.demo import DemoSetupError, mission_for, parse_waypoints, run_demo
    from aiorobot.demo._graph import ROBOT_RADIUS
    from aiorobot.demo._mission import no_mission_message
    from aiorobot.sim import World, WorldError, resolve_start

    try:
        world = World.load(args.world)
        waypoints = parse_waypoints(args.waypoints) if args.waypoints else mission_for(args.world)
        if waypoints is None:
            raise ValueError(no_mission_message(args.world))
        for i, (x, y, _) in enumerate(waypoints):
            if not world.is_free_disc(x, y, ROBOT_RADIUS):
                raise ValueError(f"waypoint {i + 1} ({x:g}, {y:g}) is outside the map or inside an obstacle of {args.world}")
        start = resolve_start(world, args.start, ROBOT_RADIUS)
        if args.slam and not args.waypoints:
            waypoints.append(start.pose)  # home: SLAM closes the loop where it began
        drive = args.drive or ("serial" if args.rtf > 0 else "direct")
        if drive == "serial" and args.rtf == 0:
            raise ValueError("--drive serial needs --rtf > 0 (the simulated firmware's pty runs on the wall clock); "
                             "use --rtf 1, or --drive direct")
        if args.time_source == "system" and args.rtf != 1:
            raise ValueError(f"--time-source system needs --rtf 1 (stamps are system time), found --rtf {args.rtf:g}; "
                             "use --time-source sim")
        if args.slam and args.localisation != "amcl":
            raise ValueError(f"--slam localises on the map it builds: leave out --localisation {args.localisation}")
        if args.localisation == "landmarks" and not args.perception:
            raise ValueError("--localisation landmarks needs perception (drop --no-perception)")
        if args.record is not None and args.record.exists():
            raise ValueError(f"--record {args.record}: exists already; choose another directory or remove it")
    except (WorldError, ValueError) as err:
        print(f"aiorobot demo: error: {err}", file=sys.stderr)
        return 2
    live = sys.stderr.isatty()

    def progress(line: str) -> None:
        if live:
            sys.stderr.write("\r" + line.ljust(100)[:100])
        else:
            sys.stderr.write(line + "\n")
        sys.stderr.flush()

    time_source = args.time_source or ("system" if args.rtf == 1 else "sim")
    localisation = "slam" if args.slam else args.localisation
    if start.warning is not None:
        print(f"aiorobot demo: warning: {start.warning}", file=sys.stderr)
    print(f"aiorobot demo: {args.world}, {len(waypoints)} waypoints, mecanum robot ({drive} drive), "
          f"{localisation} localisation, {args.controller} controller, seed {args.seed}, "
          f"{'as fast as possible' if args.rtf == 0 else f'real-time factor {args.rtf:g}'}, {time_source} time"
          f"{f', {args.duration:g} sim s' if args.duration else ''} (Ctrl-C stops)", file=sys.stderr)
    try:
        summary = aiorobot.run(run_demo(args.world, waypoints, rtf=args.rtf, seed=args.seed, drive=drive,
                                        localisation=localisation, perception=args.perception,
                                        record=str(args.record) if args.record else None,
                                        timeout_sim_sec=args.timeout, progress=progress,
                                        time_source=args.time_source, realtime=args.realtime,
                                        start=start.pose, duration_sim_sec=args.duration, controller=args.controller))
    except DemoSetupError as err:  # a node refused what the checks above let through (nothing started)
        print(f"aiorobot demo: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\naiorobot demo: interrupted", file=sys.stderr)
        return 130
    if live:
        sys.stderr.write("\n")
    _print_summary(summary)
    if args.json:
        args.json.write_text(json.dumps(summary.figures(), indent=2) + "\n")
    if args.plot:
        from aiorobot.demo._plot import plot_demo

        plot_demo(summary, args.world, waypoints, args.plot)
        print(f"plot written to {args.plot}")
    return 0 if summary.passed else 1


def _print_summary(s: object) -> None:
    from rich.console import Console
    from rich.table import Table

    f = s.figures()  # type: ignore[attr-defined]
    outcome = (f"stopped after --duration: {f['waypoints_reached']} / {f['waypoints_total']} waypoints"
               if f["stopped_by_duration"] else f["status"])
    world = Path(f["world"]).name  # a map path by its file name
    title = f"aiorobot demo — {world}, {f['drive']} drive, {f['localisation']}, {f['controller']}: {outcome}"
    table = Table()
    table.add_column("figure")
    table.add_column("value", justify="right")
    rows = [
        ("waypoints reached", f"{f['waypoints_reached']} / {f['waypoints_total']}" + (f" (missed {f['missed']})" if f["missed"] else "")),
        ("collisions", str(f["collisions"])),
        ("localisation RMSE / max vs ground truth", f"{f['localisation_rmse_m'] * 100:.1f} cm / {f['localisation_max_m'] * 100:.1f} cm"),
        ("path driven", f"{f['path_length_m']:.1f} m"),
        ("recoveries", str(f["recoveries"])),
        ("sim time / wall time", f"{f['sim_sec']:.1f} s / {f['wall_sec']:.1f} s ({f['real_time_factor']:.1f}x real time, "
         f"{f['time_source']} time)"),
        ("control period p50 / p99 / max", _control_text(f)),
        *([("  a bare Python thread, same run: p99 / max",
            f"{f['baseline_period_p99_ms']:.2f} / {f['baseline_period_max_ms']:.2f} ms")]
          if f["baseline_period_p99_ms"] is not None else []),
        ("perception (ArUco worker)", "off" if f["perception_fps"] is None else
         f"{f['perception_fps']:.1f} frames/s wall, {f['perception_frames']} frames, {f['perception_dropped']} dropped"),
        ("CPU: main process / perception workers", f"{f['cpu_pct']:.0f} % / {f['workers_cpu_pct']:.0f} % of a core"),
    ]
    if f["localisation"] == "landmarks":
        rows.insert(3, ("landmark fixes (with heading)", f"{f['landmark_fixes']} ({f.get('landmark_heading_fixes', 0)})"))
    if f["localisation"] == "slam":
        rows[2] = ("SLAM trajectory RMSE / max vs ground truth", rows[2][1])
        rows.insert(3, ("SLAM graph nodes / loop closures", f"{f['slam_nodes']} / {f['slam_loop_closures']}"))
        if f["slam_map_precision"] is not None:
            rows.insert(4, ("map vs world: occupied within 0.1 m of a wall / walls seen marked",
                            f"{f['slam_map_precision'] * 100:.1f} % / {f['slam_map_recall'] * 100:.1f} %"))
    if f["failures"]:
        rows.append(("node failures", "; ".join(f["failures"])))
    if f["record"]:
        rows.append(("recorded to", f["record"]))
    for name, value in rows:
        table.add_row(name, value)
    console = Console(width=max(110, len(title)))
    console.print(title, markup=False, highlight=False)  # its own line: a table title wraps at the table's width
    console.print(table)


def _control_text(f: dict) -> str:
    if f["control_period_p99_ms"] is None:
        return "n/a at --rtf 0 (lock-step); run with --rtf 1"
    return (f"{f['control_period_p50_ms']:.2f} / {f['control_period_p99_ms']:.2f} / {f['control_period_max_ms']:.2f} ms "
            f"(nominal {f['control_period_nominal_ms']:.0f} ms, {f['control_loop'].split(' on ')[0]}"
            f"{', SCHED_FIFO' if f['realtime'] else ''})")
