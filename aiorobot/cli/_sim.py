"""``aiorobot sim [--world box] [--start X,Y,YAW] [--robot mecanum] [--duration SEC] [--rtf R] [--seed N]``.

A config-free start of ``aiorobot.sim:Simulator`` on a sim-time runtime: it prints a
status line while it runs and a summary at the end. ``--duration`` counts sim seconds.
``--world`` is a built-in name (``box``, ``warehouse``) or a map_server YAML path (a Nav2
map: without ``--start`` the robot starts on the free cell nearest the origin, with a warning).
"""

from __future__ import annotations

import argparse
import math
import sys

from ._parser import accept_negative_number_lists, positive_seconds

__all__ = ["add_arguments", "main"]

EXIT_BAD_INPUT = 2


def _non_negative_factor(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a real-time factor such as 1 or 0 (as fast as possible), found {text!r}") from None
    if not math.isfinite(value) or value < 0.0:
        raise argparse.ArgumentTypeError(f"expected a real-time factor >= 0 (0: as fast as possible), found {text!r}")
    return value


def _seed(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer seed, found {text!r}") from None


def start_pose(text: str) -> tuple[float, float, float]:
    """argparse ``type=`` for ``--start X,Y[,YAW]``."""
    from aiorobot.sim import parse_start

    try:
        return parse_start(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.description = (
        "Run the simulated robot (lidar, IMU, wheel odometry, camera, ground truth) in a world "
        "without a config file. Drive it by publishing geometry_msgs/Twist on /cmd_vel."
    )
    parser.add_argument("--world", default="box", help="built-in world (box, warehouse) or a map YAML path (default: box)")
    parser.add_argument("--start", type=start_pose, metavar="X,Y[,YAW]",
                        help="start pose in map (m, m, rad); default: the world's start, or on a map whose start is "
                        "blocked (a Nav2 map's origin) the free cell nearest to it, with a warning")
    parser.add_argument("--robot", default="mecanum", choices=("mecanum", "diff"), help="drive (default: mecanum)")
    parser.add_argument("--duration", type=positive_seconds, metavar="SEC", help="stop after this many sim seconds")
    parser.add_argument("--rtf", type=_non_negative_factor, default=1.0, metavar="R",
                        help="real-time factor; 0 runs as fast as possible (default: 1)")
    parser.add_argument("--seed", type=_seed, default=1, help="seed of every noise model (default: 1)")
    parser.add_argument("--status-period", type=positive_seconds, default=1.0, metavar="SEC",
                        help="wall seconds between status lines (default: 1)")
    accept_negative_number_lists(parser)


def main(args: argparse.Namespace) -> int:
    import aiorobot
    from aiorobot.sim import Simulator, WorldError

    parameters = {"world": args.world, "robot": args.robot, "seed": args.seed, "real_time_factor": args.rtf,
                  "duration_sec": args.duration or 0.0}
    if args.start is not None:
        parameters["start"] = list(args.start)
    try:  # a start it has to move is a warning through the node loggers' default handler (stderr)
        simulator = Simulator(parameter_overrides=parameters)
    except (WorldError, ValueError, aiorobot.InvalidParameterValueError) as err:
        print(f"aiorobot sim: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    from ._logging import configure_logging

    configure_logging("info")
    try:
        return aiorobot.run(_serve(simulator, args.status_period))
    except KeyboardInterrupt:
        return 130


async def _serve(simulator: object, status_period_sec: float) -> int:
    from aiorobot import Runtime

    from ._status import StatusDisplay

    async with Runtime(use_sim_time=True) as rt:
        rt.add_node(simulator)  # type: ignore[arg-type]
        async with StatusDisplay([simulator], period_sec=status_period_sec, on_stream_closed=rt.shutdown):
            await rt.spin()
    return 0
