from __future__ import annotations

from tests.transport.conftest import router_port

__all__ = ["router_port"]
