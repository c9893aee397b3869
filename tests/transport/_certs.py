"""Throwaway certificates for TLS tests, made with the openssl command line (about 0.1 s)."""

from __future__ import annotations

import json
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Pki", "make_pki", "router_config", "session_config"]

_EXT = "subjectAltName=DNS:localhost,IP:127.0.0.1\nbasicConstraints=CA:FALSE\nextendedKeyUsage=serverAuth,clientAuth\n"


@dataclass(frozen=True)
class Pki:
    """A CA, a router certificate and two client certificates it signed, and one self-signed pair."""

    dir: Path

    def pem(self, name: str) -> str:
        return str(self.dir / f"{name}.pem")

    def key(self, name: str) -> str:
        return str(self.dir / f"{name}.key")


def _openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True)


def make_pki(directory: Path) -> Pki:
    if shutil.which("openssl") is None:
        raise RuntimeError("the TLS tests need the openssl command line")
    d = directory
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes")
    _openssl("req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", "/CN=aiorobot-test-ca", cwd=d)
    (d / "leaf.ext").write_text(_EXT)
    for name in ("router", "alice", "bob"):
        _openssl("req", *ec, "-keyout", f"{name}.key", "-out", f"{name}.csr", "-subj", f"/CN={name}", cwd=d)
        _openssl("x509", "-req", "-in", f"{name}.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
                 "-out", f"{name}.pem", "-days", "2", "-extfile", "leaf.ext", cwd=d)
    _openssl("req", "-x509", *ec, "-keyout", "mallory.key", "-out", "mallory.pem", "-days", "2", "-subj", "/CN=mallory",
             "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1", cwd=d)
    return Pki(d)


#: zenoh access control: nobody publishes or subscribes under <domain>/secret/**
DENY_SECRET = {
    "enabled": True,
    "default_permission": "allow",
    "rules": [{
        "id": "no_secret",
        "messages": ["put", "delete", "declare_subscriber", "query", "reply", "declare_queryable"],
        "flows": ["ingress", "egress"],
        "permission": "deny",
        "key_exprs": ["*/secret/**"],
    }],
    "subjects": [{"id": "everyone", "interfaces": ["lo"]}],
    "policies": [{"rules": ["no_secret"], "subjects": ["everyone"]}],
}


def router_config(pki: Pki, port: int, path: Path, *, acl: bool = True) -> Path:
    """A router listening only on tls/127.0.0.1:port, with mTLS (and the /secret ACL)."""
    cfg: dict = {
        "mode": "router",
        "listen": {"endpoints": [f"tls/127.0.0.1:{port}"]},
        "scouting": {"multicast": {"enabled": False}},
        "transport": {"link": {"tls": {
            "root_ca_certificate": pki.pem("ca"),
            "listen_certificate": pki.pem("router"),
            "listen_private_key": pki.key("router"),
            "enable_mtls": True,
        }}},
    }
    if acl:
        cfg["access_control"] = DENY_SECRET
    path.write_text(json.dumps(cfg, indent=1))
    return path


def session_config(
    pki: Pki, port: int, path: Path, *, mode: str = "client", cert: str | None = "alice", listen: list[str] | None = None,
    tls: bool = True,
) -> Path:
    """A session connecting to the router at port: over TLS with ``cert`` (None: no client
    certificate), or over plain tcp when ``tls`` is false. ``listen`` None leaves zenoh's default."""
    cfg: dict = {
        "mode": mode,
        "connect": {"endpoints": [f"{'tls' if tls else 'tcp'}/127.0.0.1:{port}"]},
        "scouting": {"multicast": {"enabled": False}},
    }
    if listen is not None:
        cfg["listen"] = {"endpoints": listen}
    if tls:
        link: dict = {"root_ca_certificate": pki.pem("ca")}
        if cert is not None:
            link.update(enable_mtls=True, connect_certificate=pki.pem(cert), connect_private_key=pki.key(cert))
        cfg["transport"] = {"link": {"tls": link}}
    path.write_text(json.dumps(cfg, indent=1))
    return path
