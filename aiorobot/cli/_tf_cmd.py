"""``aiorobot tf echo|tree``: tf2_echo and view_frames against a running graph (zenoh).

Both fill an :class:`aiorobot.tf.Buffer` from ``/tf`` and ``/tf_static`` with a
``TransformListener``. ``echo SOURCE TARGET`` prints tf2_echo's block for
``lookup_transform(SOURCE, TARGET)`` (TARGET's pose in SOURCE); ``tree`` listens for
``--wait-time`` seconds, as view_frames, then prints the frames as an indented tree,
tf2's YAML (``--yaml``) or Graphviz (``--dot``, view_frames' ``.gv``).
"""

from __future__ import annotations

import argparse
import asyncio
import math
import sys
from typing import Any

from ._graph_session import UserError, add_graph_options, cli_node, join_graph, run_verb

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    verbs = parser.add_subparsers(dest="verb", metavar="VERB", required=True)
    p = verbs.add_parser("echo", help="print the transform of TARGET in SOURCE, as tf2_echo")
    p.add_argument("source_frame")
    p.add_argument("target_frame")
    p.add_argument("--rate", "-r", type=float, default=1.0, help="echoes per second (default 1)")
    p.add_argument("--count", "-n", type=int, default=None, help="stop after N echoes")
    p.add_argument("--timeout", type=float, default=5.0, help="seconds to wait for the first transform")
    p = verbs.add_parser("tree", help="the frames received on /tf and /tf_static, as view_frames")
    p.add_argument("--wait-time", "-t", type=float, default=5.0, help="seconds to listen (default 5, as view_frames)")
    form = p.add_mutually_exclusive_group()
    form.add_argument("--dot", metavar="FILE", nargs="?", const="-", help="Graphviz output (to FILE, or stdout)")
    form.add_argument("--yaml", action="store_true", help="tf2's frames YAML (allFramesAsYAML)")
    for sub in verbs.choices.values():
        add_graph_options(sub)


def main(args: argparse.Namespace) -> int:
    for name in ("rate", "wait_time", "timeout"):
        value = getattr(args, name, None)
        if value is not None and not (value > 0 and math.isfinite(value)):
            unit = "echoes per second" if name == "rate" else "seconds"
            print(f"aiorobot tf {args.verb}: error: --{name.replace('_', '-')}: expected a positive number of "
                  f"{unit}, found {value}", file=sys.stderr)
            return 2
    return run_verb("tf", args, _main, interrupted=0)


async def _main(args: argparse.Namespace) -> int:
    from ..tf import Buffer, TransformListener

    async with join_graph(args) as rt:
        node = cli_node(rt, "aiorobot_tf")
        buffer = Buffer()
        TransformListener(buffer, node)
        if args.verb == "echo":
            return await _echo(buffer, args)
        await asyncio.sleep(args.wait_time)
        now = node.get_clock().now()
        if args.yaml:
            text = buffer.all_frames_as_yaml(now)
            print(text, end="" if text.endswith("\n") else "\n")
            return 0
        if args.dot:
            text = buffer.to_dot(now)
            if args.dot == "-":
                print(text, end="")
            else:
                with open(args.dot, "w", encoding="utf-8") as f:
                    f.write(text)
            return 0
        print(frames_as_tree(buffer.frame_infos()), end="")
        return 0


async def _echo(buffer: Any, args: argparse.Namespace) -> int:
    from .. import Time
    from ..tf import TransformException

    source, target = args.source_frame, args.target_frame
    try:
        await buffer.wait_for_transform(source, target, Time(), args.timeout)
    except TransformException as err:
        frames = ", ".join(sorted(buffer.get_all_frame_names())) or "none yet"
        raise UserError(f"no transform from {source!r} to {target!r}: {err} (frames received: {frames})") from None
    printed = 0
    while args.count is None or printed < args.count:
        try:
            print(echo_text(buffer.lookup_transform(source, target, Time())), flush=True)
        except TransformException as err:  # the chain broke after the first echo: say so, as tf2_echo
            print(f"Failure: {err}\nThe current list of frames is:\n{buffer.all_frames_as_string()}", flush=True)
        printed += 1
        if args.count is None or printed < args.count:
            await asyncio.sleep(1.0 / args.rate)
    return 0


def echo_text(t: Any) -> str:
    """tf2_echo's block for a ``geometry_msgs/msg/TransformStamped``."""
    import numpy as np

    from ..tf import euler_from_quaternion, transform_from_pq

    tr, rot = t.transform.translation, t.transform.rotation
    p = (tr.x, tr.y, tr.z)
    q = (rot.x, rot.y, rot.z, rot.w)
    rpy = euler_from_quaternion(q)
    matrix = transform_from_pq(np.array(p), np.array(q))

    def vec(values: Any) -> str:
        return "[" + ", ".join(f"{v:.3f}" for v in values) + "]"

    lines = [
        f"At time {t.header.stamp.sec}.{t.header.stamp.nanosec:09d}",
        f"- Translation: {vec(p)}",
        f"- Rotation: in Quaternion (xyzw) {vec(q)}",
        f"- Rotation: in RPY (radian) {vec(rpy)}",
        f"- Rotation: in RPY (degree) {vec(math.degrees(a) for a in rpy)}",
        "- Matrix:",
        *("  " + " ".join(f"{v:6.3f}" for v in row) for row in matrix),
    ]
    return "\n".join(lines)


def frames_as_tree(infos: list[Any]) -> str:
    """The frames as an indented tree, roots first: ``child [static]`` or ``child [20.0 Hz]``."""
    if not infos:
        return "no tf data received\n"
    children: dict[str, list[Any]] = {}
    for info in infos:
        children.setdefault(info.parent, []).append(info)
    framed = {i.frame for i in infos}
    lines: list[str] = []

    def walk(frame: str, depth: int, seen: set[str]) -> None:
        for info in sorted(children.get(frame, []), key=lambda i: i.frame):
            if info.frame in seen:  # a loop in the data: print it once
                continue
            seen.add(info.frame)
            timing = "static" if info.static else f"{info.rate_hz:.1f} Hz"
            lines.append(f"{'  ' * depth}{info.frame} [{timing}]")
            walk(info.frame, depth + 1, seen)

    for root in sorted(set(children) - framed):
        lines.append(root)
        walk(root, 1, {root})
    return "\n".join(lines) + "\n"
