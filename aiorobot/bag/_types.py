"""Message types of a bag: aiorobot's own, else registered from the definition the bag stores.

rosbag2 stores, per type, the ``ros2msg`` text rosbag2's definition cache builds: the type's own
file first, then each dependency after a line of 80 ``=`` and ``MSG: pkg/Type``. Three shapes
occur in bags ``ros2 bag record`` wrote that a plain ``.msg`` reading misses:

- a service-event topic (``--all-services``): type ``pkg/srv/X_Event``, text = the ``.srv`` file;
- an old-style type name without ``/msg/`` (``test_msgs/BasicTypes``, written before Foxy);
- a type with no fields (``test_msgs/msg/Empty``): an empty text is a valid definition.
"""

from __future__ import annotations

from typing import Any

__all__ = ["full_type_name", "resolve_type"]

_SEPARATOR = "=" * 80


def full_type_name(name: str) -> str:
    """``pkg/Type`` -> ``pkg/msg/Type`` (old-style names are messages); full names unchanged."""
    parts = name.strip("/").split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 else "/".join(parts)


def resolve_type(type_name: str, definition: tuple[str, str] | None) -> tuple[Any, str]:
    """``(class, "")`` for ``type_name``, an unknown type registered from ``definition``; else ``(None, reason)``.

    ``definition`` is ``(format, text)`` as stored in the bag (``MSG`` or ``IDL``), None when
    the bag stores none. The reason names the type and says why it cannot be known.
    """
    from aiorobot import msgs

    full = full_type_name(type_name)
    try:
        return msgs.get(full), ""
    except (KeyError, LookupError, ValueError):
        pass
    if definition is None:
        return None, f"type {type_name} is unknown to aiorobot and the bag holds no definition of it"
    fmt, text = definition
    if fmt != "MSG":
        return None, f"type {type_name} is unknown to aiorobot and its definition in the bag is {fmt.lower()}, which aiorobot cannot read"
    try:
        register_definition(full, text)
        return msgs.get(full), ""
    except Exception as err:  # a definition aiorobot cannot parse: play nothing rather than wrong data
        return None, f"type {type_name} is unknown to aiorobot and its definition in the bag cannot be used ({err})"


def register_definition(type_name: str, definition: str) -> None:
    """Register a concatenated ``ros2msg`` definition for ``type_name``, its dependencies first.

    ``pkg/srv/X_Event`` (or ``_Request`` / ``_Response``) registers the service ``pkg/srv/X``
    from its ``.srv`` text; anything else registers a message.
    """
    from aiorobot import msgs

    blocks = definition.replace("\r\n", "\n").split(_SEPARATOR + "\n")
    parts: list[tuple[str, str]] = []
    for block in blocks[1:]:
        header, _, text = block.partition("\n")
        if not header.startswith("MSG: "):
            raise ValueError(f"unexpected block header {header!r} in the definition of {type_name}")
        parts.append((full_type_name(header[5:].strip()), text))
    for name, text in reversed(parts):
        if not _known(name):
            msgs.register_msg(text, name)
    pkg, kind, short = type_name.split("/")
    if kind == "srv":
        for suffix in ("_Event", "_Request", "_Response"):
            if short.endswith(suffix):
                msgs.register_srv(blocks[0], f"{pkg}/srv/{short[: -len(suffix)]}")
                return
        raise ValueError(f"{type_name} is a service, not one of its messages (X_Request, X_Response, X_Event)")
    if kind != "msg":
        raise ValueError(f"{type_name}: only message and service-event definitions can be read from a bag")
    msgs.register_msg(blocks[0], type_name)


def _known(name: str) -> bool:
    from aiorobot import msgs

    try:
        msgs.get(name)
    except (KeyError, LookupError, ValueError):
        return False
    return True
