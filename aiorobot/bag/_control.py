"""rosbag2's control services (rosbag2_interfaces) on :class:`Player` and :class:`Recorder`.

The same names, types and answers as rosbag2_transport's player and recorder, so
``aiorobot service call /player/pause rosbag2_interfaces/srv/Pause`` and Foxglove's service
panel work as they do with ``ros2 bag``:

- player: ``~/pause``, ``~/resume``, ``~/toggle_paused``, ``~/is_paused``, ``~/get_rate``,
  ``~/set_rate`` (``success`` false for a rate <= 0), ``~/seek`` (bag time; earlier than the
  bag means its start), ``~/play_next`` and ``~/burst`` (only while paused, as rosbag2: false /
  0 otherwise), ``~/stop``;
- recorder: ``~/pause``, ``~/resume``, ``~/is_paused``, ``~/split_bagfile`` and, in snapshot
  mode only, ``~/snapshot``.

Each service calls the node's public method of the same meaning; this module only translates.
"""

from __future__ import annotations

from typing import Any

__all__ = ["create_player_services", "create_recorder_services"]


def _acting(action: Any) -> Any:
    """A handler that calls ``action()`` and answers with the empty response."""

    def handle(request: Any, response: Any) -> Any:
        action()
        return response

    return handle


def _answering(field: str, getter: Any) -> Any:
    """A handler that answers with ``response.<field> = getter()``."""

    def handle(request: Any, response: Any) -> Any:
        setattr(response, field, getter())
        return response

    return handle


def _ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def create_player_services(player: Any) -> None:
    """rosbag2_transport's ``Player::create_control_services`` on an aiorobot :class:`Player`."""
    from aiorobot.msgs import rosbag2_interfaces as srv

    def set_rate(request: Any, response: Any) -> Any:
        try:
            player.set_rate(request.rate)
        except ValueError as err:
            player.get_logger().warning(f"~/set_rate: {err}; the rate stays {player.get_rate():g}")
            response.success = False
        else:
            response.success = True
        return response

    def seek(request: Any, response: Any) -> Any:
        player.seek(_ns(request.time))
        response.success = True
        return response

    def play_next(request: Any, response: Any) -> Any:
        response.success = player.play_next()
        if not response.success and not player.is_paused():
            player.get_logger().warning("~/play_next: called while playing; pause first")
        return response

    def burst(request: Any, response: Any) -> Any:
        if not player.is_paused():
            player.get_logger().warning("~/burst: only works while paused; nothing played")
        response.actually_burst = player.burst(int(request.num_messages))
        return response

    for name, kind, handler in (
        ("~/pause", srv.Pause, _acting(player.pause)),
        ("~/resume", srv.Resume, _acting(player.resume)),
        ("~/toggle_paused", srv.TogglePaused, _acting(player.toggle_pause)),
        ("~/is_paused", srv.IsPaused, _answering("paused", player.is_paused)),
        ("~/get_rate", srv.GetRate, _answering("rate", player.get_rate)),
        ("~/set_rate", srv.SetRate, set_rate),
        ("~/seek", srv.Seek, seek),
        ("~/play_next", srv.PlayNext, play_next),
        ("~/burst", srv.Burst, burst),
        ("~/stop", srv.Stop, _acting(player.stop)),
    ):
        player.create_service(kind, name, handler)


def create_recorder_services(recorder: Any, *, snapshot: bool = False) -> None:
    """rosbag2_transport's recorder services on an aiorobot :class:`Recorder`."""
    from aiorobot.msgs import rosbag2_interfaces as srv

    services = [
        ("~/pause", srv.Pause, _acting(recorder.pause)),
        ("~/resume", srv.Resume, _acting(recorder.resume)),
        ("~/is_paused", srv.IsPaused, _answering("paused", recorder.is_paused)),
        ("~/split_bagfile", srv.SplitBagfile, _acting(recorder.split_bagfile)),
    ]
    if snapshot:
        services.append(("~/snapshot", srv.Snapshot, _answering("success", recorder.snapshot)))
    for name, kind, handler in services:
        recorder.create_service(kind, name, handler)
