"""``aiorobot bag check RUN --node module:Class [--params f.yaml] [-p NAME:=VALUE] [--tolerance TOPIC.FIELD=ABS]``.

Replays the bag's inputs into the nodes in lock-step on sim time and compares what they publish
with what the bag recorded (:func:`aiorobot.bag.check_bag`). Exit 0 when every output matches
within tolerance, 1 when something differs, 2 for a usage error (bad arguments, a node that
cannot be built, a bag that cannot be read or holds none of the nodes' inputs): one line each,
checked before anything runs.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path
from typing import Any

__all__ = ["add_check_arguments", "check_main", "usage_error"]

EXIT_USAGE = 2


def usage_error(verb: str, text: str) -> int:
    """Print ``aiorobot bag VERB: error: TEXT`` (one line) and return the usage status, 2."""
    print(f"aiorobot bag {verb}: error: {text}", file=sys.stderr)
    return EXIT_USAGE
_PARAM = re.compile(r"^[A-Za-z_][\w.]*:=.*$")


def _node_spec(text: str) -> str:
    from ._run_node import is_node_spec

    if not is_node_spec(text):
        raise argparse.ArgumentTypeError(f"expected module:Class such as aiorobot.fusion:EkfNode, found {text!r}")
    return text


def _tolerance(text: str) -> tuple[str, str, float]:
    from aiorobot.bag import parse_tolerance

    try:
        return parse_tolerance(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err).removeprefix("tolerance: ")) from None


def _param(text: str) -> str:
    if not _PARAM.match(text):
        raise argparse.ArgumentTypeError(f"expected NAME:=VALUE such as frequency:=30.0, found {text!r}")
    return text


def add_check_arguments(sub: Any) -> None:
    check = sub.add_parser(
        "check", help="replay a bag into nodes and compare their outputs with the recording",
        description="Replay the bag's inputs into the given nodes in lock-step on sim time, record what they publish "
        "and compare it message by message and field by field with the bag. Exit 0 when everything is within "
        "tolerance, 1 otherwise, 2 for a usage error.")
    check.add_argument("bag", type=Path, metavar="RUN", help="the recorded bag directory")
    check.add_argument("--node", dest="nodes", action="append", type=_node_spec, required=True, metavar="module:Class",
                       help="a node to run (repeat for several)")
    check.add_argument("--params", dest="params_file", type=Path, metavar="FILE",
                       help="a ROS 2 parameter file for the nodes (ros__parameters under each node's name)")
    check.add_argument("-p", "--param", dest="params", action="append", type=_param, default=[], metavar="NAME:=VALUE",
                       help="set a parameter of every node (after --params)")
    check.add_argument("--tolerance", dest="tolerances", nargs="+", action="extend", type=_tolerance, default=[],
                       metavar="TOPIC.FIELD=ABS", help="allowed absolute error of a field (a prefix covers its sub-fields; "
                       "TOPIC=ABS covers a whole topic); others must match exactly")
    check.add_argument("--topics", nargs="+", default=None, metavar="TOPIC",
                       help="compare only these outputs (default: every topic the nodes publish that the bag holds)")


def check_main(args: argparse.Namespace) -> int:
    from aiorobot.bag import BagError, BagReader

    from ._run_node import _UsageError, build_node

    def usage(text: str) -> int:
        return usage_error("check", text)

    ros_args = ["--ros-args"]
    if args.params_file is not None:
        if not args.params_file.is_file():
            return usage(f"--params: no such file {str(args.params_file)!r}")
        ros_args += ["--params-file", str(args.params_file)]
    for item in args.params:
        ros_args += ["-p", item]
    try:
        with BagReader(args.bag):
            pass  # a bag that cannot be read is a usage error here: exit 1 means "differs"
        nodes = [build_node(spec, ros_args) for spec in args.nodes]
    except (BagError, _UsageError) as err:
        return usage(str(err))
    import aiorobot
    from aiorobot.bag import check_bag

    try:
        result = aiorobot.run(
            check_bag(str(args.bag), [lambda n=n: n for n in nodes], tolerances=args.tolerances, outputs=args.topics)
        )
    except BagError as err:
        return usage(str(err))
    except KeyboardInterrupt:
        return 130
    print(result.table())
    return 0 if result.passed else 1
