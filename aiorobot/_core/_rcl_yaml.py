"""YAML as rcl reads it for parameters (``rcl_yaml_param_parser``), not as PyYAML's YAML 1.1 does.

rcl types each scalar itself (``parse.c``, ``get_value``), in this order:

1. tagged ``!!str`` or quoted (``'...'``, ``"..."``): a string;
2. ``y Y yes Yes YES true True TRUE on On ON`` (and the ``n``/``no``/``false``/``off`` forms): a bool;
3. what C's ``strtoll(text, base 0)`` reads whole: an integer (``0x1F`` is 31, ``010`` is 8);
4. ``.nan``/``.inf`` and their case/sign forms, or what ``strtod`` reads whole: a double, so
   ``1e-9`` (no dot), ``5.``, ``.5``, ``inf`` and ``0x1p3`` are doubles;
5. anything else, ``null`` and ``~`` included: a string.

PyYAML differs exactly where ROS 2 files live: it reads ``1e-9`` as a string (YAML 1.1 wants a
dot), ``1_000`` as an int, ``null`` as nothing, ``y`` as a string and ``2024-01-01`` as a date.
Keys are always strings; aliases are refused, as rcl refuses them. Out-of-range numbers are
strings, as ``strtod`` and ``strtoll`` report ``ERANGE`` (an integer too large for int64 is read
as a double first).
"""

from __future__ import annotations

import math
import re
import sys
from typing import Any

__all__ = ["NoValue", "Pairs", "load_yaml", "parse_yaml_value", "rcl_scalar"]

_TRUE = frozenset("Y y yes Yes YES true True TRUE on On ON".split())
_FALSE = frozenset("N n no No NO false False FALSE off Off OFF".split())
_SPECIAL = {
    **{s: math.nan for s in (".nan", ".NaN", ".NAN")},
    **{p + s: math.inf for p in ("", "+") for s in (".inf", ".Inf", ".INF")},
    **{"-" + s: -math.inf for s in (".inf", ".Inf", ".INF")},
}
_SPACE = " \t\n\v\f\r"  # what strtoll/strtod skip before a number
_INT = re.compile(r"[+-]?(?:0[xX][0-9a-fA-F]+|0[0-7]*|[1-9][0-9]*)")
_DEC = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_HEX = re.compile(r"[+-]?0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?")
_INF_NAN = re.compile(r"([+-]?)(?:(inf(?:inity)?)|nan(?:\([0-9A-Za-z_]*\))?)", re.IGNORECASE)
_INT64 = (-(2**63), 2**63 - 1)


class NoValue:
    """A key written with no value (``key:``), which rcl refuses ("No value at line N")."""

    def __init__(self, line: int) -> None:
        self.line = line

    def __repr__(self) -> str:
        return f"<no value at line {self.line}>"


class Pairs(list):  # type: ignore[type-arg]
    """A YAML mapping as ``(key, value, line)`` triples, repeated keys included (rcl keeps the last)."""


def _strtoll(text: str) -> int | None:
    body = text.lstrip(_SPACE)
    if not _INT.fullmatch(body):
        return None
    sign = -1 if body.startswith("-") else 1
    digits = body.lstrip("+-")
    if digits[:2] in ("0x", "0X"):
        value = int(digits[2:], 16)
    elif len(digits) > 1 and digits[0] == "0":
        value = int(digits, 8)
    else:
        value = int(digits)
    value *= sign
    return value if _INT64[0] <= value <= _INT64[1] else None  # ERANGE: try strtod


def _strtod(text: str) -> float | None:
    body = text.lstrip(_SPACE)
    if _DEC.fullmatch(body):
        value, mantissa = float(body), re.split("[eE]", body)[0]
    elif _HEX.fullmatch(body):
        value, mantissa = float.fromhex(body), re.split("[pP]", body)[0].lstrip("+-")[2:]
    elif m := _INF_NAN.fullmatch(body):
        if not m.group(2):
            return math.nan
        return -math.inf if m.group(1) == "-" else math.inf
    else:
        return None
    if math.isinf(value):
        return None  # overflow: ERANGE
    if abs(value) < sys.float_info.min and any(c not in "0.+-" for c in mantissa):
        return None  # underflow to zero or a subnormal: ERANGE
    return value


def rcl_scalar(text: str, *, quoted: bool = False) -> bool | int | float | str:
    """One scalar typed as rcl's ``get_value`` types it; ``quoted`` for quoted or ``!!str`` scalars."""
    if quoted:
        return text
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    as_int = _strtoll(text)
    if as_int is not None:
        return as_int
    if text in _SPECIAL:
        return _SPECIAL[text]
    as_float = _strtod(text)
    if as_float is not None:
        return as_float
    return text


