"""``aiorobot router``: a zenoh router, what ``ros2 run rmw_zenoh_cpp rmw_zenohd`` is for ROS 2."""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--listen", action="append", metavar="ENDPOINT",
        help="endpoint to listen on (default tcp/127.0.0.1:7447: loopback only; tcp/[::]:7447 as rmw_zenohd)",
    )
    parser.add_argument("--config", metavar="FILE", help="a zenoh JSON5 router config (TLS, access control, ...)")


def main(args: argparse.Namespace) -> int:
    import zenoh

    try:
        cfg = zenoh.Config.from_file(args.config) if args.config else zenoh.Config()
    except Exception as err:
        print(f"aiorobot router: error: cannot load zenoh config {args.config!r}: {err}", file=sys.stderr)
        return 1
    cfg.insert_json5("mode", '"router"')
    if args.listen or not args.config:
        cfg.insert_json5("listen/endpoints", json.dumps(args.listen or ["tcp/127.0.0.1:7447"]))
    if not args.config:
        cfg.insert_json5("scouting/multicast/enabled", "false")
        # as the sessions: what the router forwards (client-mode peers) is not held for batching
        cfg.insert_json5("transport/link/tx/queue/batching/enabled", "false")
    try:
        session = zenoh.open(cfg)
    except Exception as err:
        print(f"aiorobot router: error: cannot start the router: {err}", file=sys.stderr)
        return 1
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    print(f"router {session.zid()} listening on {', '.join(args.listen or ['tcp/127.0.0.1:7447'])}", flush=True)
    stop.wait()
    session.close()
    return 0
