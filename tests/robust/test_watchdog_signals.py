"""The watchdog's signal path takes no lock: a second Ctrl-C that arrives while the first one's
handler is half-way through must not deadlock the main thread (once seen with gdb: the handler,
re-entered inside ``threading.Event.set``, waited for ever on the event's own lock)."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from aiorobot._core._watchdog import Watchdog


@pytest.mark.timeout(60)
def test_signals_landing_inside_on_signal_do_not_deadlock() -> None:
    watchdog = Watchdog()
    watchdog.close()  # no thread acts on the signals: a second one would rightly abandon this process
    handled = 0

    def handler(signum: int, frame: object) -> None:
        nonlocal handled
        handled += 1
        watchdog.on_signal("SIGUSR1", 3600.0)

    previous = signal.signal(signal.SIGUSR1, handler)
    stop = threading.Event()

    def fire() -> None:  # signals arrive while the main thread is inside on_signal, over and over
        while not stop.is_set():
            os.kill(os.getpid(), signal.SIGUSR1)

    sender = threading.Thread(target=fire, daemon=True)
    try:
        sender.start()
        calls = 0
        while handled < 2000:
            watchdog.on_signal("SIGUSR1", 3600.0)
            calls += 1
    finally:
        stop.set()
        sender.join()
        signal.signal(signal.SIGUSR1, lambda signum, frame: None)
        while signal.SIGUSR1 in signal.sigpending():  # every signal sent is taken before the default returns
            pass
        signal.signal(signal.SIGUSR1, previous)
    assert handled >= 2000 and calls > 0
