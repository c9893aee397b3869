"""Service introspection, as rcl's: events of a service or client on ``<service>/_service_event``.

``configure_introspection(clock, qos, state)`` on a :class:`~aiorobot._core._services.Service` or
``Client`` turns it on: each call then publishes ``<Srv>_Event`` messages
(``service_msgs/ServiceEventInfo info``, ``request[<=1]``, ``response[<=1]``) — REQUEST_SENT and
RESPONSE_RECEIVED from the client, REQUEST_RECEIVED and RESPONSE_SENT from the service, all
four carrying the client's GID and the call's sequence number. ``METADATA`` leaves the
request and response out; ``CONTENTS`` puts them in; ``OFF`` removes the publisher.
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._services import Client, Service

__all__ = ["EVENT_TOPIC_SUFFIX", "ServiceIntrospection", "ServiceIntrospectionState"]

#: rcl's ``RCL_SERVICE_INTROSPECTION_TOPIC_POSTFIX``
EVENT_TOPIC_SUFFIX = "/_service_event"


class ServiceIntrospectionState(enum.IntEnum):
    """rcl's ``rcl_service_introspection_state_t``."""

    OFF = 0
    METADATA = 1
    CONTENTS = 2


class ServiceIntrospection:
    """The event publisher of one service or client, and what it is configured to say."""

    def __init__(self, endpoint: Service | Client) -> None:
        self.endpoint = endpoint
        self.state = ServiceIntrospectionState.OFF
        self._clock: Any = None
        self._publisher: Any = None

    def __repr__(self) -> str:
        return f"<ServiceIntrospection {self.endpoint.srv_name}{EVENT_TOPIC_SUFFIX} {self.state.name}>"

    def configure(self, clock: Any, qos: Any, state: Any) -> None:
        try:
            state = ServiceIntrospectionState(state)
        except ValueError:
            raise ValueError(
                f"configure_introspection on {self.endpoint.srv_name}: expected a ServiceIntrospectionState "
                f"(OFF, METADATA, CONTENTS), found {state!r}"
            ) from None
        node = self.endpoint.node
        if state is ServiceIntrospectionState.OFF:
            publisher, self._publisher = self._publisher, None
            if publisher is not None:
                node.destroy_publisher(publisher)
        elif self._publisher is None:
            event_type = self.endpoint.srv_type.Event
            self._publisher = node.create_publisher(event_type, self.endpoint.srv_name + EVENT_TOPIC_SUFFIX, qos)
        self._clock = clock if clock is not None else node.get_clock()
        self.state = state

    def emit(self, event_type: int, client_gid: bytes, sequence_number: int, request: Any = None, response: Any = None) -> None:
        """Publish one event (nothing while OFF)."""
        publisher = self._publisher
        if publisher is None or self.state is ServiceIntrospectionState.OFF:
            return
        from ..msgs.service_msgs import ServiceEventInfo

        event = self.endpoint.srv_type.Event()
        event.info = ServiceEventInfo(
            event_type=event_type, stamp=self._clock.now().to_msg(), client_gid=list(client_gid),
            sequence_number=sequence_number,
        )
        if self.state is ServiceIntrospectionState.CONTENTS:
            event.request = [] if request is None else [request]
            event.response = [] if response is None else [response]
        publisher.publish(event)
