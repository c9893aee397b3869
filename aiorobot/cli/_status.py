"""The live status line of ``aiorobot run`` and its end-of-run summary.

Nodes opt in by duck typing: a node with ``status_line() -> str`` contributes to the
line printed every period, one with ``summary() -> str`` to the summary at the end.
The line is a rich ``Live`` display on a terminal, a plain line per period otherwise.
When the reader of a pipe goes away (``aiorobot run | head``), ``on_stream_closed`` is
called: ``aiorobot run`` then shuts the runtime down.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import sys
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Any, TextIO

__all__ = ["StatusDisplay"]


class StatusDisplay:
    """Async context manager printing ``nodes``' status every ``period_sec`` and a summary on exit."""

    def __init__(
        self,
        nodes: Sequence[Any],
        *,
        period_sec: float = 1.0,
        stream: TextIO | None = None,
        on_stream_closed: Callable[[], None] | None = None,
    ) -> None:
        self._nodes = list(nodes)
        self._on_stream_closed = on_stream_closed
        self._closed = False
        self._period_sec = period_sec
        self._stream = sys.stdout if stream is None else stream
        self._live: Any = None
        self._task: asyncio.Task[None] | None = None
        self._start_sec = 0.0
        self._loop: asyncio.AbstractEventLoop | None = None
        self._log_handler: Any = None
        self._log_console: Any = None

    async def __aenter__(self) -> StatusDisplay:
        self._loop = asyncio.get_running_loop()
        self._start_sec = self._loop.time()
        if self._stream.isatty():
            from rich.console import Console
            from rich.live import Live
            from rich.text import Text

            self._live = Live(
                Text(self.status_line()),
                console=Console(file=self._stream),
                auto_refresh=False,
                redirect_stdout=True,
                redirect_stderr=True,
            )
            self._live.start()
            self._share_console_with_log_handler()
        self._task = asyncio.create_task(self._run(), name="aiorobot-status")
        return self

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self._task is not None:
            self._task.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await self._task
        line = self.status_line()
        if self._live is not None:
            from rich.text import Text

            self._live.update(Text(line), refresh=True)
            self._live.stop()
            if self._log_handler is not None:
                self._log_handler.console = self._log_console
        self._write("\n".join(self.summary_lines()))

    def _share_console_with_log_handler(self) -> None:
        """On one terminal, rich log lines must go through the Live console to land above it."""
        from ._logging import installed_handler

        handler = installed_handler()
        if handler is not None and hasattr(handler, "console") and sys.stderr.isatty():
            self._log_handler, self._log_console = handler, handler.console
            handler.console = self._live.console

    def elapsed_sec(self) -> float:
        return 0.0 if self._loop is None else self._loop.time() - self._start_sec

    def status_line(self) -> str:
        parts = [_call(node, "status_line") for node in self._nodes if hasattr(node, "status_line")]
        if not parts:
            parts = [f"{len(self._nodes)} node{'s' if len(self._nodes) != 1 else ''} running"]
        return f"[{self.elapsed_sec():7.1f} s] " + " | ".join(parts)

    def summary_lines(self) -> list[str]:
        count = len(self._nodes)
        lines = [f"ran {self.elapsed_sec():.1f} s with {count} node{'s' if count != 1 else ''}"]
        lines += [_call(node, "summary") for node in self._nodes if hasattr(node, "summary")]
        return lines

    async def _run(self) -> None:
        assert self._loop is not None
        deadline = self._start_sec
        while True:
            deadline += self._period_sec
            await asyncio.sleep(max(0.0, deadline - self._loop.time()))
            line = self.status_line()
            if self._live is not None:
                from rich.text import Text

                self._live.update(Text(line), refresh=True)
            else:
                self._write(line)

    def _write(self, text: str) -> None:
        if self._closed:
            return
        try:
            print(text, file=self._stream, flush=True)
        except BrokenPipeError:  # `aiorobot run | head`: the reader is gone, stop like `yes | head`
            self._closed = True
            with contextlib.suppress(OSError, ValueError):
                # Point the descriptor at /dev/null so the interpreter's final flush stays quiet.
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, self._stream.fileno())
                os.close(devnull)
            if self._on_stream_closed is not None:
                self._on_stream_closed()


def _call(node: Any, method: str) -> str:
    try:
        return str(getattr(node, method)())
    except Exception as err:  # noqa: BLE001 - a broken status must not stop the run
        name = getattr(node, "get_name", lambda: type(node).__name__)()
        return f"{name}: {method}() failed: {type(err).__name__}: {err}"
