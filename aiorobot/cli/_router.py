"""``aiorobot router``: a zenoh router, what ``ros2 run rmw_zenoh_cpp rmw_zenohd`` is for ROS 2.

A ``--config`` file is checked before zenoh opens, as a session's is (it parses, its
certificate and key files are there, no plain listener beside TLS or access control unless
``--allow-plain`` names it): a problem is one line naming the file and the key, exit 2.
The router then prints the endpoints it listens on, read back from the config zenoh opened.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys

__all__ = ["add_arguments", "main"]

DEFAULT_LISTEN = "tcp/127.0.0.1:7447"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--listen", action="append", metavar="ENDPOINT",
        help="endpoint to listen on (default tcp/127.0.0.1:7447: loopback only; tcp/[::]:7447 as rmw_zenohd)",
    )
    parser.add_argument(
        "--config", metavar="FILE",
        help="a zenoh JSON5 router config (TLS, access control, ...); ZENOH_ROUTER_CONFIG_URI names one too",
    )
    parser.add_argument(
        "--allow-plain", action="append", metavar="ENDPOINT", default=[],
        help="allow this plain (non-TLS) listener although the config enables TLS or access control "
        "(AIOROBOT_ZENOH_ALLOW_PLAIN too)",
    )


def main(args: argparse.Namespace) -> int:
    import zenoh

    from aiorobot.transport._session_config import (
        ZenohConfigError,
        allowed_plain,
        check_plan,
        load_config_file,
        plan_of,
        zenoh_error_text,
    )

    path, named_by = args.config, None
    if not path and os.environ.get("ZENOH_ROUTER_CONFIG_URI", "").strip():
        path, named_by = os.environ["ZENOH_ROUTER_CONFIG_URI"].strip(), "ZENOH_ROUTER_CONFIG_URI"
    try:
        cfg = load_config_file(path, named_by=named_by) if path else zenoh.Config()
        cfg.insert_json5("mode", '"router"')
        if args.listen or not path:
            cfg.insert_json5("listen/endpoints", json.dumps(args.listen or [DEFAULT_LISTEN]))
        if not path:
            cfg.insert_json5("scouting/multicast/enabled", "false")
            # as the sessions: what the router forwards (client-mode peers) is not held for batching
            cfg.insert_json5("transport/link/tx/queue/batching/enabled", "false")
        plan = plan_of(cfg, path or "the default router config", default_mode="router")
        check_plan(plan, allowed_plain(args.allow_plain))
    except ZenohConfigError as err:
        print(f"aiorobot router: error: {err}", file=sys.stderr)
        return 2
    # SIGINT/SIGTERM are blocked here, so zenoh's threads inherit the mask, and taken by sigwait below:
    # a handler that sets a threading.Event can interrupt the main thread inside that event's own
    # lock and wait for ever (the watchdog's bug of the same shape)
    stop_signals = {signal.SIGINT, signal.SIGTERM}
    previous_mask = signal.pthread_sigmask(signal.SIG_BLOCK, stop_signals)
    try:
        session = zenoh.open(cfg)
    except Exception as err:  # noqa: BLE001 - zenoh raises ZError (a port in use, a listener it cannot make)
        where = f" ({path})" if path else ""
        print(
            f"aiorobot router: error: cannot listen on {', '.join(plan.listen) or 'no endpoint'}{where}: {zenoh_error_text(err)}",
            file=sys.stderr,
        )
        signal.pthread_sigmask(signal.SIG_SETMASK, previous_mask)
        return 1
    print(f"router {session.zid()} listening on {', '.join(plan.listen) or 'no endpoint'}", flush=True)
    signal.sigwait(stop_signals)
    session.close()
    signal.pthread_sigmask(signal.SIG_SETMASK, previous_mask)
    return 0
