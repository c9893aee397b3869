"""``Recorder``: records topics of a running graph into a rosbag2 (MCAP) directory, losing nothing.

Each recorded topic gets a *tap* on the runtime's bus: a subscription whose callback runs in
the publishing thread, so the recorder sees every message in publish order without a queue
that could overflow. The tap serialises the message there (so a publisher that reuses its
message object afterwards cannot change what was recorded) and hands the bytes to a writer
thread, which appends them to the bag. With ``all_topics`` a bus watcher taps every topic the
moment its first publisher appears, before that publisher can publish.
"""

from __future__ import annotations

import datetime
import queue
import re
import threading
import time
from pathlib import Path
from dataclasses import dataclass
from typing import Any

from .._core._node import Node
from .._core._pubsub import Endpoint, Publisher
from .._core._qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ..lowlevel import Tap, add_tap, remove_tap, watch_publishers
from ._metadata import BagError
from ._snapshot import SnapshotBuffer
from ._writer import CHUNK_SIZE, BagWriter

__all__ = ["Recorder", "RecorderStatistics", "default_bag_name"]

_STOP = object()
_SPLIT = object()
_SNAPSHOT = object()
#: How often (wall seconds) ``snapshot_on_failure`` looks at the runtime's failure counts.
_FAILURE_POLL_SEC = 0.2
#: How long the writer thread lets messages gather between batches.
_BATCH_SEC = 0.005


def default_bag_name() -> str:
    """``rosbag2_YYYY_MM_DD-HH_MM_SS``, the directory name ``ros2 bag record`` picks."""
    return datetime.datetime.now().strftime("rosbag2_%Y_%m_%d-%H_%M_%S")


@dataclass(frozen=True, slots=True)
class RecorderStatistics:
    """What a recorder has done so far."""

    topics: int
    messages: int
    bytes: int
    queued: int
    #: snapshots written (snapshot mode)
    snapshots: int = 0


