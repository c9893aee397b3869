"""Type hashes (REP-2011 RIHS01), type descriptions and message definition texts (for MCAP schemas).

``type_description`` gives the ``type_description_interfaces/msg/TypeDescription`` a ROS 2 Jazzy
node's ``~/get_type_description`` service answers with (the structure the type hash is computed
over); ``register_type_description`` registers a type this process does not know from one.
"""

from __future__ import annotations

from typing import Any

from ._registry import ActionSpec, ServiceSpec, get_spec
from ._spec import ARRAY, SCALAR, FieldType, MsgSpec

__all__ = ["message_definition", "register_type_description", "type_description", "type_hash"]

# type_description_interfaces/msg/FieldType ids. A .msg ``char`` is IDL ``uint8`` in
# rosidl (rosidl_adapter MSG_TYPE_TO_IDL), so it hashes as UINT8, not CHAR.
_TYPE_IDS = {
    "int8": 2, "uint8": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7, "int64": 8,
    "uint64": 9, "float32": 10, "float64": 11, "char": 3, "bool": 15, "byte": 16,
    "string": 17, "wstring": 18,
}
_BOUNDED_STRING_IDS = {"string": 21, "wstring": 22}
_NESTED = 1


def _name_of(msg_type: type | str) -> str:
    if isinstance(msg_type, str):
        return msg_type
    name = getattr(msg_type, "__msgtype__", None)
    if not isinstance(name, str):
        raise TypeError(f"expected an interface type or its name, got {msg_type!r}")
    return name


def _field(name: str, t: FieldType) -> dict[str, Any]:
    if t.is_message:
        tid = _NESTED
    elif t.string_bound:
        tid = _BOUNDED_STRING_IDS[t.base]
    else:
        tid = _TYPE_IDS[t.base]
    if t.kind == ARRAY:
        tid += 48
    elif t.kind != SCALAR:
        tid += 96 if t.count else 144
    return {
        "name": name,
        "type": {
            "type_id": tid,
            "capacity": t.count,
            "string_capacity": t.string_bound,
            "nested_type_name": t.base if t.is_message else "",
        },
    }


def _nested(name: str) -> FieldType:
    return FieldType(name)


def _struct_fields(spec: Any) -> list[tuple[str, FieldType]]:
    if isinstance(spec, MsgSpec):
        return [(f.name, f.type) for f in spec.fields]
    if isinstance(spec, ServiceSpec):
        return [("request_message", _nested(spec.request.name)),
                ("response_message", _nested(spec.response.name)),
                ("event_message", _nested(spec.event.name))]
    assert isinstance(spec, ActionSpec)
    return [("goal", _nested(spec.goal.name)), ("result", _nested(spec.result.name)),
            ("feedback", _nested(spec.feedback.name)),
            ("send_goal_service", _nested(spec.send_goal.name)),
            ("get_result_service", _nested(spec.get_result.name)),
            ("feedback_message", _nested(spec.feedback_message.name))]


def _description(msg_type: type | str) -> dict[str, Any]:
    """The type description of REP-2011 as plain data: the type and every type it references (sorted)."""
    top = get_spec(_name_of(msg_type))
    structs: dict[str, dict[str, Any]] = {}

    def visit(spec: Any) -> None:
        if spec.name in structs:
            return
        fields = _struct_fields(spec)
        structs[spec.name] = {"type_name": spec.name,
                              "fields": [_field(n, t) for n, t in fields]}
        for _, t in fields:
            if t.is_message:
                visit(get_spec(t.base))

    visit(top)
    return {
        "type_description": structs[top.name],
        "referenced_type_descriptions": [structs[k] for k in sorted(structs) if k != top.name],
    }


def type_hash(msg_type: type | str) -> str:
    """REP-2011 type hash ``RIHS01_<sha256 hex>`` of a message, service or action type.

    Equal to what ROS 2 Jazzy computes (rosidl_generator_type_description), so it can
    be used in rmw_zenoh key expressions and bag metadata.
    """
    import hashlib
    import json

    digest = hashlib.sha256(json.dumps(_description(msg_type)).encode()).hexdigest()
    return f"RIHS01_{digest}"


def type_description(msg_type: type | str) -> Any:
    """``msg_type``'s ``type_description_interfaces/msg/TypeDescription`` (fields without default values)."""
    from .type_description_interfaces import Field, FieldType, IndividualTypeDescription, TypeDescription

    def individual(d: dict[str, Any]) -> Any:
        return IndividualTypeDescription(
            type_name=d["type_name"],
            fields=[Field(name=f["name"], type=FieldType(**f["type"])) for f in d["fields"]],
        )

    doc = _description(msg_type)
    return TypeDescription(
        type_description=individual(doc["type_description"]),
        referenced_type_descriptions=[individual(d) for d in doc["referenced_type_descriptions"]],
    )


