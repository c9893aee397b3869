"""``Player``: plays a rosbag2 directory back into a graph, paced like the recording.

Messages are published in time order with the recorded spacing divided by ``rate``, from the
first message on (``metadata.yaml``'s ``starting_time`` may be later than it). With ``clock``
the player also publishes ``/clock`` (rosgraph_msgs/Clock) carrying the playback time, at
``clock_hz`` between messages and exactly at each message's recorded time just before it is
published, so nodes on sim time see ``now()`` equal to the recorded stamp.

The player shares the loop: it never holds it longer than ``_YIELD_NS`` while catching up on
messages that are due, and a ``loop`` pass of a bag whose messages all share one stamp still
gives the loop a turn, so a very short bag played with ``loop`` cannot starve it.
"""

from __future__ import annotations

import asyncio
import time
from dataclasses import dataclass
from typing import Any

from .._core._node import Node
from .._core._qos import QoSProfile, ReliabilityPolicy
from ..lowlevel import wait_until_ns
from ._metadata import BagError
from ._reader import BagReader

__all__ = ["Player", "PlayerStatistics", "parse_remaps"]

#: The longest the player publishes due messages back to back before giving the loop a turn.
_YIELD_NS = 2_000_000
#: The longest the player sleeps before looking again at its state (a seek, a stop, a rate change).
_POLL_NS = 50_000_000


def parse_remaps(remaps: list[str]) -> dict[str, str]:
    """``["/a:=/b", ...]`` -> ``{"/a": "/b"}``; a malformed entry raises ValueError naming it."""
    out: dict[str, str] = {}
    for item in remaps:
        src, sep, dst = item.partition(":=")
        if not sep or not src or not dst:
            raise ValueError(f"remap: expected FROM:=TO, found {item!r}")
        out[src] = dst
    return out


@dataclass(frozen=True, slots=True)
class PlayerStatistics:
    """What a player has done: messages published, skipped (unknown type), loops completed.

    ``subscribers``: over the topics played, the most subscriptions (local and remote) each one
    had matched when a message was published, summed; ``topics_matched``: topics that had any.
    """

    published: int
    skipped: int
    loops: int
    paused: bool
    rate: float
    subscribers: int = 0
    topics_matched: int = 0


class _Cursor:
    """The next message to play, in time order; ``seek`` starts again from a time."""

    def __init__(self, reader: BagReader, topics: list[str], start_ns: int) -> None:
        self._reader, self._topics = reader, topics
        self.seek(start_ns)

    def seek(self, start_ns: int) -> None:
        self._messages = self._reader.messages(self._topics, start_ns=start_ns)
        self._next: tuple[str, int, bytes] | None = next(self._messages, None)

    def peek(self) -> tuple[str, int, bytes] | None:
        return self._next

    def pop(self) -> None:
        self._next = next(self._messages, None)