class Recorder(Node):
    """A node that records topics into a rosbag2 directory with MCAP storage.

    Parameters (also from a config's ``parameters``): ``path`` (output directory; default
    ``rosbag2_<date>-<time>``), ``topics`` (list of topic names), ``all`` (record every topic;
    the default when ``topics`` is empty), ``exclude`` (a regular expression of topics not to
    record with ``all``), ``max_bag_size`` (bytes per file, 0 = no split),
    ``max_bag_duration`` (seconds per file, 0 = no split), ``max_cache_size`` (bytes of messages
    held before a chunk goes to the file: what a crash can lose; default 256 KiB), ``compression``
    (``none`` as rosbag2's default, ``zstd`` or ``lz4`` per chunk), ``storage`` (``mcap``, or
    ``sqlite3`` for ``.db3`` files), ``compression_mode`` (rosbag2's zstd per ``file`` or per
    ``message``, either storage; ``compression`` then stays ``none``).

    Snapshot mode (``snapshot_mode``, rosbag2's flight recorder): nothing is written while
    recording; the last ``max_cache_size`` bytes of messages (required > 0 here) are kept in a
    :class:`SnapshotBuffer`, and :meth:`snapshot` (the ``~/snapshot`` service, or any message on
    the ``snapshot_trigger`` topic, or with ``snapshot_on_failure`` a callback failure, a failed
    start or a loop stall in this recorder's runtime) writes them. Each snapshot ends its storage file and rewrites
    ``metadata.yaml``, so the directory is a complete, readable bag as soon as it is written.

    rosbag2's recorder services (``~/pause``, ``~/resume``, ``~/is_paused``, ``~/split_bagfile``)
    call :meth:`pause`, :meth:`resume`, :meth:`is_paused` and :meth:`split_bagfile`.
    """

    def __init__(
        self,
        node_name: str = "recorder",
        *,
        path: str | None = None,
        topics: list[str] | None = None,
        all_topics: bool | None = None,
        exclude: str = "",
        max_bag_size: int = 0,
        max_bag_duration: float = 0.0,
        max_cache_size: int = 0,
        compression: str = "none",
        snapshot_mode: bool = False,
        snapshot_trigger: str = "",
        snapshot_on_failure: bool = False,
        storage: str = "mcap",
        compression_mode: str = "",
        **kwargs: Any,
    ) -> None:
        super().__init__(node_name, **kwargs)
        self.path = str(self.declare_parameter("path", path or default_bag_name()).value)
        wanted = list(self.declare_parameter("topics", list(topics or [""])).value or [])
        self.topics = [t for t in wanted if t]
        self.all_topics = bool(self.declare_parameter("all", not self.topics if all_topics is None else all_topics).value)
        pattern = str(self.declare_parameter("exclude", exclude).value)
        self._exclude = re.compile(pattern) if pattern else None
        self._max_size = int(self.declare_parameter("max_bag_size", int(max_bag_size)).value)
        self._max_duration = float(self.declare_parameter("max_bag_duration", float(max_bag_duration)).value)
        self._cache = int(self.declare_parameter("max_cache_size", int(max_cache_size)).value)
        self._compression = str(self.declare_parameter("compression", compression).value)
        if self._compression not in ("none", "zstd", "lz4"):
            raise ValueError(f"recorder {self.get_name()}: compression must be 'none', 'zstd' or 'lz4', found {self._compression!r}")
        self._storage = str(self.declare_parameter("storage", storage).value)
        if self._storage not in ("mcap", "sqlite3"):
            raise ValueError(f"recorder {self.get_name()}: storage must be 'mcap' or 'sqlite3', found {self._storage!r}")
        self._compression_mode = str(self.declare_parameter("compression_mode", compression_mode).value)
        if self._compression_mode not in ("", "file", "message"):
            raise ValueError(f"recorder {self.get_name()}: compression_mode must be '', 'file' or 'message', found {self._compression_mode!r}")
        if self._compression_mode and self._compression != "none":
            raise ValueError(f"recorder {self.get_name()}: compression_mode {self._compression_mode!r} compresses with zstd "
                             f"already; leave compression at 'none'")
        if self._storage == "sqlite3" and self._compression != "none":
            raise ValueError(f"recorder {self.get_name()}: compression {self._compression!r} is MCAP chunk compression; "
                             "sqlite3 storage is written uncompressed")
        if self._max_size < 0 or self._max_duration < 0 or self._cache < 0:
            raise ValueError(
                f"recorder {self.get_name()}: max_bag_size, max_bag_duration and max_cache_size must be >= 0"
            )
        self.snapshot_mode = bool(self.declare_parameter("snapshot_mode", snapshot_mode).value)
        self._trigger = str(self.declare_parameter("snapshot_trigger", snapshot_trigger).value)
        self._on_failure = bool(self.declare_parameter("snapshot_on_failure", snapshot_on_failure).value)
        self._ring: SnapshotBuffer | None = None
        if self.snapshot_mode:
            if self._cache <= 0:
                raise ValueError(
                    f"recorder {self.get_name()}: snapshot_mode keeps the last max_cache_size bytes in memory, "
                    f"so max_cache_size must be > 0, found {self._cache}"
                )
            self._ring = SnapshotBuffer(self._cache)
        elif self._trigger or self._on_failure:
            what = f"snapshot_trigger {self._trigger!r}" if self._trigger else "snapshot_on_failure"
            raise ValueError(f"recorder {self.get_name()}: {what} needs snapshot_mode")
        if Path(self.path).exists():
            raise BagError(f"{self.path}: exists already; choose another output directory or remove it")
        self._taps: dict[str, Tap] = {}
        self._lock = threading.Lock()
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._writer: BagWriter | None = None
        self._thread: threading.Thread | None = None
        self._unwatch: Any = None
        self._error: BaseException | None = None
        self._bytes = 0
        self._count = 0
        self._paused = False
        self._snapshots = 0
        self._trigger_tap: Tap | None = None
        from ._control import create_recorder_services

        create_recorder_services(self, snapshot=self.snapshot_mode)

    def __repr__(self) -> str:
        return f"<Recorder {self.path} topics={len(self._taps)} messages={self._count}>"

    def statistics(self) -> RecorderStatistics:
        return RecorderStatistics(len(self._taps), self._count, self._bytes, self._queue.qsize(), self._snapshots)

    @property
    def recorded_topics(self) -> list[str]:
        return sorted(self._taps)

    # -- lifecycle --------------------------------------------------------------------

    def on_added(self) -> None:
        # Attach when added to the runtime, synchronously, not in on_start: a publisher added
        # right after the recorder must not publish before the recorder taps it.
        if self._thread is None:
            self._attach()

    def _attach(self) -> None:
        self._writer = BagWriter(
            self.path,
            max_bag_size=self._max_size,
            max_bag_duration_ns=int(self._max_duration * 1e9),
            chunk_size=CHUNK_SIZE if self.snapshot_mode else self._cache or CHUNK_SIZE,
            compression=self._compression,
            storage=self._storage,
            compression_mode=self._compression_mode,
        )
        self._thread = threading.Thread(target=self._write_loop, name=f"aiorobot-recorder {self.path}", daemon=True)
        self._thread.start()
        if self.all_topics:
            self._unwatch = watch_publishers(self.runtime, self._on_endpoint)
        for name in self.topics:
            self._tap_requested(name)
        if self._trigger:
            self._on_first_publisher(self._trigger, self._add_trigger)
        mode = f" in snapshot mode (the last {self._cache} bytes, written on ~/snapshot)" if self.snapshot_mode else ""
        self.get_logger().info(
            f"recording {'all topics' if self.all_topics else ', '.join(self.topics)} to {self.path}{mode}"
        )

    async def on_start(self) -> None:
        if self._on_failure:
            self.create_task(self._watch_failures(), name=f"aiorobot-recorder {self.path} failure trigger")

    async def on_shutdown(self) -> None:
        self.stop()

    def stop(self) -> None:
        """Stop recording: detach every tap, write what is queued, close the bag. Idempotent."""
        if self._unwatch is not None:
            self._unwatch()
            self._unwatch = None
        if self.executor is not None:
            with self._lock:
                taps, self._taps = list(self._taps.values()), {}
                if self._trigger_tap is not None:
                    taps.append(self._trigger_tap)
                    self._trigger_tap = None
            for tap in taps:
                remove_tap(self.runtime, tap)
        if self._thread is not None:
            self._queue.put(_STOP)
            self._thread.join()
            self._thread = None
        if self._error is not None:
            raise BagError(f"recorder {self.get_name()}: writing {self.path} failed: {self._error}")

    # -- control (rosbag2's Recorder API; ``_control`` serves it as rosbag2_interfaces services) ----

    def pause(self) -> None:
        """Stop writing messages (they are dropped) until :meth:`resume`; the topics stay tapped."""
        self._paused = True

    def resume(self) -> None:
        self._paused = False

    def is_paused(self) -> bool:
        return self._paused

    def split_bagfile(self) -> None:
        """Go on in a new storage file, after every message received so far."""
        self._queue.put(_SPLIT)

    def snapshot(self) -> bool:
        """Write what the snapshot buffer holds (snapshot mode; False otherwise, as rosbag2's ``take_snapshot``).

        The writer thread appends the messages, ends the file and rewrites ``metadata.yaml``;
        ``statistics().snapshots`` counts the snapshots written.
        """
        if self._ring is None:
            self.get_logger().warning("snapshot requested, but the recorder is not in snapshot mode")
            return False
        self._queue.put((_SNAPSHOT, self._ring.take()))
        return True

    async def _watch_failures(self) -> None:
        """Take a snapshot whenever the runtime counts a new failure, failed start or stall (checked
        every ``_FAILURE_POLL_SEC`` of wall time, so a stall is caught as soon as the loop runs again)."""
        import asyncio

        def trouble() -> int:
            stats = self.runtime.statistics()
            return sum(stats["failures"].values()) + len(stats["failed_starts"]) + sum(stats["stalls"].values())

        seen = trouble()
        while True:
            await asyncio.sleep(_FAILURE_POLL_SEC)
            now = trouble()
            if now > seen:
                self.get_logger().warning(f"the runtime counted {now - seen} new failure(s) or stall(s): taking a snapshot")
                self.snapshot()
            seen = now

    def _add_trigger(self, pub: Publisher[Any]) -> None:
        """Any message on the trigger topic takes a snapshot (in the publishing thread: the buffer and the queue are thread-safe)."""
        qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=1)
        tap = Tap(pub.msg_type, pub.topic_name, qos, lambda _msg: self.snapshot(), owner=self.get_fully_qualified_name())
        tap.node, tap.wants_remote = self, True
        with self._lock:
            if self._thread is None:
                return
            self._trigger_tap = tap
        add_tap(self.runtime, tap)

    # -- taps -------------------------------------------------------------------------

    def _on_endpoint(self, endpoint: Endpoint) -> None:
        if not isinstance(endpoint, Publisher) or endpoint.topic_name in self._taps:
            return
        if self._exclude is not None and self._exclude.search(endpoint.topic_name):
            return
        self._add_tap(endpoint.topic_name, endpoint.msg_type, endpoint.qos)

    def _tap_requested(self, name: str) -> None:
        """Tap ``name`` now if it has a publisher, else as soon as one appears."""
        self._on_first_publisher(name, lambda pub: self._add_tap(pub.topic_name, pub.msg_type, pub.qos))

    def _on_first_publisher(self, name: str, callback: Any) -> None:
        """``callback(publisher)`` for the first publisher of ``name``: now if there is one, else when it appears."""
        name = self.resolve_topic_name(name)
        found = False
        unwatch = None

        def on_publisher(pub: Publisher[Any]) -> None:
            nonlocal found
            if pub.topic_name == name and not found:
                found = True
                callback(pub)
                if unwatch is not None:
                    unwatch()

        unwatch = watch_publishers(self.runtime, on_publisher)
        if found:
            unwatch()

    def _add_tap(self, name: str, msg_type: Any, offered: QoSProfile) -> None:
        from aiorobot.msgs import serialize

        with self._lock:
            if name in self._taps or self._thread is None:
                return
            # Best effort connects to every publisher; transient local only where the publisher
            # keeps history, so latched topics (/tf_static, /map) are recorded from their start.
            durability = offered.durability
            qos = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, durability=durability, depth=max(offered.depth, 1))
            type_name = str(msg_type.__msgtype__)
            self._queue.put(("topic", name, type_name, offered))
            clock = self.runtime.clock
            put = self._queue.put
            ring = self._ring

            def record(msg: Any) -> None:
                if self._paused:
                    return
                if ring is not None:
                    ring.push(name, clock.now().nanoseconds, serialize(msg))
                else:
                    put((name, clock.now().nanoseconds, serialize(msg)))

            tap = Tap(msg_type, name, qos, record, owner=self.get_fully_qualified_name())
            tap.node, tap.wants_remote = self, True  # also receives remote publishers over a transport
            self._taps[name] = tap
        add_tap(self.runtime, tap)
        if durability is DurabilityPolicy.TRANSIENT_LOCAL:
            self.get_logger().debug(f"recording {name} (transient local)")

    # -- writer thread ------------------------------------------------------------------

    def _write_loop(self) -> None:
        """Drain the queue in batches: a wake-up per message would hand the GIL back and forth
        with the publishing loop a thousand times a second for a 1 kHz topic."""
        writer = self._writer
        assert writer is not None
        get, get_nowait = self._queue.get, self._queue.get_nowait
        try:
            while True:
                item = get()
                while True:
                    if item is _STOP:
                        return
                    if item is _SPLIT:
                        writer.split()
                    elif item[0] is _SNAPSHOT:
                        for topic, time_ns, data in item[1]:
                            writer.write(topic, time_ns, data)
                            self._count += 1
                            self._bytes += len(data)
                        writer.checkpoint()
                        self._snapshots += 1
                    elif item[0] == "topic":
                        _, name, type_name, qos = item
                        writer.add_topic(name, type_name, qos)
                    else:
                        topic, time_ns, data = item
                        writer.write(topic, time_ns, data)
                        self._count += 1
                        self._bytes += len(data)
                    try:
                        item = get_nowait()
                    except queue.Empty:
                        break
                time.sleep(_BATCH_SEC)
        except BaseException as err:  # keep the error for stop(); publishers never block on us
            self._error = err
        finally:
            writer.close()
