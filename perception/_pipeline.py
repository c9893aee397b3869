"""Pipelines: for each message on a topic, run a kernel in worker processes fed by a frame ring, publish the result.

::

    pipeline = Pipeline(node, "/camera/image_raw", Image, my_kernel,
                        publish=("/detections", MarkerDetectionArray), workers=2, queue=1)

The subscription callback checks the message, copies its pixels once into a
free ring slot and sends the slot's index to an idle worker; the worker runs
``kernel(pixels, frame)`` on an in-place view and replies with the result (a
message), which the pipeline publishes. Frames that find every worker busy
wait in a queue of ``queue`` frames; the ``policy`` says which frame gives way
when it is full. Bad input is dropped, counted and warned about (throttled);
a worker that dies is restarted and counted; closing (or the node stopping)
stops the workers and unlinks the ring.
"""

from __future__ import annotations

import asyncio
import collections
import multiprocessing
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._images import BadInput, image_array
from ._ring import FrameRing
from ._worker import READY, Frame, worker_main

__all__ = ["POLICIES", "Pipeline", "PipelineStatistics", "StageLatency"]

#: Back-pressure policies: which waiting frame gives way when the queue is full.
POLICIES = ("latest", "drop_oldest")
#: Latency stages reported by :meth:`Pipeline.statistics`.
STAGES = ("handoff", "to_worker", "kernel", "from_worker", "total", "stamp_to_publish")
_WARN_EVERY_SEC = 5.0
_SAMPLES = 4096
_MAX_START_FAILURES = 3


@dataclass(frozen=True)
class StageLatency:
    """Latency of one stage over the last frames, in milliseconds."""

    count: int
    p50_ms: float
    p99_ms: float
    max_ms: float


@dataclass(frozen=True)
class PipelineStatistics:
    """Counters since start, and per-stage latency.

    Stages: ``handoff`` main-process time in the subscription callback (check,
    copy into the ring, send); ``to_worker`` arrival -> kernel start (one-way
    latency); ``kernel``; ``from_worker`` kernel end -> result received;
    ``total`` arrival -> published; ``stamp_to_publish`` header stamp -> published
    (node clock).
    """

    received: int
    processed: int
    published: int
    dropped_queue: int
    dropped_bad_input: int
    failed: int
    worker_restarts: int
    in_flight: int
    latency: dict[str, StageLatency] = field(default_factory=dict)


class _Worker:
    __slots__ = ("index", "process", "conn", "job", "dead", "served", "ready")

    def __init__(self, index: int, process: Any, conn: Any) -> None:
        self.index, self.process, self.conn = index, process, conn
        self.job: tuple[int, int, Frame, float, float] | None = None  # id, slot, frame, arrival, dispatch
        self.dead = False
        self.served = 0
        self.ready = False  # its READY message arrived


def _context() -> Any:
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    return multiprocessing.get_context(method)


