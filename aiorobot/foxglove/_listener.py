"""The foxglove-sdk ``ServerListener`` of a bridge: each client request handed to the part that serves it.

The server calls these from its own thread. Nothing here raises into the server (it would only
print "Callback failed" on stderr): each part reports a refusal to the app as a status.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._bridge import FoxgloveBridge

__all__ = ["make_listener"]


def make_listener(bridge: FoxgloveBridge) -> Any:
    """A ``ServerListener`` for ``bridge`` (built here: foxglove is imported only when serving)."""
    from foxglove.websocket import ServerListener

    class Listener(ServerListener):
        def on_subscribe(self, client: Any, channel: Any) -> None:
            bridge.replay_latched(int(client.id), str(channel.topic))

        def on_unsubscribe(self, client: Any, channel: Any) -> None:
            bridge.forget_latched(int(client.id), str(channel.topic))

        def on_client_advertise(self, client: Any, channel: Any) -> None:
            bridge.client_publishing.on_advertise(client, channel)

        def on_client_unadvertise(self, client: Any, client_channel_id: int) -> None:
            bridge.client_publishing.on_unadvertise(client, client_channel_id)

        def on_message_data(self, client: Any, client_channel_id: int, data: bytes) -> None:
            bridge.client_publishing.on_message(client, client_channel_id, data)

        def on_get_parameters(self, client: Any, param_names: list[str], request_id: str | None = None) -> list[Any]:
            return bridge.parameters.get(list(param_names))

        def on_set_parameters(self, client: Any, parameters: list[Any], request_id: str | None = None) -> list[Any]:
            return bridge.parameters.set(list(parameters))

        def on_parameters_subscribe(self, param_names: list[str]) -> None:
            bridge.parameters.subscribe(list(param_names))

        def on_parameters_unsubscribe(self, param_names: list[str]) -> None:
            bridge.parameters.unsubscribe(list(param_names))

        def on_playback_control_request(self, playback_control_request: Any) -> Any:
            if bridge.playback is None:
                return None
            return bridge.playback.request(playback_control_request)

    return Listener()
