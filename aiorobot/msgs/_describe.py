"""Type hashes (REP-2011 RIHS01) and message definition texts (for MCAP schemas)."""

from __future__ import annotations

from typing import Any

from ._registry import ActionSpec, ServiceSpec, get_spec
from ._spec import ARRAY, SCALAR, FieldType, MsgSpec

__all__ = ["message_definition", "type_hash"]

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


def type_hash(msg_type: type | str) -> str:
    """REP-2011 type hash ``RIHS01_<sha256 hex>`` of a message, service or action type.

    Equal to what ROS 2 Jazzy computes (rosidl_generator_type_description), so it can
    be used in rmw_zenoh key expressions and bag metadata.
    """
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

    import hashlib
    import json

    visit(top)
    doc = {
        "type_description": structs[top.name],
        "referenced_type_descriptions": [structs[k] for k in sorted(structs) if k != top.name],
    }
    digest = hashlib.sha256(json.dumps(doc).encode()).hexdigest()
    return f"RIHS01_{digest}"


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
