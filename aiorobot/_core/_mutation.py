"""``Runtime(debug_messages=True)``: checks of the zero-copy contract.

``publish`` hands subscribers one copy whose large arrays are shared read-only
with the publisher (see ``aiorobot._core._pubsub``); with debug checks on that copy is
a read-only twin (every assignment raises). What the flags cannot stop is a
write through another view of a shared buffer (a driver refilling the frame an
Image's data is a view of) or a callback that sets an array writeable again. So
a publisher re-checks the copies of its last few messages each time it
publishes, and a subscription checks that its callback left the message as it
found it; a change is logged as an error naming the topic and the node. The
checks pickle messages, so they are for development, not production.
"""

from __future__ import annotations

import pickle
from collections import deque
from typing import Any

__all__ = ["PublishGuard", "digest"]

#: How many recent messages a publisher keeps checking.
RECENT = 8


def digest(msg: Any) -> bytes:
    """A byte image of ``msg`` (numpy array contents included)."""
    return pickle.dumps(msg, protocol=pickle.HIGHEST_PROTOCOL)


class PublishGuard:
    """Remembers a publisher's recent messages and reports those changed after ``publish``."""

    def __init__(self) -> None:
        self._recent: deque[tuple[Any, bytes]] = deque(maxlen=RECENT)

    def check(self, msg: Any) -> bool:
        """Record ``msg``; return False when one of the recent messages has changed since it was published."""
        intact = True
        for entry in list(self._recent):
            if digest(entry[0]) != entry[1]:
                intact = False
                self._recent.remove(entry)
        self._recent.append((msg, digest(msg)))
        return intact
