"""The process-wide interface registry: definitions by name, classes built on demand.

Definitions come from three places, all looked up lazily: the ROS 2 Jazzy snapshot
(``_jazzy.py``), the .msg/.srv/.action files shipped in ``_interfaces/`` (named
``<pkg>__<Name>.<ext>``), and user registrations (``register_msg`` and friends).
Like ROS's own type support, there is one registry per process; registering an
identical definition again is a no-op and a conflicting one raises ``ValueError``.
"""

from __future__ import annotations

import difflib
import threading
from pathlib import Path
from typing import Any, NamedTuple

from ._spec import Field, FieldType, MsgSpec, parse_action, parse_msg, parse_srv, parse_type

__all__ = [
    "ActionSpec",
    "ServiceSpec",
    "all_names",
    "exists",
    "generation",
    "get",
    "get_spec",
    "package_names",
    "register_action",
    "register_file",
    "register_many",
    "register_msg",
    "register_srv",
]

_INTERFACES_DIR = Path(__file__).with_name("_interfaces")
_KINDS = {"msg": ".msg", "srv": ".srv", "action": ".action"}


class ServiceSpec(NamedTuple):
    """A service ``pkg/srv/Name`` (or an action's ``pkg/action/Name_SendGoal``)."""

    name: str
    request: MsgSpec
    response: MsgSpec
    event: MsgSpec


class ActionSpec(NamedTuple):
    name: str
    goal: MsgSpec
    result: MsgSpec
    feedback: MsgSpec
    send_goal: ServiceSpec
    get_result: ServiceSpec
    feedback_message: MsgSpec


Spec = MsgSpec | ServiceSpec | ActionSpec

_lock = threading.RLock()
_specs: dict[str, Spec] = {}  # every loaded spec, incl. srv/action parts
_classes: dict[str, type] = {}
_shipped_index: dict[str, Path] | None = None
_generation = 0  # counts registrations, so that views of the registry know when to look again


def _shipped() -> dict[str, Path]:
    global _shipped_index
    if _shipped_index is None:
        index = {}
        for path in sorted(_INTERFACES_DIR.iterdir()):
            kind = path.suffix[1:]
            if kind in _KINDS and "__" in path.stem:
                pkg, name = path.stem.split("__", 1)
                index[f"{pkg}/{kind}/{name}"] = path
        _shipped_index = index
    return _shipped_index


def _jazzy() -> dict[str, Any]:
    from ._jazzy import DEFS

    return DEFS


def _make_service(name: str, request: MsgSpec, response: MsgSpec) -> ServiceSpec:
    event = MsgSpec(f"{name}_Event", (
        Field("info", FieldType("service_msgs/msg/ServiceEventInfo")),
        Field("request", parse_type(f"{request.name}[<=1]")),
        Field("response", parse_type(f"{response.name}[<=1]")),
    ))
    return ServiceSpec(name, request, response, event)


def _make_action(name: str, goal: MsgSpec, result: MsgSpec, feedback: MsgSpec) -> ActionSpec:
    uuid = Field("goal_id", FieldType("unique_identifier_msgs/msg/UUID"))
    send_goal = _make_service(
        f"{name}_SendGoal",
        MsgSpec(f"{name}_SendGoal_Request", (uuid, Field("goal", FieldType(goal.name)))),
        MsgSpec(f"{name}_SendGoal_Response", (
            Field("accepted", FieldType("bool")),
            Field("stamp", FieldType("builtin_interfaces/msg/Time")),
        )),
    )
    get_result = _make_service(
        f"{name}_GetResult",
        MsgSpec(f"{name}_GetResult_Request", (uuid,)),
        MsgSpec(f"{name}_GetResult_Response", (
            Field("status", FieldType("int8")),
            Field("result", FieldType(result.name)),
        )),
    )
    fb_msg = MsgSpec(f"{name}_FeedbackMessage", (uuid, Field("feedback", FieldType(feedback.name))))
    return ActionSpec(name, goal, result, feedback, send_goal, get_result, fb_msg)


def _parts(spec: Spec) -> list[Spec]:
    """The spec and every spec it defines (service request/response/event, action parts)."""
    if isinstance(spec, MsgSpec):
        return [spec]
    if isinstance(spec, ServiceSpec):
        return [spec, spec.request, spec.response, spec.event]
    return [spec, spec.goal, spec.result, spec.feedback, *_parts(spec.send_goal),
            *_parts(spec.get_result), spec.feedback_message]


def _parse_text(text: str, name: str) -> Spec:
    kind = name.split("/")[1]
    if kind == "msg":
        return parse_msg(text, name)
    if kind == "srv":
        return _make_service(name, *parse_srv(text, name))
    return _make_action(name, *parse_action(text, name))


def _install(spec: Spec) -> None:
    for part in _parts(spec):
        _specs[part.name] = part


