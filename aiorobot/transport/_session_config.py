"""A zenoh session's config: built the way rmw_zenoh builds it, then checked before zenoh opens.

The pure half reads a built ``zenoh.Config`` back into a :class:`SessionPlan` (mode,
the endpoints it will really listen on and connect to, TLS and access-control settings)
and checks it: every certificate and key path names a readable PEM file, and a config that
secures the session (TLS endpoints or certificates, or access control) has no plain
listener or connect endpoint (zenoh's peer default ``tcp/[::]:0`` included) unless the
user allowed that endpoint by name (``AIOROBOT_ZENOH_ALLOW_PLAIN``, ``allow_plain=``,
``aiorobot router --allow-plain``). Without that check, two peers holding valid
certificates find each other through gossip and talk over the plain listener, past TLS
and past the router's access control.

Every problem is a :class:`ZenohConfigError`: one line naming the file, the key (zenoh's
``a/b/c`` path, as ``ZENOH_CONFIG_OVERRIDE`` spells it) and what was expected and found.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._core._errors import ConfigError

__all__ = [
    "ALLOW_PLAIN_ENV",
    "SECURE_SCHEMES",
    "TLS_FILE_KEYS",
    "SessionPlan",
    "ZenohConfigError",
    "ZenohSessionError",
    "allowed_plain",
    "apply_overrides",
    "check_plan",
    "check_session_file",
    "load_config_file",
    "plan_of",
    "zenoh_error_text",
]

#: endpoints named here (comma or semicolon separated) may stay plain in a secured config
ALLOW_PLAIN_ENV = "AIOROBOT_ZENOH_ALLOW_PLAIN"
#: link protocols that carry TLS
SECURE_SCHEMES = frozenset({"tls", "quic"})
#: ``transport/link/tls`` keys that name files (zenoh reads them relative to the working directory)
TLS_FILE_KEYS = (
    "root_ca_certificate",
    "listen_certificate",
    "listen_private_key",
    "connect_certificate",
    "connect_private_key",
)
_TLS = "transport/link/tls"


class ZenohConfigError(ConfigError, ValueError):
    """A zenoh config that cannot be used: ``path`` is the zenoh file (or the variable naming
    the setting), ``key`` zenoh's key path inside it. Nothing was opened. A ``ValueError`` too,
    as the transport's config errors were before."""


class ZenohSessionError(RuntimeError):
    """zenoh refused to open the session (a client that reached no router, a certificate
    rejected): one line naming the endpoints and why."""


@dataclass(frozen=True, slots=True)
class SessionPlan:
    """What a built config will do, read back from zenoh's own parse of it."""

    #: where the config came from: a file path, or ``"the default session config"``
    source: str
    mode: str
    #: the endpoints zenoh will listen on (the mode's default when the config sets none)
    listen: tuple[str, ...]
    connect: tuple[str, ...]
    #: ``listen`` is zenoh's default for the mode, not set by the config
    listen_is_default: bool
    #: ``transport/link/tls``: the keys that are set
    tls: Mapping[str, Any]
    access_control: bool

    @property
    def secure(self) -> str | None:
        """What secures this config (``TLS (transport/link/tls)``, ...), or None."""
        for kind, endpoints in (("listen", self.listen), ("connect", self.connect)):
            for ep in endpoints:
                if scheme(ep) in SECURE_SCHEMES:
                    return f"TLS ({kind}/endpoints has {ep})"
        if any(self.tls.get(k) for k in (*TLS_FILE_KEYS, *(k + "_base64" for k in TLS_FILE_KEYS), "enable_mtls")):
            return f"TLS ({_TLS})"
        if self.access_control:
            return "access control (access_control/enabled)"
        return None


def scheme(endpoint: str) -> str:
    return endpoint.split("/", 1)[0].strip().lower()


