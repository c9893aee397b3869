"""tf2's TimeCache, case by case from geometry2's tf2/test/cache_unittest.cpp. Pure, no runtime."""

from __future__ import annotations

import math

import numpy as np
import pytest

from aiorobot.tf._cache import TimeCache


def item(stamp: int, parent: int, x: float = 0.0):
    return stamp, (parent, x, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def insert(cache: TimeCache, it) -> bool:
    return cache.insert(it[0], it[1])


def items(cache: TimeCache):
    return list(zip(cache.stamps, cache.samples))


def test_get_all_items_sorting_and_pruning():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.GetAllItems
    cache = TimeCache(10)
    a, b, c, d = item(0, 0), item(10, 1), item(5, 2), item(3, 3)
    e, f, g = item(8, 4), item(8, 5), item(8, 6)  # same stamp, different parent
    for it in (a, b, c, d, e, f, g):
        insert(cache, it)
    assert cache.latest_stamp() - cache.oldest_stamp() == 10  # exactly the max storage time
    # tf2 keeps newest first; same stamps come out in reverse insertion order. Ours is oldest
    # first, so the same list reversed.
    expected = [a, d, c, e, f, g, b]
    assert items(cache) == expected
    for it in (g, f, e, d, c, b, a):  # repeated, in reverse: nothing changes
        insert(cache, it)
    assert items(cache) == expected
    h, i, j = item(15, 7), item(0, 8), item(5, 9)
    assert insert(cache, h) is True
    assert insert(cache, i) is False  # stale: dropped
    assert insert(cache, j) is True
    assert items(cache) == [c, j, e, f, g, b, h]  # a, d and i pruned


def test_repeatability():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.Repeatability
    cache = TimeCache(10_000_000_000)
    for i in range(1, 100):
        cache.insert(i, (i, 0, 0, 0, 0, 0, 0, 1))
    assert len(cache) == 99
    for i in range(1, 100):
        sample, _ = cache.get_data(i)
        assert sample[0] == i


def test_repeatability_reverse_insert_order():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.RepeatabilityReverseInsertOrder
    cache = TimeCache(10_000_000_000)
    for i in range(99, -1, -1):
        cache.insert(i, (i, 0, 0, 0, 0, 0, 0, 1))
    assert len(cache) == 100
    for i in range(1, 100):
        assert cache.get_data(i)[0][0] == i


def test_repeated_elements_are_stored_once():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.RepeatedElements and ::DuplicateEntries
    cache = TimeCache(10_000_000_000)
    assert len(cache) == 0
    for _ in range(99):
        cache.insert(1, (3, 0, 0, 0, 0, 0, 0, 1))
    assert len(cache) == 1
    sample, _ = cache.get_data(1)
    assert not any(math.isnan(v) for v in sample[1:])


def test_zero_at_front_is_the_latest():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.ZeroAtFront
    cache = TimeCache(10_000_000_000)
    for i in range(1, 101):
        cache.insert(i, (i, 0, 0, 0, 0, 0, 0, 1))
    for i in range(1, 100):
        assert cache.get_data(i)[0][0] == i
    assert cache.get_data(0)[0][0] == 100
    assert cache.latest_time_and_parent() == (100, 100)
    cache.insert(101, (100, 0, 0, 0, 0, 0, 0, 1))
    assert cache.latest_time_and_parent() == (101, 100)


def test_cartesian_interpolation():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.CartesianInterpolation
    rng = np.random.default_rng(42)
    cache = TimeCache(10_000_000_000)
    offset = 200
    for _ in range(20):
        values = 10.0 * rng.random((2, 3))
        for step in range(2):
            cache.insert(step * 100 + offset, (2, *values[step], 0.0, 0.0, 0.0, 1.0))
        for pos in range(100):
            sample, _ = cache.get_data(offset + pos)
            expected = values[0] + (values[1] - values[0]) * pos / 100.0
            assert sample[1:4] == pytest.approx(tuple(expected), abs=2e-6)
        cache.clear()


def test_reparenting_interpolation_protection():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.ReparentingInterpolationProtection
    rng = np.random.default_rng(7)
    cache = TimeCache(10_000_000_000)
    offset = 555
    values = 10.0 * rng.random((2, 3))
    for step in range(2):
        cache.insert(step * 100 + offset, (step + 4, *values[step], 0.0, 0.0, 0.0, 1.0))
    for pos in range(100):
        sample, error = cache.get_data(offset + pos)
        assert error == "" and sample[1:4] == pytest.approx(tuple(values[0]), abs=1e-6)


def test_angular_interpolation():
    # geometry2 tf2/test/cache_unittest.cpp::TimeCache.AngularInterpolation (yaw about z)
    cache = TimeCache(10_000_000_000)
    offset = 200
    yaws = (0.3, 1.1)
    for step, yaw in enumerate(yaws):
        cache.insert(step * 100 + offset, (3, 0, 0, 0, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))
    for pos in range(100):
        sample, _ = cache.get_data(offset + pos)
        yaw = yaws[0] + (yaws[1] - yaws[0]) * pos / 100.0
        assert sample[4:8] == pytest.approx((0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)), abs=1e-9)


def test_one_sample_older_than_the_cache_length_survives_until_the_next_insert():
    # geometry2 tf2/src/cache.cpp TimeCache::insertData: pruneList() runs before the insert, with the
    # newest stamp held so far, so interpolation at the cache boundary keeps working.
    cache = TimeCache(10)
    cache.insert(0, (1, 0.0, 0, 0, 0, 0, 0, 1))
    cache.insert(10, (1, 10.0, 0, 0, 0, 0, 0, 1))
    cache.insert(11, (1, 11.0, 0, 0, 0, 0, 0, 1))
    assert cache.oldest_stamp() == 0  # older than 11 - 10, still here
    assert cache.get_data(5)[0][1] == pytest.approx(5.0)
    cache.insert(12, (1, 12.0, 0, 0, 0, 0, 0, 1))  # prunes against 11: stamps < 1 go
    assert cache.oldest_stamp() == 10
    assert cache.insert(1, (1, 1.0, 0, 0, 0, 0, 0, 1)) is False  # older than 12 - 10
    assert cache.insert(2, (1, 2.0, 0, 0, 0, 0, 0, 1)) is True  # exactly the cache length: kept