_BASE_TEXT = {v: k for k, v in _TYPE_IDS.items() if k != "char"}


def _field_text(field: Any) -> str:
    """A TypeDescription field as a .msg line."""
    tid, capacity, bound = int(field.type.type_id), int(field.type.capacity), int(field.type.string_capacity)
    kind, base_id = divmod(tid - 1, 48)
    base_id += 1
    if base_id == _NESTED:
        base = field.type.nested_type_name
    elif base_id in (21, 22):
        base = f"{'string' if base_id == 21 else 'wstring'}<={bound}"
    elif base_id in _BASE_TEXT:
        base = _BASE_TEXT[base_id]
    else:
        raise ValueError(f"field {field.name!r}: type id {tid} has no .msg spelling")
    suffix = ("", f"[{capacity}]", f"[<={capacity}]", "[]")[kind] if kind < 4 else None
    if suffix is None:
        raise ValueError(f"field {field.name!r}: unknown type id {tid}")
    return f"{base}{suffix} {field.name}"


def register_type_description(description: Any) -> type:
    """Register the type ``description`` (a TypeDescription) describes, and the types it references
    that this process does not know; returns its class. A service's ``X_Event`` (a service-event
    topic) registers the service ``X``. Raises ValueError when a description cannot be used."""
    from ._registry import exists, get, register_msg, register_srv

    texts = {d.type_name: "".join(_field_text(f) + "\n" for f in d.fields if f.name != "structure_needs_at_least_one_member")
             for d in [description.type_description, *description.referenced_type_descriptions]}
    top = description.type_description.type_name
    services = {}
    for name in texts:
        pkg, kind, short = name.split("/")
        if kind == "srv" and short.endswith("_Event") and not exists(name):
            base = f"{pkg}/srv/{short[: -len('_Event')]}"
            services[base] = f"{texts[f'{base}_Request']}---\n{texts[f'{base}_Response']}"
    pending = {n: t for n, t in texts.items() if n.split("/")[1] == "msg" and not exists(n)}
    while pending:  # dependencies first: register what can be, until nothing is left
        done = []
        for name, text in pending.items():
            try:
                register_msg(text, name)
            except LookupError:
                continue
            done.append(name)
        if not done:
            raise ValueError(f"cannot register {', '.join(sorted(pending))}: they refer to types that are not described")
        for name in done:
            del pending[name]
    for name, text in services.items():
        register_srv(text, name)
    return get(top)


def _short(name: str) -> str:
    pkg, kind, short = name.split("/")
    return f"{pkg}/{short}" if kind == "msg" else name


def _type_text(t: FieldType, package: str | None = None) -> str:
    """A field type as a .msg file writes it: ``pkg/Type`` (just ``Type`` inside ``package``), bounds, arrays."""
    base = t.base
    if t.is_message:
        pkg, _, short = base.split("/")
        base = short if pkg == package else _short(base)
    if t.string_bound:
        base = f"{base}<={t.string_bound}"
    if t.kind == ARRAY:
        return f"{base}[{t.count}]"
    if t.kind != SCALAR:
        return f"{base}[<={t.count}]" if t.count else f"{base}[]"
    return base


def message_definition(msg_type: type | str) -> str:
    """The message definition text for MCAP ``ros2msg`` schemas and rosbag2.

    The type's .msg text, then each nested type after a line of 80 ``=`` and
    ``MSG: pkg/Type`` (the text rosbags' ``generate_msgdef(..., ros_version=2)`` gives).
    """
    top = get_spec(_name_of(msg_type))
    if not isinstance(top, MsgSpec):
        kind = "service" if isinstance(top, ServiceSpec) else "action"
        raise TypeError(f"message_definition() needs a message type; {top.name} is a {kind} "
                        "(use its .Request/.Response or .Goal/.Result/.Feedback types)")
    subdefs: dict[str, str] = {}

    def text_of(spec: MsgSpec) -> str:
        lines = [f"{c.type} {c.name}={c.value}" for c in spec.constants]
        for f in spec.fields:
            if f.name == "structure_needs_at_least_one_member":
                continue
            if f.type.is_message and f.type.base not in subdefs:
                subdefs[f.type.base] = ""
                sub = get_spec(f.type.base)
                assert isinstance(sub, MsgSpec)
                subdefs[f.type.base] = text_of(sub)
            lines.append(f"{_type_text(f.type)} {f.name}")
        lines.append("")
        return "\n".join(lines)

    main = text_of(top)
    return "".join([main, *(f"{'=' * 80}\nMSG: {_short(k)}\n{v}" for k, v in subdefs.items())])