def _owner(name: str) -> str:
    """``pkg/srv/X_Request`` -> ``pkg/srv/X``; ``pkg/action/X_SendGoal_Request`` -> ``pkg/action/X``."""
    parts = name.split("/")
    if len(parts) != 3:
        return name
    pkg, kind, short = parts
    if kind == "srv":
        for suffix in ("_Request", "_Response", "_Event"):
            if short.endswith(suffix):
                return f"{pkg}/srv/{short[: -len(suffix)]}"
    if kind == "action":
        for suffix in ("_SendGoal_Request", "_SendGoal_Response", "_SendGoal_Event", "_SendGoal",
                       "_GetResult_Request", "_GetResult_Response", "_GetResult_Event",
                       "_GetResult", "_FeedbackMessage", "_Goal", "_Result", "_Feedback"):
            if short.endswith(suffix):
                return f"{pkg}/action/{short[: -len(suffix)]}"
    return name


def _load_builtin(name: str) -> Spec | None:
    """Find ``name`` in the Jazzy snapshot or the shipped files (caller holds the lock)."""
    defs = _jazzy()
    if name in defs:
        from ._spec import spec_from_snapshot

        spec: Spec = spec_from_snapshot(name, defs[name])
        _install(spec)
        return spec
    owner = _owner(name)
    path = _shipped().get(owner)
    if path is None:
        return None
    _install(_parse_text(path.read_text(encoding="utf-8"), owner))
    return _specs.get(name)


def normalize_name(name: str) -> str:
    """``sensor_msgs/Image`` -> ``sensor_msgs/msg/Image``; full names pass unchanged."""
    if not isinstance(name, str):
        raise TypeError(f"interface type names are strings like 'sensor_msgs/msg/Image', "
                        f"got {type(name).__name__} {name!r}")
    parts = name.strip("/").split("/")
    if len(parts) == 2:
        pkg, short = parts
        for kind in ("msg", "srv", "action"):
            full = f"{pkg}/{kind}/{short}"
            if exists(full):
                return full
        return f"{pkg}/msg/{short}"
    return "/".join(parts)


def exists(name: str) -> bool:
    """Whether the full interface name ``pkg/kind/Name`` is known (no loading, no errors)."""
    return name in _specs or name in _jazzy() or _owner(name) in _shipped()


def all_names(*, registered: bool = True) -> list[str]:
    """Every known interface name (messages, services, actions; not their parts).

    ``registered=False`` leaves out user registrations (only the built-in definitions).
    """
    with _lock:
        names = set(_jazzy()) | set(_shipped())
        if registered:
            names |= {n for n in _specs if _owner(n) == n}
    return sorted(names)


def package_names(package: str) -> list[str]:
    """Short names of the messages, services and actions of ``package``."""
    prefix = f"{package}/"
    return sorted({n.rsplit("/", 1)[1] for n in all_names() if n.startswith(prefix)
                   and _owner(n) == n})


def get_spec(name: str) -> Spec:
    """The spec for ``name``; LookupError naming the type and close names if unknown."""
    full = normalize_name(name)
    with _lock:
        spec = _specs.get(full)
        if spec is None:
            spec = _load_builtin(full)
    if spec is None:
        names = all_names()
        if full.count("/") != 2:  # e.g. "Twist": offer the types of that name
            close = [n for n in names if n.rsplit("/", 1)[-1] == full.rsplit("/", 1)[-1]][:3]
        else:
            close = difflib.get_close_matches(full, names, n=3, cutoff=0.8)
        hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else (
            "; register it with aiorobot.msgs.register_msg/register_srv/register_action/"
            "register_file")
        raise LookupError(f"unknown interface type {name!r}{hint}")
    return spec


def get(name: str) -> type:
    """The class of message, service or action type ``name``.

    ``name`` is ``pkg/msg/Name`` (``pkg/srv/Name``, ``pkg/action/Name``) or the short
    ``pkg/Name``. Raises LookupError naming the type and suggesting close names.
    """
    if isinstance(name, type) and hasattr(name, "__msgtype__"):
        return name
    cls = _classes.get(name)  # fast path for full names
    if cls is not None:
        return cls
    spec = get_spec(name)
    with _lock:
        cls = _classes.get(spec.name)
        if cls is None:
            from ._classgen import build_class

            from ._classgen import _walk

            cls = build_class(spec, get)
            _classes[spec.name] = cls
            for part in _walk(cls):
                _classes.setdefault(part.__msgtype__, part)
    return cls


def _check_name(name: str, kind: str) -> None:
    parts = name.split("/")
    if len(parts) != 3 or parts[1] != kind or not all(parts):
        raise ValueError(f"expected a type name like 'my_pkg/{kind}/Name', got {name!r}")


