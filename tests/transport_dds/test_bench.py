"""The bench's DDS rows: both processes meet, every path delivers, the table gives the ratios."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.timeout(120)


def test_the_dds_bench_measures_aiorobot_and_both_bare_pairs() -> None:
    from aiorobot.bench import _dds

    part = _dds.run(quick=True)
    assert "error" not in part, part
    for key in ("twist", "bare_twist", "typed_twist", "image", "bare_image", "typed_image"):
        assert part[key]["n"] > 0 and part[key]["p50_us"] > 0, key
    assert part["discovery_sec"] > 0 and "noise" in part
    table = _dds.table(part)
    assert [c.header for c in table.columns] == [
        "message", "aiorobot p50 us", "bare bytes p50 us", "ratio", "bare IdlStruct p50 us", "ratio"]