_loader_class: Any = None


def _loader() -> Any:
    global _loader_class
    if _loader_class is not None:
        return _loader_class
    import yaml
    from yaml.composer import Composer, ComposerError
    from yaml.constructor import ConstructorError, SafeConstructor
    from yaml.parser import Parser
    from yaml.reader import Reader
    from yaml.resolver import BaseResolver
    from yaml.scanner import Scanner

    plain_tag = "tag:aiorobot,2024:rcl-plain"
    str_tag = "tag:yaml.org,2002:str"

    class RclResolver(BaseResolver):
        def resolve(self, kind: Any, value: Any, implicit: Any) -> Any:
            if kind is yaml.ScalarNode and implicit[0]:
                return plain_tag  # untagged plain scalar: typed by rcl's rules
            return super().resolve(kind, value, implicit)

    class RclComposer(Composer):
        def compose_node(self, parent: Any, index: Any) -> Any:
            if self.check_event(yaml.AliasEvent):
                event = self.peek_event()
                raise ComposerError(None, None, "aliases are not supported (rcl refuses them)", event.start_mark)
            return super().compose_node(parent, index)

    class RclLoader(Reader, Scanner, Parser, RclComposer, SafeConstructor, RclResolver):
        yaml_constructors: dict[Any, Any] = {}

        def __init__(self, stream: Any) -> None:
            Reader.__init__(self, stream)
            Scanner.__init__(self)
            Parser.__init__(self)
            RclComposer.__init__(self)
            SafeConstructor.__init__(self)
            RclResolver.__init__(self)

    def scalar(loader: Any, node: Any) -> Any:
        if node.tag == plain_tag and node.value == "" and node.style is None:
            return NoValue(node.start_mark.line + 1)
        quoted = node.tag == str_tag or node.style in ("'", '"')
        return rcl_scalar(node.value, quoted=quoted)

    def any_node(loader: Any, node: Any) -> Any:
        if isinstance(node, yaml.ScalarNode):
            return scalar(loader, node)
        if isinstance(node, yaml.SequenceNode):
            return [loader.construct_object(child, deep=True) for child in node.value]
        out = Pairs()
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):
                raise ConstructorError(None, None, "expected a name as key, found a list or mapping", key.start_mark)
            out.append((key.value, loader.construct_object(value, deep=True), key.start_mark.line + 1))
        return out

    RclLoader.add_constructor(None, any_node)  # every tag: rcl looks only for !!str
    RclLoader.add_constructor(plain_tag, scalar)
    RclLoader.add_constructor(str_tag, scalar)
    _loader_class = RclLoader
    return RclLoader


def load_yaml(text: str) -> Any:
    """The document in ``text`` with rcl's scalar types: mappings as :class:`Pairs`, lists, scalars.

    Raises ``yaml.YAMLError`` for invalid YAML (and aliases).
    """
    import yaml

    return yaml.load(text, Loader=_loader())  # noqa: S506 - no object construction: every tag builds plain data


def parse_yaml_value(text: str) -> Any:
    """A ``-p name:=value`` value as rcl reads it (``rcl_parse_yaml_value``): a scalar or a flat list.

    ``ValueError`` for a mapping, a nested list or invalid YAML, saying what was expected.
    """
    import yaml

    if text == "":
        return ""  # aiorobot: an empty string (rcl refuses the rule)
    try:
        value = load_yaml(text)
    except yaml.YAMLError as err:
        raise ValueError(f"expected a YAML value, found {text!r} ({getattr(err, 'problem', err)})") from None
    if isinstance(value, Pairs):
        raise ValueError(f"expected a value or a [list], found a mapping {text!r}")
    if isinstance(value, NoValue) or value is None:
        return ""
    if isinstance(value, list):
        if any(isinstance(v, (list, Pairs)) for v in value):
            raise ValueError(f"expected a flat list, found {text!r}")
        return homogeneous(value, text)
    return value


def homogeneous(values: list[Any], where: str) -> list[Any]:
    """``values`` as rcl accepts a sequence: one type; ints among doubles become doubles (aiorobot's
    leniency, as in TOML; rcl refuses the mix). ``ValueError`` naming the types otherwise."""
    kinds = {_kind(v) for v in values}
    if len(kinds) <= 1:
        return values
    if kinds == {"integer", "double"}:
        return [float(v) for v in values]
    raise ValueError(f"expected a list of one type (as rcl), found {' and '.join(sorted(kinds))} values in {where}")


def _kind(value: Any) -> str:
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "double"
    return "string"
