"""``BagReplay``: the ``bag_replay`` fixture, a regression test against a recorded bag in three lines::

    async def test_ekf_still_matches_the_recording(bag_replay):
        await bag_replay.assert_matches("tests/data/run1", functools.partial(EkfNode, parameter_overrides=P))

It is :func:`aiorobot.bag.check_bag` (lock-step replay of the bag's inputs on sim time, field
by field comparison of the outputs), with the report table as the assertion message.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

__all__ = ["BagReplay"]


class BagReplay:
    """Replays bags into nodes for tests; each node is given as a callable that builds it (a class, a ``partial``)."""

    def __repr__(self) -> str:
        return "<BagReplay>"

    async def __call__(
        self,
        path: str | Path,
        *nodes: Callable[[], Any],
        tolerances: Sequence[str] = (),
        outputs: Sequence[str] | None = None,
    ) -> Any:
        """The :class:`aiorobot.bag.CheckResult` of replaying ``path`` into ``nodes``."""
        from aiorobot.bag import check_bag

        if not nodes:
            raise TypeError("bag_replay: expected at least one node factory (a Node class or a callable that builds one)")
        return await check_bag(str(path), nodes, tolerances=tolerances, outputs=outputs)

    async def assert_matches(
        self,
        path: str | Path,
        *nodes: Callable[[], Any],
        tolerances: Sequence[str] = (),
        outputs: Sequence[str] | None = None,
    ) -> Any:
        """Replay and fail the test, with the report table, unless every output matches within tolerance."""
        result = await self(path, *nodes, tolerances=tolerances, outputs=outputs)
        if not result.passed:
            raise AssertionError(result.table())
        return result
