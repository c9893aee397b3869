"""The ``dora-rs`` row of ``aiorobot bench latency --only zenoh``: the bench's own message pair
through two dora-rs Python nodes.

The parent (:class:`DoraDataflow`) starts a dora coordinator and daemon of its own on free loopback
ports (``dora coordinator --store memory``, ``dora daemon --local-listen-port``), in a temporary
directory, and starts a dataflow whose two nodes are *dynamic* (``path: dynamic``): the bench's
sender and receiver processes join it with ``Node("sender"|"receiver", daemon_port=...)``, so they
answer the same stdin commands as every other path's pair. ``close()`` stops the dataflow and ends
the daemon and the coordinator (their process groups), also when a peer failed; on Linux the two
also get SIGTERM if the bench process is killed outright.

The sender puts the small message on output ``small`` as ``bytes`` and the image on output
``image`` as a ``pyarrow`` array over a numpy buffer (dora copies it once into shared memory; the
receiver gets a ``pyarrow`` array over that memory, read here through a zero-copy numpy view).
The receiver blocks in ``node.next()`` on a thread of its own and stamps each message there, as the
iceoryx2 receiver does on its listener thread (no busy polling: ``next`` waits in dora's Rust code
with the GIL released; its timeout only lets the thread see the end of the run).

dora is optional: nothing here is imported unless ``dora`` is importable, and a dora that cannot
start says why in its row.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from ._zenoh import IMAGE_BYTES, SMALL_BYTES, _free_port, _Record, _sender_commands, _serve_stdin, _stamp_bytes, _unstamp

__all__ = ["DoraDataflow", "dora_cli"]

_DATAFLOW = """\
nodes:
  - id: sender
    path: dynamic
    outputs:
      - small
      - image
  - id: receiver
    path: dynamic
    inputs:
      small: sender/small
      image: sender/image
"""
_START_TIMEOUT_SEC = 20.0
_PR_SET_PDEATHSIG = 1


def dora_cli() -> str | None:
    """The ``dora`` command beside this Python (a venv's ``bin``), else on ``PATH``."""
    here = Path(sys.executable).with_name("dora")
    return str(here) if here.exists() else shutil.which("dora")


def _die_with_parent() -> Any:
    """A ``preexec_fn`` that has Linux send the child SIGTERM when the process (thread) that started it
    ends, so a bench killed outright leaves no dora daemon behind (None elsewhere). libc is loaded
    here, before the fork: the child only makes the one call."""
    if not sys.platform.startswith("linux"):
        return None
    import ctypes

    prctl = ctypes.CDLL(None, use_errno=True).prctl
    return lambda: prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)


def _error_line(text: str) -> str:
    """A dora error (``[ERROR]``, a message, ``Caused by:`` and numbered causes, a location and a
    backtrace) as one line: the message and its causes."""
    parts = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith(("Location:", "Stack backtrace:")):
            break
        if line and line not in ("[ERROR]", "Caused by:"):
            parts.append(re.sub(r"^\d+: ", "", line))
    return ": ".join(parts) or "no output"


