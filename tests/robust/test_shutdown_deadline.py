"""A blocked callback, on_shutdown or constructor never makes ``aiorobot run`` unstoppable.

Each case runs a real graph in a subprocess (the serial bridge on a pty to the simulated
firmware, plus a node that blocks in ``time.sleep``), sends SIGINT once it blocks, and
checks that the process ends within the deadline (a generous bound), with the exit code
and message promised, and that the firmware saw a zero wheel command after the signal.
"""

from __future__ import annotations

import signal
import subprocess

import pytest

from aiorobot._core._watchdog import EXIT_SHUTDOWN_TIMEOUT

from ._proc import FirmwareThread, interrupt, start, wait_for_line, write_graph

BOUND_SEC = 20.0  # shutdown_timeout is 1 s; this only catches a hang


@pytest.mark.parametrize("executor", ["main", "priority"])
@pytest.mark.parametrize("block_in", ["callback", "on_shutdown"])
def test_blocked_node_is_abandoned_after_the_deadline_and_the_wheels_get_zero(tmp_path, executor, block_in):
    link = str(tmp_path / "motors")
    config = write_graph(tmp_path, link, executor=executor, block_in=block_in)
    with FirmwareThread(link) as firmware:
        proc = start(["run", str(config)], tmp_path)
        try:
            wait_for_line(proc, "READY")
            before = len(firmware.wheel_commands())
            assert before > 0 and any(any(v) for v in firmware.wheel_commands())
            interrupt(proc)
            _, err = proc.communicate(timeout=BOUND_SEC)
        finally:
            proc.kill()
        after = firmware.wheel_commands()
    assert proc.returncode == EXIT_SHUTDOWN_TIMEOUT, err
    assert "shutdown did not finish within shutdown_timeout = 1 s" in err
    what = "on_shutdown" if block_in == "on_shutdown" else "timer 0.05s"
    assert f"{executor} loop: {what} of /commander blocked at blockers.py" in err, err
    assert "Traceback" not in err
    assert "firmware status OK" in err and "<FirmwareStatus" not in err  # enums by name
    assert after and after[-1] == (0.0, 0.0, 0.0, 0.0)


def test_a_second_signal_abandons_at_once(tmp_path):
    link = str(tmp_path / "motors")
    config = write_graph(tmp_path, link, executor="main", block_in="callback", shutdown_timeout=600)
    with FirmwareThread(link) as firmware:
        proc = start(["run", str(config)], tmp_path)
        try:
            wait_for_line(proc, "READY")
            interrupt(proc, signal.SIGTERM)
            with pytest.raises(subprocess.TimeoutExpired):  # the deadline is far: it waits ...
                proc.wait(timeout=0.5)
            interrupt(proc)  # ... until the second signal
            _, err = proc.communicate(timeout=BOUND_SEC)
        finally:
            proc.kill()
        after = firmware.wheel_commands()
    assert proc.returncode == EXIT_SHUTDOWN_TIMEOUT
    assert "a second signal (SIGINT) received; abandoning what is still blocked"  in err
    assert "main loop: timer 0.05s of /commander blocked" in err
    assert after[-1] == (0.0, 0.0, 0.0, 0.0)


def test_blocked_constructor_ends_at_once_without_a_traceback(tmp_path):
    config = write_graph(tmp_path, str(tmp_path / "motors"), executor="main", block_in="none", use="SlowConstructor")
    proc = start(["run", str(config)], tmp_path)
    try:
        wait_for_line(proc, "READY")
        interrupt(proc)
        _, err = proc.communicate(timeout=BOUND_SEC)
    finally:
        proc.kill()
    assert proc.returncode == 130
    assert "interrupted before the graph started" in err and "Traceback" not in err