def zenoh_error_text(err: BaseException) -> str:
    """zenoh's error message on one line, without the Rust source location and parser art."""
    text = str(err)
    text = re.sub(r"\s+at /\S+\.rs:\d+\.?", "", text).strip()
    pest = re.search(r"-->\s*(\d+):(\d+).*?=\s*(.+)$", text, re.S)
    if pest:  # a JSON5 syntax error, drawn as a caret under the line
        return f"line {pest[1]}, column {pest[2]}: not valid JSON5 ({pest[3].strip()})"
    serde = re.search(r'msg: "(.*?)", location: Some\(Location \{ line: (\d+), column: (\d+)', text, re.S)
    if serde:
        return f"line {serde[2]}, column {serde[3]}: {serde[1]}"
    serde = re.search(r'msg: "(.*?)", location: None', text, re.S)
    if serde:
        return serde[1]
    return " ".join(text.split())


def load_config_file(path: str, *, named_by: str | None = None) -> Any:
    """``zenoh.Config.from_file`` with one-line errors naming ``path``."""
    import zenoh

    where = f" (named by {named_by})" if named_by else ""
    resolved = Path(path).expanduser()
    if not resolved.is_file():
        raise ZenohConfigError(path, None, f"expected a zenoh config file (JSON5){where}, found no file at {resolved.resolve()}")
    try:
        return zenoh.Config.from_file(str(resolved))
    except Exception as err:  # noqa: BLE001 - zenoh raises ZError for every parse problem
        raise ZenohConfigError(path, None, zenoh_error_text(err) + where) from None


def apply_overrides(cfg: Any, override: str) -> None:
    """``ZENOH_CONFIG_OVERRIDE`` (``key=value;key=value``), applied last as in rmw_zenoh."""
    for item in filter(None, (part.strip() for part in override.split(";"))):
        key, sep, value = item.partition("=")
        if not sep:
            raise ZenohConfigError("ZENOH_CONFIG_OVERRIDE", None, f"expected key=value, found {item!r}")
        try:
            cfg.insert_json5(key.strip(), value.strip())
        except Exception as err:  # noqa: BLE001
            raise ZenohConfigError(
                "ZENOH_CONFIG_OVERRIDE", key.strip(), f"cannot set it to {value.strip()!r}: {zenoh_error_text(err)}"
            ) from None


def _get(cfg: Any, key: str) -> Any:
    try:
        return json.loads(cfg.get_json(key))
    except Exception:  # noqa: BLE001 - a key this zenoh version lacks
        return None


def _for_mode(value: Any, mode: str) -> list[str]:
    """``listen``/``connect`` endpoints: a list, or a per-mode table (zenoh's defaults are one)."""
    if isinstance(value, Mapping):
        value = value.get(mode) or []
    return [str(v) for v in value or []]


def plan_of(cfg: Any, source: str, *, default_mode: str = "peer") -> SessionPlan:
    """Read a built config back: what the session will listen on and connect to."""
    import zenoh

    mode = _get(cfg, "mode") or default_mode
    listen = _for_mode(_get(cfg, "listen/endpoints"), mode)
    default_listen = _for_mode(_get(zenoh.Config(), "listen/endpoints"), mode)
    tls = {k: v for k, v in (_get(cfg, _TLS) or {}).items() if v is not None}
    for key in TLS_FILE_KEYS:  # the base64 variants are not in the table's JSON
        value = _get(cfg, f"{_TLS}/{key}_base64")
        if value:
            tls[key + "_base64"] = value
    return SessionPlan(
        source=source,
        mode=mode,
        listen=tuple(listen),
        connect=tuple(_for_mode(_get(cfg, "connect/endpoints"), mode)),
        listen_is_default=listen == default_listen,
        tls=tls,
        access_control=bool(_get(cfg, "access_control/enabled")),
    )


def allowed_plain(extra: Iterable[str] = ()) -> frozenset[str]:
    """Plain endpoints the user allowed in a secured config: ``extra`` and ``AIOROBOT_ZENOH_ALLOW_PLAIN``."""
    raw = os.environ.get(ALLOW_PLAIN_ENV, "")
    return frozenset(e.strip() for e in (*extra, *re.split(r"[,;]", raw)) if e.strip())