def _register(text: str, name: str, kind: str) -> type:
    _check_name(name, kind)
    spec = _parse_text(text, name)
    with _lock:
        try:
            existing = get_spec(name)
        except LookupError:
            existing = None
        if existing is not None:
            if _same(existing, spec):
                return get(name)
            raise ValueError(
                f"conflicting definition for {name!r}: already registered as\n"
                f"{_describe(existing)}\nnew definition:\n{_describe(spec)}\n"
                "Use a different type name for the new definition.")
        _install(spec)
        _bump()
        try:
            return get(name)
        except LookupError as exc:  # a nested type is unknown: register nothing
            for part in _parts(spec):
                _specs.pop(part.name, None)
            raise LookupError(f"cannot register {name!r}: {exc}; register the types it uses "
                              "first") from None


def _same(a: Spec, b: Spec) -> bool:
    return all(_strip(x) == _strip(y) for x, y in zip(_parts(a), _parts(b), strict=True))


def _strip(spec: Spec) -> Any:
    if isinstance(spec, MsgSpec):
        return (spec.name, tuple((f.name, f.type) for f in spec.fields),
                tuple((c.name, c.type, c.value) for c in spec.constants))
    return spec.name


def _describe(spec: Spec) -> str:
    lines = []
    for part in _parts(spec):
        if isinstance(part, MsgSpec):
            body = "; ".join([*(f"{c.type} {c.name}={c.value!r}" for c in part.constants),
                              *(f"{f.type} {f.name}" for f in part.fields)])
            lines.append(f"  {part.name}: {body}")
    return "\n".join(lines)


def register_msg(text: str, name: str) -> type:
    """Register .msg ``text`` as message type ``name`` (``pkg/msg/Name``); returns its class."""
    return _register(text, name, "msg")


def register_srv(text: str, name: str) -> type:
    """Register .srv ``text`` as service type ``name`` (``pkg/srv/Name``); returns its class."""
    return _register(text, name, "srv")


def register_action(text: str, name: str) -> type:
    """Register .action ``text`` as ``name`` (``pkg/action/Name``); returns its class."""
    return _register(text, name, "action")


def register_file(path: str | Path) -> type:
    """Register a ``<pkg>/msg|srv|action/<Name>.<ext>`` file; returns the class."""
    p = Path(path)
    kind = p.suffix[1:]
    if kind not in _KINDS or len(p.parts) < 3 or p.parent.name != kind:
        raise ValueError(f"cannot infer the type name from {str(path)!r}: expected a path like "
                         "'<pkg>/msg/<Name>.msg', '<pkg>/srv/<Name>.srv' or "
                         "'<pkg>/action/<Name>.action'")
    name = f"{p.parent.parent.name}/{kind}/{p.stem}"
    return _register(p.read_text(encoding="utf-8"), name, kind)


def generation() -> int:
    """A number that changes whenever a definition is registered."""
    return _generation


def _bump() -> None:
    global _generation
    _generation += 1


def _known(name: str) -> Spec | None:
    try:
        return get_spec(name)
    except LookupError:
        return None


def register_many(definitions: list[tuple[str, str, str]]) -> list[str]:
    """Register ``(name, text, origin)`` definitions together; the names registered.

    The definitions may use one another in any order (a package's messages, or several
    packages that depend on each other). ``origin`` (a file path) starts every error.
    All or nothing: a parse error, a conflict with a known definition or a field type
    that is neither known nor among ``definitions`` registers none of them.
    """
    specs: list[tuple[Spec, str]] = []
    for name, text, origin in definitions:
        _check_name(name, name.split("/")[1] if name.count("/") == 2 else "msg")
        try:
            specs.append((_parse_text(text, name), origin))
        except ValueError as err:
            raise ValueError(f"{origin}: {err}") from None
    with _lock:
        new: list[tuple[Spec, str]] = []
        for spec, origin in specs:
            existing = _known(spec.name)
            if existing is None:
                new.append((spec, origin))
            elif not _same(existing, spec):
                raise ValueError(
                    f"{origin}: defines {spec.name} differently from the definition aiorobot already "
                    f"has:\n{_describe(existing)}\nthis file:\n{_describe(spec)}\n"
                    "A package may not redefine a type of another (aiorobot ships ROS 2 Jazzy's).")
        for spec, _ in new:
            _install(spec)
        for spec, origin in new:
            for part in _parts(spec):
                if not isinstance(part, MsgSpec):
                    continue
                for dep in part.dependencies():
                    if not exists(dep):
                        for undo, _ in new:
                            for p in _parts(undo):
                                _specs.pop(p.name, None)
                        pkg, _, short = dep.split("/")
                        if pkg in {s.name.split("/", 1)[0] for s, _ in new}:
                            raise LookupError(f"{origin}: {spec.name} uses {dep}, which is unknown: "
                                              f"package {pkg!r} has no msg/{short}.msg")
                        raise LookupError(
                            f"{origin}: {spec.name} uses {dep}, which is unknown; add the folder of "
                            f"package {pkg!r} too (or register that type first)")
        _bump()
    return [spec.name for spec, _ in specs]


def rebuild(msgtype: str, values: tuple[Any, ...]) -> Any:
    """Pickle support: rebuild a message from its type name and field values."""
    return get(msgtype)(*values)
