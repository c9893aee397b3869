"""``aiorobot bag record|play|info|reindex|check|convert|sweep``: ``ros2 bag`` for aiorobot graphs.

``record`` and ``play`` join the running graph through a transport (``--transport``, zenoh by
default: other processes are only reachable over the network); ``info`` and ``reindex`` work
on the directory alone; ``check`` (``_bag_check``) replays a bag into nodes in this process;
``convert`` (``_bag_convert``) rewrites bags as a rosbag2 output-options file says; ``sweep``
(``_bag_sweep``) replays a bag into parameter variants in worker processes.
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path
from typing import Any

from ._parser import positive_seconds, transport_name

__all__ = ["add_arguments", "main"]


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number such as 2 or 0.5, found {text!r}") from None
    if not value > 0 or value != value or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number, found {text!r}")
    return value


def _non_negative_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds such as 0 or 2.5, found {text!r}") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a number of seconds >= 0, found {text!r}")
    return value


def _remap(text: str) -> str:
    src, sep, dst = text.partition(":=")
    if not sep or not src or not dst:
        raise argparse.ArgumentTypeError(f"expected FROM:=TO, found {text!r}")
    return text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="bag_command", metavar="VERB", title="verbs")
    rec = sub.add_parser("record", help="record topics of the running graph into a rosbag2 (MCAP) directory",
                         description="Record topics into a rosbag2 directory with MCAP storage (ros2 bag record).")
    rec.add_argument("topics", nargs="*", metavar="TOPIC", help="topics to record (or -a for all)")
    rec.add_argument("-a", "--all", action="store_true", help="record every topic, including ones that appear later")
    rec.add_argument("-o", "--output", metavar="DIR", help="bag directory to create (default: rosbag2_<date>-<time>)")
    rec.add_argument("-x", "--exclude", default="", metavar="REGEX", help="with -a: topics matching REGEX are not recorded")
    rec.add_argument("--max-duration", type=positive_seconds, metavar="S", help="start a new file every S seconds (ros2's --max-bag-duration)")
    rec.add_argument("--max-size", type=_positive_float, metavar="MB", help="start a new file every MB megabytes (ros2's --max-bag-size)")
    rec.add_argument("--duration", type=positive_seconds, metavar="S", help="stop recording after S seconds (default: until Ctrl-C)")
    rec.add_argument("--max-cache-size", type=_positive_float, metavar="MB",
                     help="megabytes held in memory before they go to the file; with --snapshot-mode, the ring buffer's size")
    rec.add_argument("--snapshot-mode", action="store_true",
                     help="flight recorder: keep the last --max-cache-size MB in memory and write them only on "
                     "~/snapshot (rosbag2_interfaces/srv/Snapshot) or a message on --snapshot-trigger")
    rec.add_argument("-s", "--storage", default="mcap", choices=("mcap", "sqlite3"), help="storage format (default mcap)")
    rec.add_argument("--compression-format", default="none", choices=("none", "zstd", "lz4"),
                     help="compression (default none, as rosbag2): alone, of the MCAP chunks (readable by rosbags, mcap "
                     "and ros2 bag as they are); with --compression-mode, rosbag2's zstd per file or per message")
    rec.add_argument("--compression-mode", default="", choices=("file", "message"), help="rosbag2's compression: zstd per file or per message")
    rec.add_argument("--snapshot-trigger", default="", metavar="TOPIC", help="with --snapshot-mode: any message on TOPIC takes a snapshot")
    _transport_args(rec)

    play = sub.add_parser("play", help="play a bag into the running graph", description="Play a rosbag2 directory (ros2 bag play).")
    play.add_argument("bag", type=Path, metavar="DIR", help="the bag directory")
    play.add_argument("--rate", "-r", type=_positive_float, default=1.0, metavar="R", help="playback speed (default 1)")
    play.add_argument("--clock", nargs="?", type=_positive_float, const=40.0, default=None, metavar="HZ",
                      help="publish /clock with the playback time (at HZ between messages, default 40)")
    play.add_argument("--loop", "-l", action="store_true", help="start again at the end, until Ctrl-C")
    play.add_argument("--start-offset", type=_non_negative_float, default=0.0, metavar="S", help="start S seconds into the bag")
    play.add_argument("--topics", nargs="+", default=[], metavar="TOPIC", help="play only these topics")
    play.add_argument("--remap", nargs="+", type=_remap, default=[], metavar="FROM:=TO", help="publish FROM as TO")
    play.add_argument("--start-paused", action="store_true", help="start paused (space to resume when a terminal is attached)")
    from ._foxglove import port_number

    play.add_argument("--foxglove", nargs="?", type=port_number, const=8765, default=None, metavar="PORT",
                      help="serve the playback to Foxglove on PORT (default 8765): play, pause, seek and speed from its playback bar")
    _transport_args(play)

    info = sub.add_parser("info", help="what a bag holds", description="Print a bag's files, time range and topics (ros2 bag info).")
    info.add_argument("bag", type=Path, metavar="DIR")

    reidx = sub.add_parser("reindex", help="rebuild a bag whose recording was interrupted",
                           description="Rebuild the MCAP files and metadata.yaml of a bag whose recorder died (SIGKILL, power loss).")
    reidx.add_argument("bag", type=Path, metavar="DIR")

    from ._bag_check import add_check_arguments
    from ._bag_convert import add_convert_arguments
    from ._bag_sweep import add_sweep_arguments

    add_check_arguments(sub)
    add_convert_arguments(sub)
    add_sweep_arguments(sub)


def _transport_args(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--transport", default="zenoh", type=transport_name, metavar="NAME",
                        help="how to reach the graph (default zenoh; 'local' is an empty graph in this process)")
    parser.add_argument("--domain-id", type=int, default=None, metavar="N", help="ROS domain id (default: $ROS_DOMAIN_ID or 0)")


def main(args: argparse.Namespace) -> int:
    from aiorobot.bag import BagError

    verb = args.bag_command
    if verb is None:
        print("aiorobot bag: error: expected a verb (record, play, info, reindex, check, convert, sweep)", file=sys.stderr)
        return 2
    if verb == "record" and (problem := _record_problem(args)):
        print(f"aiorobot bag record: error: {problem}", file=sys.stderr)
        return 2
    if verb == "check":
        from ._bag_check import check_main

        return check_main(args)
    if verb == "convert":
        from ._bag_convert import convert_main

        return convert_main(args)
    if verb == "sweep":
        from ._bag_sweep import sweep_main

        return sweep_main(args)
    try:
        if verb == "info":
            return _info(args.bag)
        if verb == "reindex":
            return _reindex(args.bag)
        import aiorobot

        return int(aiorobot.run(_record(args) if verb == "record" else _play(args)))
    except BagError as err:
        print(f"aiorobot bag {verb}: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130


def _record_problem(args: argparse.Namespace) -> str:
    if args.snapshot_mode and not args.max_cache_size:
        return "--snapshot-mode keeps the last --max-cache-size MB in memory: give --max-cache-size"
    if args.snapshot_trigger and not args.snapshot_mode:
        return "--snapshot-trigger needs --snapshot-mode"
    if args.compression_mode and args.compression_format != "zstd":
        return f"--compression-mode {args.compression_mode} needs --compression-format zstd (rosbag2's only format)"
    if args.storage == "sqlite3" and args.compression_format != "none" and not args.compression_mode:
        return (f"--compression-format {args.compression_format} alone is MCAP chunk compression; with --storage sqlite3 "
                "add --compression-mode file or message")
    return ""


# -- info / reindex --------------------------------------------------------------------------


def _size(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{int(n)} B"
        n /= 1024
    return f"{n:.1f} GiB"


def _seconds(ns: int) -> str:
    """``ns`` as seconds with nine decimals, from the integer (a float loses the last digits)."""
    return f"{'-' if ns < 0 else ''}{abs(ns) // 1_000_000_000}.{abs(ns) % 1_000_000_000:09d}"


def _stamp(ns: int) -> str:
    t = datetime.datetime.fromtimestamp(ns // 1_000_000_000, datetime.timezone.utc)
    return f"{t:%b %d %Y %H:%M:%S}.{ns % 1_000_000_000:09d} ({_seconds(ns)})"


def info_text(path: Path) -> str:
    """The ``ros2 bag info`` text of the bag at ``path``."""
    from aiorobot.bag import BagReader

    with BagReader(path) as reader:
        files = reader.files
        lines = [
            f"Files:             {files[0].name if files else ''}",
            *(f"                   {f.name}" for f in files[1:]),
            f"Bag size:          {_size(sum(f.stat().st_size for f in files if f.exists()))}",
            f"Storage id:        {reader.storage}",
            f"Duration:          {_seconds(reader.duration_ns)}s",
            f"Start:             {_stamp(reader.start_ns)}",
            f"End:               {_stamp(reader.end_ns)}",
            f"Messages:          {reader.message_count}",
        ]
        width = max((len(t.name) for t in reader.topics), default=0)
        for i, t in enumerate(sorted(reader.topics, key=lambda t: t.name)):
            head = "Topic information: " if i == 0 else "                   "
            lines.append(f"{head}Topic: {t.name:<{width}} | Type: {t.type} | Count: {t.message_count} | Serialization Format: cdr")
        if not reader.topics:
            lines.append("Topic information: (none)")
    return "\n".join(lines)


def _info(path: Path) -> int:
    print(info_text(path))
    return 0


def _reindex(path: Path) -> int:
    from aiorobot.bag import reindex

    result = reindex(path)
    state = "damaged file(s) repaired" if result.damaged else "no damage found"
    print(f"reindexed {path}: {result.files} file(s), {result.messages} messages recovered; {state}")
    return 0


# -- record / play ---------------------------------------------------------------------------


def _runtime(args: argparse.Namespace, **kwargs: Any) -> Any:
    from aiorobot import Runtime

    kw: dict[str, Any] = {"transport": args.transport}
    if args.domain_id is not None:
        kw["domain_id"] = args.domain_id
    try:
        return Runtime(**kw, **kwargs)
    except NotImplementedError as err:
        from aiorobot.bag import BagError

        raise BagError(f"{err}; use --transport local to record or play inside this process only") from None


async def _record(args: argparse.Namespace) -> int:
    from aiorobot.bag import BagError, Recorder

    if not args.all and not args.topics:
        raise BagError("expected topics to record, or -a for all of them")
    rec_kwargs: dict[str, Any] = {
        "topics": args.topics,
        "all_topics": args.all,
        "exclude": args.exclude,
        "max_bag_size": int((args.max_size or 0) * 1e6),
        "max_bag_duration": args.max_duration or 0.0,
        "max_cache_size": int((args.max_cache_size or 0) * 1e6),
        "snapshot_mode": args.snapshot_mode,
        "snapshot_trigger": args.snapshot_trigger,
        "storage": args.storage,
        "compression": "none" if args.compression_mode else args.compression_format,
        "compression_mode": args.compression_mode,
    }
    if args.output:
        rec_kwargs["path"] = args.output
    try:
        recorder = Recorder(**rec_kwargs)
    except ValueError as err:
        raise BagError(str(err)) from None
    async with _runtime(args) as rt:
        rt.add_node(recorder)
        print(f"recording to {recorder.path} (Ctrl-C to stop)", file=sys.stderr)
        await rt.spin(duration_sec=args.duration)
    stats = recorder.statistics()
    print(f"recorded {stats.messages} messages on {len(recorder.recorded_topics) or stats.topics} topic(s) into {recorder.path}", file=sys.stderr)
    return 0


async def _play(args: argparse.Namespace) -> int:
    import asyncio

    from aiorobot.bag import Player

    async with _runtime(args) as rt:
        player = Player(
            path=str(args.bag),
            rate=args.rate,
            clock=args.clock is not None,
            clock_hz=args.clock or 40.0,
            loop=args.loop,
            start_offset=args.start_offset,
            topics=args.topics,
            remap=args.remap,
            start_paused=args.start_paused,
        )
        rt.add_node(player)
        if args.foxglove is not None:
            from aiorobot.foxglove import FoxgloveBridge

            bridge = rt.add_node(FoxgloveBridge(port=args.foxglove, player=player))
            print(f"Foxglove: open ws://127.0.0.1:{bridge.bound_port}; its playback bar controls this player "
                  "(Ctrl-C to stop)", file=sys.stderr)
        keys = _Keyboard(player) if sys.stdin.isatty() else None
        try:
            done = asyncio.ensure_future(player.wait_for_completion())
            stop = asyncio.ensure_future(rt.spin())
            # with Foxglove, the end of the bag does not end the process: the app may seek back (Ctrl-C stops)
            await asyncio.wait({stop} if args.foxglove is not None else {done, stop}, return_when=asyncio.FIRST_COMPLETED)
            for fut in (done, stop):
                fut.cancel()
        finally:
            if keys is not None:
                keys.close()
        stats = player.statistics()
        topics = len(player.topics_played)
    skipped = f" ({stats.skipped} skipped)" if stats.skipped else ""
    print(
        f"played {stats.published} messages from {args.bag}{skipped} to {stats.subscribers} subscriber(s) "
        f"on {stats.topics_matched} of {topics} topic(s)",
        file=sys.stderr,
    )
    if stats.published and not stats.subscribers:
        where = "in this process" if args.transport == "local" else "in this process or reachable over zenoh"
        print(f"aiorobot bag play: warning: no subscriber matched any of the {topics} topic(s) played ({where}); nothing received these messages", file=sys.stderr)
    return 0


class _Keyboard:
    """Space pauses/resumes, up/down arrows change the rate by 10 % (ros2 bag play's keys)."""

    def __init__(self, player: Any) -> None:
        import asyncio
        import termios
        import tty

        self.player = player
        self.fd = sys.stdin.fileno()
        self.saved = termios.tcgetattr(self.fd)
        tty.setcbreak(self.fd)
        self.loop = asyncio.get_running_loop()
        self.loop.add_reader(self.fd, self._on_key)
        self.buffer = ""
        print("keys: space = pause/resume, up/down = rate +/- 10 %", file=sys.stderr)

    def _on_key(self) -> None:
        import os

        self.buffer += os.read(self.fd, 16).decode(errors="ignore")
        while self.buffer:
            if self.buffer.startswith(" "):
                paused = self.player.toggle_pause()
                print("paused" if paused else "playing", file=sys.stderr)
                self.buffer = self.buffer[1:]
            elif self.buffer.startswith("\x1b[A") or self.buffer.startswith("\x1b[B"):
                factor = 1.1 if self.buffer[2] == "A" else 1 / 1.1
                self.player.set_rate(self.player.rate * factor)
                print(f"rate {self.player.rate:.2f}", file=sys.stderr)
                self.buffer = self.buffer[3:]
            elif self.buffer.startswith("\x1b") and len(self.buffer) < 3:
                return  # the rest of an arrow key is on its way
            else:
                self.buffer = self.buffer[1:]

    def close(self) -> None:
        import termios

        self.loop.remove_reader(self.fd)
        termios.tcsetattr(self.fd, termios.TCSADRAIN, self.saved)
