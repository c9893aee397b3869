from __future__ import annotations

from collections.abc import AsyncIterator

import pytest

from ._helpers import BarePeer, fresh_domain


@pytest.fixture
def domain_id() -> int:
    return fresh_domain()


@pytest.fixture
async def peer(domain_id: int) -> AsyncIterator[BarePeer]:
    async with await BarePeer.start(domain_id) as p:
        yield p
