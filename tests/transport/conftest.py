from __future__ import annotations

from collections.abc import Iterator

import pytest

from ._helpers import free_port, open_router


@pytest.fixture
def router_port() -> Iterator[int]:
    port = free_port()
    router = open_router(port)
    try:
        yield port
    finally:
        router.close()
