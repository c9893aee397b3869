"""Why a zenoh session did not connect to an endpoint, in words a user can act on.

zenoh-python only says "Unable to connect to any of [...]". When a connect endpoint
did not link, :func:`why_unreachable` asks the endpoint itself: a TCP connection (is
anything listening?) and, for ``tls/``, a TLS handshake with the session's own CA and
client certificate (is the router's certificate trusted? does the router accept ours?).
The probe runs only after a failure, costs one short-lived connection and is bounded
by ``timeout_sec``.
"""

from __future__ import annotations

import socket
import ssl
from collections.abc import Mapping
from typing import Any

__all__ = ["NOTHING_LISTENS", "host_port", "why_unreachable"]

#: the start of the reason when nothing answers at the endpoint
NOTHING_LISTENS = "nothing listens there"


def host_port(endpoint: str) -> tuple[str, int] | None:
    """``tls/host:port?meta#config`` -> ``("host", port)``; None for a non-IP endpoint."""
    try:
        proto, _, rest = endpoint.partition("/")
        addr = rest.split("?", 1)[0].split("#", 1)[0]
        host, _, port = addr.rpartition(":")
        if proto.lower() not in {"tcp", "tls", "ws", "quic", "udp"} or not host:
            return None
        return host.strip("[]"), int(port)
    except ValueError:
        return None


def why_unreachable(endpoint: str, tls: Mapping[str, Any], *, timeout_sec: float = 2.0) -> str:
    """One clause saying why a session could not link to ``endpoint``."""
    target = host_port(endpoint)
    proto = endpoint.split("/", 1)[0].lower()
    if target is None or proto in {"udp", "quic"}:
        return "zenoh could not link to it"
    host, port = target
    try:
        raw = socket.create_connection((host, port), timeout=timeout_sec)
    except TimeoutError:
        return f"no answer within {timeout_sec:g} s (no router reachable: wrong host, or a firewall?)"
    except OSError as err:
        return f"{NOTHING_LISTENS} ({err.strerror or err}; no router reachable)"
    with raw:
        if proto == "tls":
            return _tls_verdict(raw, host, tls, timeout_sec)
        if _speaks_tls(raw, host, timeout_sec):
            return f"the listener there expects TLS: connect with tls/{host}:{port} and the router's CA"
        return "a listener answered but refused the zenoh session (access control, or another zenoh version?)"


def _tls_verdict(raw: socket.socket, host: str, tls: Mapping[str, Any], timeout_sec: float) -> str:
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    ctx.check_hostname = tls.get("verify_name_on_connect", True) is not False
    ca = tls.get("root_ca_certificate")
    try:
        if ca:
            ctx.load_verify_locations(str(ca))
        else:
            ctx.load_default_certs()
        cert, key = tls.get("connect_certificate"), tls.get("connect_private_key")
        if cert and key:
            ctx.load_cert_chain(str(cert), str(key))
    except (OSError, ssl.SSLError) as err:
        return f"the session's TLS files could not be loaded ({err})"
    has_cert = bool(tls.get("connect_certificate") or tls.get("connect_certificate_base64"))
    try:
        with ctx.wrap_socket(raw, server_hostname=host, do_handshake_on_connect=True) as s:
            s.settimeout(min(timeout_sec, 0.5))
            try:
                s.recv(1)  # TLS 1.3: a rejected client certificate arrives as an alert after the handshake
            except TimeoutError:
                pass
    except ssl.SSLCertVerificationError as err:
        if "mismatch" in (err.verify_message or ""):
            return (
                f"the router's certificate does not name {host} ({err.verify_message.rstrip('.')}): "
                "add it to the certificate's subjectAltName, or connect with the name it has"
            )
        return (
            f"the router's certificate is not trusted ({err.verify_message}); "
            f"root_ca_certificate {ca or '(system roots)'} must be the CA that signed it"
        )
    except ssl.SSLError as err:
        reason = (err.reason or str(err)).lower()
        if "certificate_required" in reason:
            return "certificate rejected: the router requires a client certificate (mTLS) and this session sent none"
        if any(word in reason for word in ("certificate", "unknown_ca", "bad_certificate", "decrypt")):
            what = "this session's client certificate" if has_cert else "this session"
            return f"certificate rejected: the router refused {what} ({reason.replace('_', ' ')}: not signed by a CA it trusts?)"
        if "wrong_version" in reason or "record" in reason:
            return "the listener there does not speak TLS (a plain tcp/ listener?)"
        return f"TLS handshake failed ({reason.replace('_', ' ')})"
    except OSError as err:
        return f"the router closed the connection during the TLS handshake ({err.strerror or err})"
    return "TLS was accepted but the router refused the zenoh session (access control, or another zenoh version?)"


def _speaks_tls(raw: socket.socket, host: str, timeout_sec: float) -> bool:
    """Does the listener behind a plain ``tcp/`` endpoint answer a TLS hello?"""
    ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    ctx.check_hostname = False
    ctx.verify_mode = ssl.CERT_NONE
    raw.settimeout(min(timeout_sec, 1.0))
    try:
        with ctx.wrap_socket(raw, server_hostname=host):
            return True
    except ssl.SSLError as err:
        return "alert" in str(err).lower()  # a TLS server that refused us still answered in TLS
    except OSError:
        return False
