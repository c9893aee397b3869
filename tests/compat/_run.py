"""Run a program under ``aiorobot exec`` as a subprocess and watch its output."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

FIXTURES = Path(__file__).parent / "fixtures"
ROOT = Path(__file__).resolve().parents[2]
#: generous: the machine is shared; a program that works prints its lines well within this
WAIT_SEC = 20.0


class Program:
    """``aiorobot exec [--node M:C ...] FIXTURE args``; output lines collected as they come."""

    def __init__(
        self, script: str, *args: str, nodes: tuple[str, ...] = (), exec_args: tuple[str, ...] = (),
        extra_env: dict[str, str] | None = None,
    ) -> None:
        env = dict(os.environ)
        env.update(extra_env or {})
        env["PYTHONPATH"] = os.pathsep.join([str(FIXTURES), str(ROOT), env.get("PYTHONPATH", "")])
        env["PYTHONUNBUFFERED"] = "1"
        cmd = [sys.executable, "-m", "aiorobot.cli", "exec", *exec_args]
        for node in nodes:
            cmd += ["--node", f"tests.compat.native_nodes:{node}"]
        # a console_scripts entry point (package.module:function) as ``ros2 run`` runs, or a fixture file
        cmd += [script if ":" in script and not script.endswith(".py") else str(FIXTURES / script), *args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env, cwd=FIXTURES)
        self.lines: list[str] = []
        self._eof = False
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        with self.proc.stdout:
            for line in self.proc.stdout:
                with self._changed:
                    self.lines.append(line.rstrip("\n"))
                    self._changed.notify_all()
        with self._changed:
            self._eof = True
            self._changed.notify_all()

    @property
    def output(self) -> str:
        return "\n".join(self.lines)

    def wait_for(self, *needles: str, count: int = 1) -> None:
        """Until every needle appears in ``count`` lines (or the program ends, or WAIT_SEC)."""

        def found() -> bool:
            return all(sum(n in line for line in self.lines) >= count for n in needles)

        with self._changed:
            self._changed.wait_for(lambda: found() or self._eof, WAIT_SEC)
        if not found():
            self.stop()
            raise AssertionError(f"expected {needles} x{count} in the output of {self.proc.args}; got:\n{self.output}")

    def stop(self) -> int:
        """Ctrl-C (as a terminal sends it), then its exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            code = self.proc.wait(WAIT_SEC)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        self._reader.join(5)
        return code

    def finish(self) -> int:
        """Wait for the program to end by itself; its exit status."""
        try:
            code = self.proc.wait(WAIT_SEC)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            raise AssertionError(f"{self.proc.args} did not end by itself; output:\n{self.output}") from None
        self._reader.join(5)
        return code