def check_plan(plan: SessionPlan, allow_plain: Iterable[str] = ()) -> None:
    """Raise :class:`ZenohConfigError` for the first problem: a certificate file that is not
    there, TLS endpoints without what they need, a plain endpoint in a secured config."""
    _check_tls_files(plan)
    reason = plan.secure
    if reason is None:
        return
    allowed = frozenset(allow_plain)
    for kind, endpoints in (("listen", plan.listen), ("connect", plan.connect)):
        for ep in endpoints:
            if scheme(ep) in SECURE_SCHEMES or ep in allowed:
                continue
            implied = (
                f" (zenoh's default for a {plan.mode} that sets no listen endpoints)"
                if kind == "listen" and plan.listen_is_default
                else ""
            )
            if kind == "connect":
                fix = "connect with tls/ endpoints only"
            elif plan.mode == "peer":
                fix = 'listen on tls/ endpoints only, or use mode "client" with listen/endpoints []'
            else:
                fix = "listen on tls/ endpoints only"
            raise ZenohConfigError(
                plan.source,
                f"{kind}/endpoints",
                f"the config enables {reason} but {'listens on' if kind == 'listen' else 'connects to'} "
                f"plain {ep}{implied}: other processes could reach it past TLS and access control; "
                f"{fix}, or allow it with {ALLOW_PLAIN_ENV}={ep}",
            )


def _check_tls_files(plan: SessionPlan) -> None:
    tls = plan.tls
    for key in TLS_FILE_KEYS:
        value = tls.get(key)
        if not value:
            continue
        path = Path(str(value)).expanduser()
        where = f"{_TLS}/{key}"
        if not path.is_file():
            hint = ""
            if not path.is_absolute() and plan.source and Path(plan.source).is_file():
                beside = Path(plan.source).resolve().parent / path
                if beside.is_file():
                    hint = f"; zenoh reads it relative to the working directory, not the config file: use {beside}"
            raise ZenohConfigError(plan.source, where, f"expected a PEM file, found no file at {path.resolve()}{hint}")
        try:
            head = path.read_bytes()[:65536]
        except OSError as err:
            raise ZenohConfigError(plan.source, where, f"cannot read {path.resolve()}: {err.strerror}") from None
        if b"-----BEGIN " not in head:
            raise ZenohConfigError(plan.source, where, f"expected a PEM file (-----BEGIN ...), found {path.resolve()} without one")
    def given(key: str) -> bool:
        return bool(tls.get(key) or tls.get(key + "_base64"))

    for side in ("listen", "connect"):
        cert, key = f"{side}_certificate", f"{side}_private_key"
        if given(cert) != given(key):
            missing, present = (key, cert) if given(cert) else (cert, key)
            raise ZenohConfigError(plan.source, f"{_TLS}/{missing}", f"expected it beside {_TLS}/{present}, found it unset")
    tls_listen = [ep for ep in plan.listen if scheme(ep) in SECURE_SCHEMES]
    if tls_listen and not given("listen_certificate"):
        raise ZenohConfigError(
            plan.source, f"{_TLS}/listen_certificate",
            f"listening on {tls_listen[0]} needs a certificate and key (listen_certificate, listen_private_key), found none",
        )
    tls_connect = [ep for ep in plan.connect if scheme(ep) in SECURE_SCHEMES]
    if tls_connect and tls.get("enable_mtls") and not given("connect_certificate"):
        raise ZenohConfigError(
            plan.source, f"{_TLS}/connect_certificate",
            f"enable_mtls is true and the session connects to {tls_connect[0]}, but it has no client certificate "
            "(connect_certificate, connect_private_key): an mTLS router would refuse it",
        )


def check_session_file(path: str) -> None:
    """Check a session config file as a session opening it would (``[runtime] zenoh_config``):
    it parses, its certificate files are there, and it does not leak past TLS."""
    from ._zenoh import build_session_config

    build_session_config(config_file=path)