class DoraDataflow:
    """A dora coordinator, a daemon and the bench's dataflow, on loopback ports of their own.

    ``start()`` raises ``RuntimeError`` with one line saying what did not start; ``close()`` leaves
    no dora process behind (it is safe to call after a failed ``start()``)."""

    def __init__(self) -> None:
        self.daemon_port = 0
        self._procs: list[subprocess.Popen[bytes]] = []
        self._dir: tempfile.TemporaryDirectory[str] | None = None
        self._cli: str | None = None
        self._env: dict[str, str] = {}

    def __repr__(self) -> str:
        alive = sum(p.poll() is None for p in self._procs)
        return f"<DoraDataflow daemon_port={self.daemon_port} processes={alive}>"

    def start(self) -> None:
        self._cli = dora_cli()
        if self._cli is None:
            raise RuntimeError("dora CLI not found (pip install dora-rs-cli)")
        self._dir = tempfile.TemporaryDirectory(prefix="aiorobot-bench-dora-")
        cwd = self._dir.name
        coordinator_port, self.daemon_port = _free_port(), _free_port()
        self._env = {**os.environ, "DORA_COORDINATOR_ADDR": "127.0.0.1", "DORA_COORDINATOR_PORT": str(coordinator_port),
                     "RUST_BACKTRACE": "0", "RUST_LIB_BACKTRACE": "0",
                     "TMPDIR": cwd}  # the daemon's dora-artifacts-* go with the directory
        Path(cwd, "dataflow.yml").write_text(_DATAFLOW)
        self._spawn("coordinator", "--interface", "127.0.0.1", "--port", str(coordinator_port), "--store", "memory", "--quiet")
        self._spawn("daemon", "--coordinator-port", str(coordinator_port), "--local-listen-port", str(self.daemon_port),
                    "--zenoh-no-multicast")
        deadline = time.monotonic() + _START_TIMEOUT_SEC
        while True:  # until the daemon has registered with the coordinator
            self._check_running()
            try:
                done = subprocess.run([self._cli, "start", "dataflow.yml", "--detach", "--name", "aiorobot-bench"],
                                      cwd=cwd, env=self._env, capture_output=True, text=True, check=False,
                                      timeout=_START_TIMEOUT_SEC)
            except subprocess.TimeoutExpired:
                done = None
            if done is None:
                self._check_running()
                raise RuntimeError(f"the dora dataflow did not start: `dora start` gave no answer in "
                                   f"{_START_TIMEOUT_SEC:.0f} s")
            if done.returncode == 0:
                return
            if time.monotonic() > deadline:
                raise RuntimeError(f"the dora dataflow did not start in {_START_TIMEOUT_SEC:.0f} s: "
                                   f"{_error_line(done.stderr or done.stdout)}")
            time.sleep(0.2)

    def _spawn(self, *args: str) -> None:
        assert self._cli is not None and self._dir is not None
        with open(Path(self._dir.name, f"{args[0]}.log"), "wb") as log:  # the child keeps its own descriptor
            self._procs.append(subprocess.Popen([self._cli, *args], cwd=self._dir.name, env=self._env,
                                                stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                                start_new_session=True, preexec_fn=_die_with_parent()))

    def _check_running(self) -> None:
        assert self._dir is not None
        for proc, what in zip(self._procs, ("coordinator", "daemon")):
            if proc.poll() is not None:
                log = Path(self._dir.name, f"{what}.log").read_text(errors="replace")
                raise RuntimeError(f"the dora {what} did not start: {_error_line(log)}")

    def close(self) -> None:
        if self._cli is not None and self._procs and all(p.poll() is None for p in self._procs):
            with contextlib.suppress(subprocess.TimeoutExpired):  # the processes are ended below anyway
                subprocess.run([self._cli, "stop", "--all", "--grace-duration", "2s"], env=self._env,
                               capture_output=True, timeout=15, check=False)
        for proc in reversed(self._procs):  # the daemon, then the coordinator
            with contextlib.suppress(ProcessLookupError):  # the group may be gone already
                os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        self._procs.clear()
        if self._dir is not None:
            self._dir.cleanup()
            self._dir = None

    def __enter__(self) -> DoraDataflow:
        try:
            self.start()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# -- the peers (``python -m aiorobot.bench._zenoh ROLE dora-rs DAEMON_PORT``) ----------------------


def _protocol_stdout() -> None:
    """dora nodes write their log lines (JSON, one per image sent in dora 1.1) to file descriptor 1,
    where the bench's command protocol runs: point fd 1 at /dev/null and keep the protocol on a
    duplicate of the original."""
    protocol = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.close(devnull)
    sys.stdout = os.fdopen(protocol, "w", buffering=1)


async def receiver(daemon_port: int) -> None:
    _protocol_stdout()
    rec = _Record()
    joined: concurrent.futures.Future[None] = concurrent.futures.Future()
    stop = threading.Event()

    def pump() -> None:
        from dora import Node

        try:
            node = Node("receiver", daemon_port=daemon_port)
        except Exception as err:  # noqa: BLE001 (reported as the peer's one line)
            joined.set_exception(err)
            return
        joined.set_result(None)
        while not stop.is_set():
            event = node.next(timeout=0.1)
            if event is None:  # every sender gone
                return
            if event["type"] == "INPUT":
                rec.got(*_unstamp(event["value"].to_numpy(zero_copy_only=True)))
            elif event["type"] == "STOP":
                return

    thread = threading.Thread(target=pump, name="dora-receiver", daemon=True)
    thread.start()
    if (why := await _joined(joined, "receiver", daemon_port)) is not None:
        print(why, flush=True)
        return
    try:
        await _serve_stdin(lambda cmd: rec.report())
    finally:
        stop.set()
        await asyncio.to_thread(thread.join)


async def sender(daemon_port: int) -> None:
    import numpy as np
    import pyarrow as pa
    from dora import Node

    _protocol_stdout()
    try:
        node = Node("sender", daemon_port=daemon_port)
    except Exception as err:  # noqa: BLE001 (reported as the peer's one line)
        print(_node_error("sender", daemon_port, err), flush=True)
        return
    pixels = np.zeros(IMAGE_BYTES, dtype=np.uint8)
    image = pa.array(pixels)  # over the numpy buffer: the stamp written in place is in it

    def picture() -> Any:
        pixels[:9] = np.frombuffer(time.monotonic_ns().to_bytes(8, "little") + b"\x02", dtype=np.uint8)
        return image

    await _serve_stdin(_sender_commands(
        (lambda kind: _stamp_bytes(kind, SMALL_BYTES), lambda data: node.send_output("small", data)),
        (picture, lambda data: node.send_output("image", data)),
    ))


async def _joined(joined: concurrent.futures.Future[None], node_id: str, daemon_port: int) -> str | None:
    try:
        await asyncio.wrap_future(joined)
    except Exception as err:  # noqa: BLE001
        return _node_error(node_id, daemon_port, err)
    return None


def _node_error(node_id: str, daemon_port: int, err: Exception) -> str:
    return f"dora node {node_id!r} could not join the daemon on port {daemon_port}: {_error_line(str(err))}"
