"""Every Numba kernel the demo's nodes call is compiled (or loaded) when the nodes are built, not
inside a callback, where a first run after installing stalls the loop for seconds (issue 25).

A kernel compiles once per argument-type signature (dtype, dimensions, layout, read-only-ness),
so the check is that a whole mission adds no signature to any kernel after the graph was built.
"""

from __future__ import annotations

import sys

import numba
import numpy as np
import pytest
from numba.core.registry import CPUDispatcher

from aiorobot import compile_kernels
from aiorobot.demo import run_demo
from aiorobot.demo._graph import build_graph
from aiorobot.sim import World

pytestmark = pytest.mark.timeout(300)


def kernels() -> dict[str, CPUDispatcher]:
    """Every Numba dispatcher in aiorobot's loaded modules (module globals and kernel caches)."""
    found: dict[str, CPUDispatcher] = {}
    for name, module in list(sys.modules.items()):
        if not name.startswith("aiorobot.") or module is None:
            continue
        for attr, value in vars(module).items():
            values = value.items() if isinstance(value, dict) else [(attr, value)]
            for key, obj in values:
                if isinstance(obj, CPUDispatcher):
                    found[f"{name}.{key}"] = obj
    return found


def signatures() -> dict[str, set[tuple[object, ...]]]:
    return {name: set(kernel.signatures) for name, kernel in kernels().items()}


async def test_a_mission_compiles_no_kernel_after_the_graph_is_built() -> None:
    build_graph(World.load("box"), rtf=0.0, seed=2, drive="direct", localisation="amcl", perception=True,
                record=None, time_source=None)
    built = signatures()
    assert {"aiorobot.nav._kernels.astar", "aiorobot.fusion._kernels.correct_inplace",
            "aiorobot.sim._raycast_kernel.cast_rays", "aiorobot.perception._scan.segment"} <= set(built)
    summary = await run_demo("box", [(1.0, 0.0, 0.0)], seed=2, timeout_sim_sec=60.0)
    assert summary.waypoints_reached == 1, summary.figures()
    after = signatures()
    grown = {name: after[name] - built.get(name, set()) for name in after if after[name] - built.get(name, set())}
    assert grown == {}, f"compiled inside a callback, not at construction: {grown}"


class Logger:
    def __init__(self) -> None:
        self.lines: list[str] = []

    def info(self, line: str) -> None:
        self.lines.append(line)


def test_compile_kernels_says_nothing_when_the_calls_are_quick() -> None:
    logger, calls = Logger(), []
    compile_kernels(logger, lambda: calls.append(1), lambda: calls.append(2), announce_after_sec=60.0)
    assert calls == [1, 2] and logger.lines == []


def test_compile_kernels_announces_a_long_compile_and_its_duration() -> None:
    @numba.njit(cache=False)
    def double(x):  # pragma: no cover - compiled
        return 2.0 * x

    logger = Logger()
    compile_kernels(logger, lambda: double(np.ones(3)), announce_after_sec=0.0)
    assert logger.lines[0] == "compiling kernels (first run only) ..."
    assert len(logger.lines) == 2 and logger.lines[1].startswith("compiling kernels (first run only) ... ")
    assert logger.lines[1].endswith(" s")
    assert np.float64(2.0) * 3 == double(np.ones(3)).sum()
