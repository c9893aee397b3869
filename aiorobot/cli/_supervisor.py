"""The child processes of a multi-process graph: started, watched, restarted and stopped by ``aiorobot run``.

A ``[[nodes]]`` entry with ``process = "vision"`` runs in a child process, ``aiorobot run
FILE --process vision``, which builds only that process's nodes and joins the graph over
zenoh: it connects to the supervising process's session (the *hub*, listening on a
loopback port) and, through zenoh's gossip, to the other children.

* Each child runs in its own session (process group), so a Ctrl-C on the terminal reaches
  only ``aiorobot run``, which then sends every child one SIGTERM: each shuts down within
  its own ``runtime.shutdown_timeout``; one still running a second later is killed (and the
  run's exit status is 124, as for an abandoned shutdown).
* A child's stdout and stderr lines come out of ``aiorobot run``'s with ``[name] `` in front.
* A child reads its stdin, a pipe from the supervisor: end of file (the supervisor died,
  even by SIGKILL) shuts it down, so no child outlives its supervisor.
* ``[processes.<name>]`` sets the restart policy (see :class:`aiorobot.launch.ProcessConfig`).
  A child ending with status 2 (a configuration error) is never restarted.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import os
import signal
import sys
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from collections.abc import Callable

    from aiorobot.launch import GraphConfig, ProcessConfig

__all__ = ["ProcessGroup", "ProcessSupervisor", "describe_status"]

_log = logging.getLogger("aiorobot.supervisor")

#: the longest wait before a restart, whatever the backoff
MAX_RESTART_DELAY_SEC = 30.0
#: a child still running this long after its shutdown_timeout (from its SIGTERM) is killed
STOP_GRACE_SEC = 1.0
_EXIT_CONFIG_ERROR = 2
_EXIT_SHUTDOWN_TIMEOUT = 124


def describe_status(returncode: int) -> str:
    """``exited with status 1`` or ``killed by SIGKILL`` (asyncio's negative return codes)."""
    if returncode < 0:
        try:
            name = signal.Signals(-returncode).name
        except ValueError:
            name = f"signal {-returncode}"
        return f"killed by {name}"
    return f"exited with status {returncode}"


@dataclass
class _Child:
    config: ProcessConfig
    proc: asyncio.subprocess.Process | None = None
    restarts: int = 0
    #: what went wrong while the graph ran (a crash, even if restarted), one phrase each
    failures: list[str] = field(default_factory=list)
    #: the exit status after the supervisor's SIGTERM (None: ended before, or still running)
    final: int | None = None
    killed_at_stop: bool = False
    task: asyncio.Task[None] | None = None

    @property
    def name(self) -> str:
        return self.config.name


class ProcessSupervisor:
    """Runs the child processes of ``config`` (every process but ``main``).

    Parameters
    ----------
    config
        The validated graph file.
    hub
        The zenoh endpoint of the supervising process's session, which children connect to.
    status_period_sec
        Passed to each child's ``--status-period``.
    on_required_exit
        Called when a ``required`` process ended for good (the supervising process then
        shuts the whole graph down).
    """

    def __init__(
        self,
        config: GraphConfig,
        hub: str,
        *,
        status_period_sec: float = 1.0,
        on_required_exit: Callable[[], None] | None = None,
        stdout: TextIO | None = None,
        stderr: TextIO | None = None,
    ) -> None:
        self._config = config
        self._hub = hub
        self._status_period_sec = status_period_sec
        self._on_required_exit = on_required_exit
        self._stdout = stdout
        self._stderr = stderr
        self._children = {name: _Child(config.processes[name]) for name in config.child_processes}
        self._stopping = asyncio.Event()
        self._signalled: set[int] = set()

    def __repr__(self) -> str:
        running = sum(1 for c in self._children.values() if c.proc is not None and c.proc.returncode is None)
        return f"<ProcessSupervisor {self._config.path} processes={len(self._children)} running={running}>"

    # -- running --------------------------------------------------------------------------

    async def start(self) -> None:
        """Start every child (each then watched by a task of its own)."""
        for child in self._children.values():
            await self._spawn(child)
            child.task = asyncio.create_task(self._watch(child), name=f"aiorobot-process-{child.name}")

    def pids(self) -> dict[str, int]:
        """The running children's process ids, by process name."""
        return {
            c.name: c.proc.pid for c in self._children.values() if c.proc is not None and c.proc.returncode is None
        }

    async def _spawn(self, child: _Child) -> None:
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        command = [
            sys.executable, "-m", "aiorobot.cli", "run", os.path.abspath(self._config.path),
            "--process", child.name, "--status-period", repr(self._status_period_sec), "--supervisor", self._hub,
        ]
        proc = await asyncio.create_subprocess_exec(
            *command,
            stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.PIPE,
            env=env,
            start_new_session=True,  # the terminal's Ctrl-C goes to the supervisor only
        )
        child.proc = proc
        _log.info(f"process {child.name} started (pid {proc.pid})")

    async def _watch(self, child: _Child) -> None:
        cfg = child.config
        while True:
            proc = child.proc
            assert proc is not None and proc.stdout is not None and proc.stderr is not None
            pumps = [
                asyncio.create_task(self._pump(child.name, proc.stdout, self._stdout or sys.stdout)),
                asyncio.create_task(self._pump(child.name, proc.stderr, self._stderr or sys.stderr)),
            ]
            returncode = await proc.wait()
            await asyncio.wait(pumps, timeout=1.0)  # what it wrote last, bounded (a grandchild may hold the pipe)
            for pump in pumps:
                pump.cancel()
            if self._stopping.is_set():
                child.final = returncode
                return
            what = describe_status(returncode)
            failed = returncode != 0
            if failed:
                child.failures.append(what)
            restart = cfg.restart == "always" or (cfg.restart == "on-failure" and failed)
            why_not = ""
            if returncode == _EXIT_CONFIG_ERROR:
                restart, why_not = False, " (a configuration error: not restarted)"
            elif restart and child.restarts >= cfg.max_restarts:
                restart, why_not = False, f" (max_restarts = {cfg.max_restarts} reached)"
            if not restart:
                level = logging.ERROR if failed or cfg.required else logging.INFO
                tail = "; required: shutting the graph down" if cfg.required else ""
                _log.log(level, f"process {child.name} {what}{why_not}; not restarted{tail}")
                if cfg.required and self._on_required_exit is not None:
                    self._on_required_exit()
                return
            child.restarts += 1
            delay = min(cfg.restart_delay * 2 ** (child.restarts - 1), MAX_RESTART_DELAY_SEC)
            _log.warning(
                f"process {child.name} {what}; restarting in {delay:g} s "
                f"(restart {child.restarts} of at most {cfg.max_restarts})"
            )
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(self._stopping.wait(), delay)
            if self._stopping.is_set():
                return
            await self._spawn(child)

    @staticmethod
    async def _pump(name: str, reader: asyncio.StreamReader, out: TextIO) -> None:
        prefix = f"[{name}] "
        while raw := await reader.readline():
            text = raw.decode("utf-8", "replace")
            if not text.endswith("\n"):
                text += "\n"
            try:
                out.write(prefix + text)
                out.flush()
            except (BrokenPipeError, ValueError):
                pass  # our own output is gone; keep draining so the child never blocks

    # -- stopping -------------------------------------------------------------------------

    def terminate(self) -> None:
        """Send every running child one SIGTERM (each shuts down within its shutdown_timeout).

        Only one: a second signal would make a child abandon its orderly shutdown.
        """
        self._stopping.set()
        for child in self._children.values():
            proc = child.proc
            if proc is not None and proc.returncode is None and proc.pid not in self._signalled:
                self._signalled.add(proc.pid)
                with contextlib.suppress(ProcessLookupError):
                    proc.send_signal(signal.SIGTERM)

    async def wait(self, timeout_sec: float) -> None:
        """Wait until every child has ended; past ``timeout_sec`` (or on a signal), kill the rest."""
        self.terminate()
        loop = asyncio.get_running_loop()
        hurry = asyncio.Event()
        installed = []
        for sig in (signal.SIGINT, signal.SIGTERM):
            with contextlib.suppress(ValueError, RuntimeError, NotImplementedError):
                loop.add_signal_handler(sig, hurry.set)
                installed.append(sig)
        try:
            tasks = [c.task for c in self._children.values() if c.task is not None]
            if tasks:
                hurried = asyncio.create_task(hurry.wait())
                await asyncio.wait([asyncio.gather(*tasks, return_exceptions=True), hurried], timeout=timeout_sec,
                                   return_when=asyncio.FIRST_COMPLETED)
                hurried.cancel()
            for child in self._children.values():
                proc = child.proc
                if proc is not None and proc.returncode is None:
                    child.killed_at_stop = True
                    with contextlib.suppress(ProcessLookupError):
                        proc.kill()
            if tasks:
                await asyncio.wait(tasks, timeout=5.0)
        finally:
            for sig in installed:
                loop.remove_signal_handler(sig)

    def outcome(self) -> tuple[int, list[str]]:
        """The exit status the children give the run (0, 1 or 124) and one line per problem."""
        status = 0
        lines = []
        for child in self._children.values():
            for what in child.failures:
                lines.append(f"  process {child.name}: {what}")
                status = max(status, 1)
            if child.killed_at_stop:
                lines.append(f"  process {child.name}: still running past its shutdown_timeout; killed")
                status = _EXIT_SHUTDOWN_TIMEOUT
            elif child.final is not None and child.final not in (0, -signal.SIGTERM):  # -SIGTERM: ours, early
                lines.append(f"  process {child.name}: {describe_status(child.final)} at shutdown")
                status = max(status, _EXIT_SHUTDOWN_TIMEOUT if child.final == _EXIT_SHUTDOWN_TIMEOUT else 1)
        return status, lines


class ProcessGroup:
    """What ``aiorobot run`` adds to one process of a graph for the others.

    In the main process of a file with child processes (``supervise``): a
    :class:`ProcessSupervisor` and a zenoh endpoint on a free loopback port for them. In a
    child (``supervisor`` = that endpoint): a connection to it, and a watch on stdin whose
    end shuts the process down. Otherwise nothing.
    """

    def __init__(
        self, config: GraphConfig, process: str, *, supervisor: str | None, supervise: bool, status_period_sec: float
    ) -> None:
        from aiorobot.launch import MAIN_PROCESS
        from aiorobot.transport._zenoh import DEFAULT_CONNECT

        self._config = config
        self._status_period_sec = status_period_sec
        self.supervisor: ProcessSupervisor | None = None
        self._hub: str | None = None
        self._watch: asyncio.Task[None] | None = None
        self._supervised = supervisor is not None
        #: ``listen``/``connect`` for the zenoh transport (empty: its defaults)
        self.endpoints: dict[str, list[str]] = {}
        if supervisor is not None:
            self.endpoints = {"connect": [supervisor, DEFAULT_CONNECT]}
        elif supervise and process == MAIN_PROCESS and config.child_processes:
            self._hub = f"tcp/127.0.0.1:{_free_port()}"
            self.endpoints = {"listen": [self._hub], "connect": [DEFAULT_CONNECT]}

    async def start(self, rt: Any) -> None:
        if self._hub is not None:
            self.supervisor = ProcessSupervisor(
                self._config, self._hub, status_period_sec=self._status_period_sec, on_required_exit=rt.shutdown
            )
            await self.supervisor.start()
        if self._supervised:
            self._watch = asyncio.create_task(_shutdown_on_stdin_eof(rt), name="aiorobot-supervisor-watch")

    def terminate(self) -> None:
        if self.supervisor is not None:
            self.supervisor.terminate()

    async def stop(self) -> None:
        if self._watch is not None:
            self._watch.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._watch
        if self.supervisor is not None:
            await self.supervisor.wait(self._config.runtime.shutdown_timeout + STOP_GRACE_SEC)

    def outcome(self, status: int) -> int:
        """Combine this process's exit status with the children's (the worst wins)."""
        if self.supervisor is None:
            return status
        children, lines = self.supervisor.outcome()
        if lines:
            print("failures:\n" + "\n".join(lines), file=sys.stderr)
        return max(status, children)


async def _shutdown_on_stdin_eof(rt: Any) -> None:
    """A supervised child: its supervisor holds the other end of stdin; end of file = it is gone."""
    loop = asyncio.get_running_loop()
    reader = asyncio.StreamReader()
    try:
        await loop.connect_read_pipe(lambda: asyncio.StreamReaderProtocol(reader), sys.stdin)
    except (OSError, ValueError):
        return
    while await reader.read(4096):
        pass
    _log.warning("the supervising aiorobot run is gone: shutting down")
    rt.shutdown()


def _free_port() -> int:
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])