class Pipeline:
    """Run ``kernel(pixels, frame) -> message | None`` in ``workers`` processes for each message on ``topic``.

    Parameters
    ----------
    node : the node that owns the subscription and the publisher.
    topic, msg_type : what to subscribe to.
    kernel : a picklable (module-level) function of an in-place read-only numpy
        view and a :class:`Frame`; it must not keep the view after returning. It
        raises :class:`BadInput` for frames it cannot use (counted, not fatal).
    publish : ``(topic, type)`` for the results, or None to only count them.
    workers : worker processes. queue : frames that may wait for a worker (>= 1).
    policy : ``"latest"`` keeps only the newest waiting frame; ``"drop_oldest"``
        keeps up to ``queue`` and drops the oldest when a new one arrives.
    context : called on the node's loop per frame; its (picklable) result is
        ``frame.context``; raising :class:`BadInput` drops the frame.
    to_array : message -> numpy array to carry (default: the checked Image view).
    slot_bytes : the size of a ring slot (the largest frame).
    """

    def __init__(
        self,
        node: Any,
        topic: str,
        msg_type: type,
        kernel: Callable[[Any, Frame], Any],
        *,
        publish: tuple[str, type] | None = None,
        workers: int = 1,
        queue: int = 1,
        policy: str = "latest",
        context: Callable[[], Any] | None = None,
        to_array: Callable[[Any], np.ndarray] = image_array,
        slot_bytes: int = 640 * 480 * 4,
        qos: int = 10,
    ) -> None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")
        if isinstance(queue, bool) or not isinstance(queue, int) or queue < 1:
            raise ValueError(f"queue: expected an integer >= 1, got {queue!r}")
        if policy not in POLICIES:
            raise ValueError(f"policy: expected one of {', '.join(map(repr, POLICIES))}, got {policy!r}")
        self.node = node
        self.topic = topic
        self.kernel = kernel
        self.workers = workers
        self.queue = queue
        self.policy = policy
        self.slot_bytes = slot_bytes
        self._context_fn = context
        self._to_array = to_array
        self._publisher = node.create_publisher(publish[1], publish[0], qos) if publish else None
        self._subscription = node.create_subscription(msg_type, topic, self._on_message, qos)
        self._ring: FrameRing | None = None
        self._workers: list[_Worker] = []
        self._waiting: collections.deque[tuple[int, tuple[int, ...], str, Frame, float]] = collections.deque()
        self._loop: asyncio.AbstractEventLoop | None = None
        self._closed = asyncio.Event()
        self._supervisor: asyncio.Task[Any] | None = None
        self._ready: asyncio.Event | None = None
        self._next_job = 0
        self._start_failures = 0
        self._counts = dict.fromkeys(
            ("received", "processed", "published", "dropped_queue", "dropped_bad_input", "failed", "worker_restarts"),
            0)
        self._samples = {stage: collections.deque(maxlen=_SAMPLES) for stage in STAGES}

    def __repr__(self) -> str:
        busy = sum(w.job is not None for w in self._workers)
        return (f"<Pipeline {self.topic} kernel={getattr(self.kernel, '__qualname__', self.kernel)} "
                f"workers={self.workers} busy={busy} waiting={len(self._waiting)} policy={self.policy}>")

    # -- lifecycle --------------------------------------------------------------------------

    async def start(self) -> None:
        """Create the ring and start the workers (the first frame does this too). Idempotent."""
        if self._ring is None:
            self._start_now()

    async def wait_ready(self) -> None:
        """Start the workers if they are not yet, and return once every one has come up (its
        process started, the frame ring attached, the kernel's module imported). A frame that
        arrives before then waits in the queue (or is dropped by the queue policy), so a graph
        that must not lose its first frames to worker start-up waits here first."""
        if self._ready is None:
            self._ready = asyncio.Event()
            if self._workers and all(w.ready for w in self._workers if not w.dead):
                self._ready.set()
        await self.start()
        await self._ready.wait()

    def _start_now(self) -> None:
        self._loop = asyncio.get_running_loop()
        self._ring = FrameRing(self.workers + self.queue, self.slot_bytes)
        try:
            for index in range(self.workers):
                self._workers.append(self._spawn(index))
        except BaseException:
            self._stop_all()
            raise
        # a node task: the node stopping (runtime shutdown, remove_node) cancels it, which cleans up
        self._supervisor = self.node.create_task(self._supervise(), name=f"pipeline {self.topic}")

    def _spawn(self, index: int) -> _Worker:
        assert self._ring is not None and self._loop is not None
        ctx = _context()
        parent, child = ctx.Pipe()
        process = ctx.Process(target=worker_main, args=(child, self._ring.name, self.slot_bytes, self.kernel),
                              name=f"aiorobot-pipeline-{index}", daemon=True)
        process.start()
        child.close()
        worker = _Worker(index, process, parent)
        self._loop.add_reader(parent.fileno(), self._on_readable, worker)
        self._loop.add_reader(process.sentinel, self._on_exit, worker)
        return worker

    async def _supervise(self) -> None:
        try:
            await self._closed.wait()
        finally:
            self._stop_all()

    async def close(self) -> None:
        """Stop the workers and unlink the ring (idempotent)."""
        self._closed.set()
        task = self._supervisor
        if task is not None and not task.done():
            await asyncio.gather(task, return_exceptions=True)
        self._stop_all()

    def _stop_all(self) -> None:
        workers, self._workers = self._workers, []
        for worker in workers:
            self._forget(worker)
            try:
                worker.conn.send(None)
            except OSError:
                pass
        for worker in workers:
            worker.process.join(timeout=1.0)
            if worker.process.is_alive():
                worker.process.kill()
                worker.process.join()
            worker.conn.close()
            worker.process.close()
        self._waiting.clear()
        if self._ring is not None:
            self._ring.close()

    def _forget(self, worker: _Worker) -> None:
        if self._loop is not None and not self._loop.is_closed() and not worker.dead:
            self._loop.remove_reader(worker.conn.fileno())
            self._loop.remove_reader(worker.process.sentinel)
        worker.dead = True

    def worker_pids(self) -> list[int]:
        """The worker processes' ids (for monitoring; a restarted worker has a new one)."""
        return [w.process.pid for w in self._workers]

    @property
    def ring_name(self) -> str | None:
        """The shared-memory segment's name (``/dev/shm/<name>``), once started."""
        return None if self._ring is None else self._ring.name

    @property
    def free_slots(self) -> int:
        return 0 if self._ring is None else self._ring.free_slots

    # -- frames in ----------------------------------------------------------------------------

    def _on_message(self, msg: Any) -> None:
        if self._closed.is_set():  # frames still queued on the subscription while the node stops
            return
        arrival = time.monotonic()
        self._counts["received"] += 1
        try:
            context = self._context_fn() if self._context_fn is not None else None
            pixels = self._to_array(msg)
            if pixels.nbytes > self.slot_bytes:
                raise BadInput(f"a frame of {pixels.nbytes} bytes exceeds the pipeline's slot_bytes={self.slot_bytes}")
        except BadInput as exc:
            self._drop_bad(str(exc))
            return
        if self._ring is None:
            self._start_now()
        assert self._ring is not None
        if self.policy == "latest":
            self._drop_waiting(len(self._waiting))
        elif len(self._waiting) >= self.queue:
            self._drop_waiting(len(self._waiting) - self.queue + 1)
        slot = self._ring.acquire()
        if slot is None:  # cannot happen: slots = workers + queue
            self._counts["dropped_queue"] += 1
            return
        shape, dtype = self._ring.write(slot, pixels)
        frame = Frame(getattr(msg, "header", None), getattr(msg, "encoding", ""), context)
        self._waiting.append((slot, shape, dtype, frame, arrival))
        self._dispatch()
        self._samples["handoff"].append(time.monotonic() - arrival)

    def _drop_waiting(self, count: int) -> None:
        assert self._ring is not None
        for _ in range(count):
            slot, *_ = self._waiting.popleft()
            self._ring.release(slot)
            self._counts["dropped_queue"] += 1

    def _drop_bad(self, reason: str) -> None:
        self._counts["dropped_bad_input"] += 1
        self.node.get_logger().warning(
            f"pipeline {self.topic}: dropped a frame: {reason} "
            f"({self._counts['dropped_bad_input']} dropped so far)", throttle_duration_sec=_WARN_EVERY_SEC)

    def _dispatch(self) -> None:
        for worker in self._workers:
            if not self._waiting:
                return
            if worker.job is None and not worker.dead:
                slot, shape, dtype, frame, arrival = self._waiting.popleft()
                job_id = self._next_job
                self._next_job += 1
                worker.job = (job_id, slot, frame, arrival, time.monotonic())
                header = frame.header
                stamp = None if header is None else (header.stamp.sec, header.stamp.nanosec)
                try:  # plain values: pickling the Header message would cost more than the frame's copy
                    worker.conn.send((job_id, slot, shape, dtype, stamp, getattr(header, "frame_id", ""),
                                      frame.encoding, frame.context))
                except OSError:
                    self._on_exit(worker)

    # -- results back -------------------------------------------------------------------------

    def _on_readable(self, worker: _Worker) -> None:
        try:
            while not worker.dead and worker.conn.poll():
                reply = worker.conn.recv()
                self._on_reply(worker, reply)
        except (EOFError, OSError):
            self._on_exit(worker)

    def _on_reply(self, worker: _Worker, reply: tuple[int, str, Any, float, float]) -> None:
        received = time.monotonic()
        if reply == READY:
            worker.ready = True
            if self._ready is not None and all(w.ready for w in self._workers if not w.dead):
                self._ready.set()
            return
        job_id, status, result, start, end = reply
        job = worker.job
        if job is None or job[0] != job_id:
            return
        worker.job = None
        worker.served += 1
        _, slot, frame, arrival, _ = job
        assert self._ring is not None
        self._ring.release(slot)
        self._samples["to_worker"].append(start - arrival)
        self._samples["kernel"].append(end - start)
        self._samples["from_worker"].append(received - end)
        if status == "ok":
            self._counts["processed"] += 1
            if result is not None and self._publisher is not None:
                self._publish(result, frame, arrival)
        elif status == "bad":
            self._drop_bad(result)
        else:
            self._counts["failed"] += 1
            self.node.get_logger().error(f"pipeline {self.topic}: the kernel raised:\n{result}",
                                         throttle_duration_sec=_WARN_EVERY_SEC)
        self._dispatch()

    def _publish(self, result: Any, frame: Frame, arrival: float) -> None:
        assert self._publisher is not None
        try:
            self._publisher.publish(result)
        except TypeError as exc:
            self._counts["failed"] += 1
            self.node.get_logger().error(f"pipeline {self.topic}: {exc}", throttle_duration_sec=_WARN_EVERY_SEC)
            return
        self._counts["published"] += 1
        self._samples["total"].append(time.monotonic() - arrival)
        stamp = getattr(frame.header, "stamp", None)
        if stamp is not None and (stamp.sec or stamp.nanosec):
            age_ns = self.node.now().nanoseconds - (stamp.sec * 1_000_000_000 + stamp.nanosec)
            self._samples["stamp_to_publish"].append(age_ns / 1e9)

    def _on_exit(self, worker: _Worker) -> None:
        if worker.dead:
            return
        self._forget(worker)
        worker.process.join(timeout=1.0)
        code = worker.process.exitcode
        if worker.job is not None and self._ring is not None:
            self._ring.release(worker.job[1])
            self._counts["failed"] += 1
        worker.conn.close()
        worker.process.close()
        if worker not in self._workers:
            return
        self._start_failures = 0 if worker.served or worker.job is not None else self._start_failures + 1
        if self._start_failures >= _MAX_START_FAILURES:
            self._workers.remove(worker)
            self.node.get_logger().error(
                f"pipeline {self.topic}: worker {worker.index} exited with code {code} before serving a frame, "
                f"{self._start_failures} times in a row; not restarting it (is the kernel importable? a script "
                f"needs the `if __name__ == \"__main__\":` guard)")
            return
        self._counts["worker_restarts"] += 1
        self.node.get_logger().warning(
            f"pipeline {self.topic}: worker {worker.index} exited with code {code}"
            f"{' while processing a frame' if worker.job is not None else ''}; restarting it "
            f"({self._counts['worker_restarts']} restarts so far)")
        replacement = self._spawn(worker.index)
        self._workers[self._workers.index(worker)] = replacement
        self._dispatch()

    # -- statistics ---------------------------------------------------------------------------

    def reset_statistics(self) -> None:
        """Forget the latency samples (e.g. after a warm-up); the counters keep counting."""
        for samples in self._samples.values():
            samples.clear()

    def statistics(self) -> PipelineStatistics:
        latency = {}
        for stage, samples in self._samples.items():
            if samples:
                ms = np.asarray(samples) * 1e3
                latency[stage] = StageLatency(len(ms), float(np.percentile(ms, 50)), float(np.percentile(ms, 99)),
                                              float(ms.max()))
        in_flight = sum(w.job is not None for w in self._workers) + len(self._waiting)
        return PipelineStatistics(**self._counts, in_flight=in_flight, latency=latency)
