"""playbackControl: Foxglove's playback bar drives a :class:`~aiorobot.bag.Player` (play, pause,
seek, speed), as ``aiorobot bag play --foxglove`` serves it.

The server is started with the bag's time range; each request from the app is applied on the
player's loop and answered with the player's state; while playing, the state (current time,
status, speed) is broadcast every ``period_sec`` so the bar follows the recording. Playback that
reached the end reports ``Ended``; a seek then does not restart it (``--loop`` keeps it going).
"""

from __future__ import annotations

import asyncio
import time
from typing import TYPE_CHECKING, Any

from ..lowlevel import node_loop

if TYPE_CHECKING:
    from ._bridge import FoxgloveBridge

__all__ = ["PlaybackControl"]


class PlaybackControl:
    """Applies the app's playback requests to ``player`` and reports its state."""

    def __init__(self, bridge: FoxgloveBridge, player: Any, *, period_sec: float = 0.1) -> None:
        self.bridge = bridge
        self.player = player
        self.period_ns = int(period_sec * 1e9)
        self._last = 0
        self.requests = 0

    @property
    def time_range(self) -> tuple[int, int]:
        return int(self.player.reader.start_ns), int(self.player.reader.end_ns)

    def request(self, req: Any) -> Any:
        """Apply a ``PlaybackControlRequest`` (in the server's thread); the state it leaves."""
        from foxglove.websocket import PlaybackCommand

        player = self.player
        seek = req.seek_time
        speed = float(req.playback_speed)
        play = req.playback_command == PlaybackCommand.Play

        async def apply() -> None:
            if speed > 0 and speed != player.rate:
                player.set_rate(speed)
            if seek is not None:
                player.seek(int(seek))
            if play:
                player.resume()
            else:
                player.pause()

        loop = node_loop(player)
        if loop is not None:
            asyncio.run_coroutine_threadsafe(apply(), loop).result(timeout=5.0)
        self.requests += 1
        return self.state(did_seek=seek is not None, request_id=req.request_id)

    def state(self, *, did_seek: bool = False, request_id: str | None = None) -> Any:
        from foxglove.websocket import PlaybackState, PlaybackStatus

        player = self.player
        stats = player.statistics()
        if player.done:
            status = PlaybackStatus.Ended
        elif stats.paused:
            status = PlaybackStatus.Paused
        else:
            status = PlaybackStatus.Playing
        return PlaybackState(status, int(player.current_time_ns), float(player.rate), did_seek, request_id)

    def tick(self, server: Any) -> None:
        """From the bridge's thread: broadcast the state every ``period_sec``."""
        now = time.monotonic_ns()
        if now - self._last >= self.period_ns:
            self._last = now
            server.broadcast_playback_state(self.state())
