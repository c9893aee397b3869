"""ROS 2 names: validation, expansion of relative and private names, remapping.

Rules follow rcl (``rcl_expand_topic_name``, ``rmw_validate_full_topic_name``,
``rmw_validate_node_name``, ``rmw_validate_namespace``):

* a name is made of tokens separated by ``/``; a token is ``[A-Za-z_][A-Za-z0-9_]*``
  (after expansion no token may start with a digit);
* ``/x`` is absolute, ``x`` is relative to the node's namespace, ``~/x`` (or ``~``)
  is private to the node: ``<namespace>/<node>/x``;
* ``{node}`` and ``{ns}`` / ``{namespace}`` are substituted;
* no empty tokens (``//``), no trailing ``/``.
"""

from __future__ import annotations

from collections.abc import Mapping

from ._errors import InvalidNameError

__all__ = [
    "expand_name",
    "join_fqn",
    "resolve_name",
    "validate_namespace",
    "validate_node_name",
]


def _is_token_char(ch: str) -> bool:
    return ch == "_" or ("a" <= ch <= "z") or ("A" <= ch <= "Z") or ("0" <= ch <= "9")


def validate_node_name(name: str) -> str:
    if not isinstance(name, str):
        raise TypeError(f"node name must be a str, got {name!r}")
    if not name:
        raise InvalidNameError("node", name, "must not be empty")
    if name[0].isdigit():
        raise InvalidNameError("node", name, "must not start with a digit", 0)
    for i, ch in enumerate(name):
        if not _is_token_char(ch):
            raise InvalidNameError(
                "node", name, f"character {ch!r} is not allowed (letters, digits and '_' only)", i
            )
    return name


def validate_namespace(namespace: str) -> str:
    """Validate and normalise a namespace to absolute form (``""`` -> ``"/"``, ``"ns"`` -> ``"/ns"``)."""
    if not isinstance(namespace, str):
        raise TypeError(f"namespace must be a str, got {namespace!r}")
    ns = namespace if namespace.startswith("/") else "/" + namespace
    if ns == "/":
        return ns
    if ns.endswith("/"):
        raise InvalidNameError("namespace", namespace, "must not end with '/'", len(namespace) - 1)
    _check_tokens("namespace", ns, namespace, offset=len(namespace) - len(ns))
    return ns


def _check_tokens(kind: str, full: str, original: str, offset: int) -> None:
    """Check an absolute name's tokens; report positions in ``original`` (shifted by offset)."""
    start = 1
    while start <= len(full):
        end = full.find("/", start)
        if end == -1:
            end = len(full)
        token = full[start:end]
        pos = max(start + offset, 0)
        if not token:
            raise InvalidNameError(kind, original, "empty token ('//' or trailing '/')", pos)
        if token[0].isdigit():
            raise InvalidNameError(kind, original, "a token must not start with a digit", pos)
        for i, ch in enumerate(token):
            if not _is_token_char(ch):
                raise InvalidNameError(
                    kind,
                    original,
                    f"character {ch!r} is not allowed (letters, digits, '_' and '/' only)",
                    max(start + i + offset, 0),
                )
        start = end + 1


def join_fqn(namespace: str, name: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


def expand_name(name: str, node_name: str, namespace: str, kind: str = "topic") -> str:
    """Expand a topic or service name to its fully qualified form and validate it."""
    if not isinstance(name, str):
        raise TypeError(f"{kind} name must be a str, got {name!r}")
    if not name:
        raise InvalidNameError(kind, name, "must not be empty")
    for i, ch in enumerate(name):
        if not (_is_token_char(ch) or ch in "/~{}"):
            raise InvalidNameError(
                kind,
                name,
                f"character {ch!r} is not allowed (letters, digits, '_', '/', '~' and {{}} only)",
                i,
            )
    tilde = name.find("~")
    if tilde > 0:
        raise InvalidNameError(kind, name, "'~' is only allowed at the start", tilde)
    if name.startswith("~") and len(name) > 1 and name[1] != "/":
        raise InvalidNameError(kind, name, "'~' must be followed by '/'", 1)
    if len(name) > 1 and name.endswith("/"):
        raise InvalidNameError(kind, name, "must not end with '/'", len(name) - 1)

    ns = namespace.rstrip("/")
    expanded = name
    if "{" in expanded or "}" in expanded:
        expanded = (
            expanded.replace("{node}", node_name)
            .replace("{namespace}", ns)
            .replace("{ns}", ns)
        )
        brace = next((i for i, ch in enumerate(expanded) if ch in "{}"), None)
        if brace is not None:
            pos = name.find("{") if "{" in name else name.find("}")
            raise InvalidNameError(
                kind, name, "unknown substitution (known: {node}, {ns}, {namespace})", pos
            )
    if expanded.startswith("~"):
        expanded = f"{ns}/{node_name}{expanded[1:]}"
    elif not expanded.startswith("/"):
        expanded = f"{ns}/{expanded}"
    if expanded == "/":
        raise InvalidNameError(kind, name, "must name something below '/'")
    if name.startswith("/") or name.startswith("~") or "{" in name:
        offset = None
    else:
        offset = len(name) - len(expanded)
    try:
        _check_tokens(kind, expanded, name, offset if offset is not None else 0)
    except InvalidNameError as err:
        if offset is None:
            # The error lies in a substituted part: point at the expanded name instead.
            raise InvalidNameError(kind, expanded, err.reason, err.index) from None
        raise
    return expanded


def resolve_name(
    name: str,
    node_name: str,
    namespace: str,
    remappings: Mapping[str, str],
    kind: str = "topic",
) -> str:
    """Expand ``name`` and apply the first remapping rule whose (expanded) source matches."""
    expanded = expand_name(name, node_name, namespace, kind)
    for source, target in remappings.items():
        if source.startswith("__"):
            continue
        if expand_name(source, node_name, namespace, kind) == expanded:
            return expand_name(target, node_name, namespace, kind)
    return expanded