class Player(Node):
    """A node that plays a rosbag2 directory.

    Parameters: ``path`` (the bag directory), ``rate`` (playback speed, > 0), ``clock``
    (publish ``/clock``), ``clock_hz`` (its rate between messages, default 40 as ``ros2 bag
    play --clock``), ``loop``, ``start_offset`` (seconds into the bag), ``topics`` (only these),
    ``remap`` (``["/from:=/to", ...]``), ``start_paused``.

    rosbag2's player services (``~/pause`` ... ``~/stop``, see :mod:`._control`) call the
    methods of the same names; a seek, a rate change or a resume re-anchors the pacing at the
    current bag time, so playback goes on from there.
    """

    def __init__(
        self,
        node_name: str = "player",
        *,
        path: str = "",
        rate: float = 1.0,
        clock: bool = False,
        clock_hz: float = 40.0,
        loop: bool = False,
        start_offset: float = 0.0,
        topics: list[str] | None = None,
        remap: list[str] | None = None,
        start_paused: bool = False,
        **kwargs: Any,
    ) -> None:
        super().__init__(node_name, **kwargs)
        self._published = 0
        self._skipped = 0
        self._loops = 0
        self._matched: dict[str, int] = {}
        self.path = str(self.declare_parameter("path", path).value)
        self.rate = float(self.declare_parameter("rate", float(rate)).value)
        self.publish_clock = bool(self.declare_parameter("clock", clock).value)
        self.clock_hz = float(self.declare_parameter("clock_hz", float(clock_hz)).value)
        self.loop = bool(self.declare_parameter("loop", loop).value)
        self.start_offset = float(self.declare_parameter("start_offset", float(start_offset)).value)
        self.only = [t for t in self.declare_parameter("topics", list(topics or [""])).value if t]
        self.remaps = parse_remaps([r for r in self.declare_parameter("remap", list(remap or [""])).value if r])
        if not self.path:
            raise ValueError(f"player {self.get_name()}: parameter 'path' (the bag directory) is required")
        if not self.rate > 0:
            raise ValueError(f"player {self.get_name()}: rate must be > 0, found {self.rate!r}")
        if not self.clock_hz > 0:
            raise ValueError(f"player {self.get_name()}: clock_hz must be > 0, found {self.clock_hz!r}")
        if self.start_offset < 0:
            raise ValueError(f"player {self.get_name()}: start_offset must be >= 0, found {self.start_offset!r}")
        self.reader = BagReader(self.path)  # a bad bag fails here, before anything starts
        known = {t.name for t in self.reader.topics}
        missing = [t for t in self.only if t not in known]
        if missing:
            raise BagError(f"{self.path}: no topic {missing[0]} in the bag (topics: {', '.join(sorted(known))})")
        self._topic_pubs: dict[str, Any] = {}
        self._types: dict[str, Any] = {}
        from aiorobot.msgs.type_description_interfaces import GetTypeDescription

        # As every ROS 2 Jazzy node does: another process that does not know a type played here
        # (one registered from the bag) asks for its description, as the zenoh transport does;
        # declared before the publishers, so it is there when they are discovered.
        self.create_service(GetTypeDescription, "~/get_type_description", self._describe_type)
        for info in self.reader.topics:
            if self.only and info.name not in self.only:
                continue
            msg_type = self.reader.message_type(info.name)
            if msg_type is None:
                self.get_logger().warning(f"{info.name}: {self.reader.type_problem(info.name)}; its {info.message_count} messages are skipped")
                continue
            self._types[info.name] = msg_type
            self._topic_pubs[info.name] = self.create_publisher(msg_type, self.remaps.get(info.name, info.name), info.qos)
        self._clock_pub: Any = None
        if self.publish_clock:
            from aiorobot.msgs.rosgraph_msgs import Clock

            self._clock_pub = self.create_publisher(Clock, "/clock", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1))
        self._resume = asyncio.Event()
        if not start_paused:
            self._resume.set()
        self._done = asyncio.Event()
        self._task: asyncio.Task[None] | None = None
        self._stopped = False
        start_ns = self.reader.start_ns + int(self.start_offset * 1e9)
        self._cursor = _Cursor(self.reader, list(self._types), start_ns)
        self._paused_bag_ns = start_ns
        self._anchor(start_ns)
        from ._control import create_player_services

        create_player_services(self)

    def __repr__(self) -> str:
        return f"<Player {self.path} rate={self.rate:g} published={self._published}>"

    def statistics(self) -> PlayerStatistics:
        return PlayerStatistics(
            self._published,
            self._skipped,
            self._loops,
            not self._resume.is_set(),
            self.rate,
            sum(self._matched.values()),
            sum(1 for n in self._matched.values() if n),
        )

    @property
    def topics_played(self) -> list[str]:
        """The bag's topics this player publishes (known types, after ``topics``), under their bag names."""
        return list(self._topic_pubs)

    def _describe_type(self, request: Any) -> Any:
        """``~/get_type_description`` (type_description_interfaces/srv/GetTypeDescription) for the types played."""
        from aiorobot.msgs import type_description, type_hash
        from aiorobot.msgs.type_description_interfaces import GetTypeDescription

        response = GetTypeDescription.Response()
        msg_type = next((t for t in self._types.values() if t.__msgtype__ == request.type_name), None)
        if msg_type is None:
            response.failure_reason = f"type {request.type_name} is not played by {self.get_fully_qualified_name()}"
        elif request.type_hash and request.type_hash != type_hash(msg_type):
            response.failure_reason = f"type {request.type_name} is played with hash {type_hash(msg_type)}, not {request.type_hash}"
        else:
            response.successful = True
            response.type_description = type_description(msg_type)
        return response

    # -- control (rosbag2's Player API; ``_control`` serves it as rosbag2_interfaces services) ----

    def pause(self) -> None:
        if self._resume.is_set():
            self._paused_bag_ns = self._bag_now()
            self._resume.clear()

    def resume(self) -> None:
        if not self._resume.is_set():
            self._anchor(self._paused_bag_ns)
            self._resume.set()

    def toggle_pause(self) -> bool:
        """Pause if playing, resume if paused; returns True when now paused."""
        if self._resume.is_set():
            self.pause()
            return True
        self.resume()
        return False

    def is_paused(self) -> bool:
        return not self._resume.is_set()

    def get_rate(self) -> float:
        return self.rate

    def set_rate(self, rate: float) -> None:
        if not rate > 0:
            raise ValueError(f"rate must be > 0, found {rate!r}")
        self._anchor(self._bag_now())  # playback goes on from where it is, at the new speed
        self.rate = float(rate)

    def seek(self, time_ns: int) -> None:
        """Go on from the first message at or after ``time_ns`` (bag time, clamped to the bag's
        start and end); paused stays paused. After the end, playback starts again from there."""
        time_ns = min(max(int(time_ns), self.reader.start_ns), self.reader.end_ns)
        self._cursor.seek(time_ns)
        self._paused_bag_ns = time_ns
        self._anchor(time_ns)
        if self._done.is_set() and not self._stopped and self._task is not None:
            self._done.clear()
            self._task = self.create_task(self._play(from_seek=True), name=f"aiorobot-player {self.path}")

    @property
    def current_time_ns(self) -> int:
        """The bag time playback has reached (while paused: the time it goes on from)."""
        return min(self._bag_now(), self.reader.end_ns)

    def play_next(self) -> bool:
        """While paused, publish the next message at once; False when playing, stopped or at the end (as rosbag2)."""
        if self._resume.is_set() or self._stopped:
            return False
        item = self._cursor.peek()
        if item is None:
            return False
        self._cursor.pop()
        self._paused_bag_ns = item[1]
        return self._publish_recorded(*item)

    def burst(self, num_messages: int) -> int:
        """While paused, publish up to ``num_messages`` (0: all the rest) at once; returns how many were."""
        count = 0
        while num_messages <= 0 or count < num_messages:
            if not self.play_next():
                break
            count += 1
        return count

    def stop(self) -> None:
        """End playback (the player stays in the graph; ``done`` becomes true)."""
        self._stopped = True
        self._resume.set()

    @property
    def done(self) -> bool:
        return self._done.is_set()

    async def wait_for_completion(self, timeout_sec: float | None = None) -> bool:
        """Wait until every message was played (never, with ``loop``); False on timeout."""
        try:
            await asyncio.wait_for(self._done.wait(), timeout_sec)
        except TimeoutError:
            return False
        return True

    # -- playing -------------------------------------------------------------------------

    async def on_start(self) -> None:
        self._task = self.create_task(self._play(), name=f"aiorobot-player {self.path}")

    async def on_shutdown(self) -> None:
        if self._task is not None:
            self._task.cancel()
        self.reader.close()

    def _anchor(self, bag_ns: int) -> None:
        """From now on, bag time ``bag_ns`` is played at this wall instant, advancing at ``rate``."""
        self._anchor_wall_ns, self._anchor_bag_ns = time.monotonic_ns(), bag_ns

    def _bag_now(self) -> int:
        if not self._resume.is_set():
            return self._paused_bag_ns
        return self._anchor_bag_ns + int((time.monotonic_ns() - self._anchor_wall_ns) * self.rate)

    async def _play(self, from_seek: bool = False) -> None:
        """Play the bag (``loop``: again and again); ``from_seek``: a seek after the end started
        this pass, which goes on from the sought time rather than the start."""
        start = self.reader.start_ns + int(self.start_offset * 1e9)
        clock_period_ns = int(1e9 / self.clock_hz)
        turn = time.monotonic_ns()  # when the loop last had a turn
        try:
            while not self._stopped:
                if self._loops and not from_seek:
                    self.seek(start)
                else:  # the bag time set at construction or by a seek since, played from now on
                    self._anchor(self._paused_bag_ns)
                from_seek = False
                last_clock = time.monotonic_ns() - clock_period_ns
                played = self._published + self._skipped
                while not self._stopped and (item := self._cursor.peek()) is not None:
                    if not self._resume.is_set():
                        await self._resume.wait()
                        continue  # a play_next, seek or stop may have come meanwhile
                    now = time.monotonic_ns()
                    due = self._anchor_wall_ns + int((item[1] - self._anchor_bag_ns) / self.rate)
                    if now < due:  # pace: wait for the message's time, publishing /clock meanwhile
                        wake = min(due, now + _POLL_NS)
                        if self._clock_pub is not None:
                            if now - last_clock >= clock_period_ns:
                                self._publish_clock(self._bag_now())
                                last_clock = now
                            wake = min(wake, last_clock + clock_period_ns)
                        await self._sleep_until_ns(wake)
                        turn = time.monotonic_ns()
                        continue
                    if now - turn >= _YIELD_NS:  # behind schedule: still let the loop run
                        await asyncio.sleep(0)
                        turn = time.monotonic_ns()
                        continue
                    self._cursor.pop()
                    self._publish_recorded(*item)
                self._loops += 1
                if not self.loop or self._published + self._skipped == played:  # nothing to play again
                    break
                await asyncio.sleep(0)  # a pass may have taken no time at all: the loop gets a turn
                turn = time.monotonic_ns()
        finally:
            self._done.set()

    def _publish_recorded(self, topic: str, t_ns: int, data: bytes) -> bool:
        """Publish one recorded message (``/clock`` first, at its time, with ``clock``); False if it does not decode."""
        from aiorobot.msgs import deserialize

        if self._clock_pub is not None:
            self._publish_clock(t_ns)
        try:
            msg = deserialize(data, self._types[topic])
        except Exception as err:  # a damaged record: skip it, say so, keep playing
            self._skipped += 1
            self.get_logger().warning(f"{topic}: a message at {t_ns} ns does not decode ({err}); skipped", throttle_duration_sec=1.0)
            return False
        pub = self._topic_pubs[topic]
        pub.publish(msg)
        self._published += 1
        matched = pub.get_subscription_count()
        if matched > self._matched.get(topic, 0):
            self._matched[topic] = matched
        return True

    async def _sleep_until_ns(self, deadline_ns: int) -> None:
        """Sleep to a monotonic deadline with the loop's precise waker (libuv timers are whole ms)."""
        await wait_until_ns(self, deadline_ns)

    def _publish_clock(self, t_ns: int) -> None:
        from aiorobot.msgs.builtin_interfaces import Time as TimeMsg
        from aiorobot.msgs.rosgraph_msgs import Clock

        self._clock_pub.publish(Clock(clock=TimeMsg(sec=t_ns // 1_000_000_000, nanosec=t_ns % 1_000_000_000)))
