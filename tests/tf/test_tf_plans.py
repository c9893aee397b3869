"""Cached chain walks give what the full tf2 walk gives, and notice when the tree changes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _tf_helpers import q_of, tf, xyz_of, yaw_q

from aiorobot import Time
from aiorobot.tf import Buffer, ExtrapolationException, LookupException


def full_walk(buffer: Buffer, target: str, source: str, t_ns: int):
    """The uncached tf2 walk (BufferCore._walk), for reference."""
    with buffer._lock:
        tid, sid = buffer._ids[target], buffer._ids[source]
        _, vec, q = buffer._walk(tid, sid, t_ns, True)
    from aiorobot.tf._math import _canonical

    return vec, _canonical(q)


def random_q(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


@pytest.mark.parametrize("seed", range(3))
def test_cached_walks_match_the_full_walk_on_random_dynamic_trees(seed):
    rng = np.random.default_rng(seed)
    frames = ["f0"]
    buffer = Buffer(cache_time_sec=100.0)
    for i in range(1, 12):
        child, parent = f"f{i}", frames[rng.integers(len(frames))]
        frames.append(child)
        static = bool(rng.integers(2))
        stamps = [0.0] if static else sorted(rng.uniform(1, 9, size=4))
        for s in stamps:
            buffer.set_transform(tf(parent, child, s, rng.normal(size=3), random_q(rng)), "r", static=static)
    for _ in range(200):
        source, target = (str(f) for f in rng.choice(frames, size=2))
        t_ns = int(rng.uniform(1.1e9, 8.9e9))
        try:
            expected = full_walk(buffer, target, source, t_ns)
        except ExtrapolationException:
            with pytest.raises(ExtrapolationException):
                buffer.lookup_transform(target, source, Time(nanoseconds=t_ns))
            continue
        for _ in range(2):  # the first call traces the plan, the second replays it
            out = buffer.lookup_transform(target, source, Time(nanoseconds=t_ns))
            assert xyz_of(out) == pytest.approx(expected[0], abs=1e-12)
            assert q_of(out) == pytest.approx(expected[1], abs=1e-12)


def test_reparenting_after_a_cached_lookup_is_seen():
    b = Buffer()
    b.set_transform(tf("world", "a", 0, (1, 0, 0)), "t", static=True)
    b.set_transform(tf("world", "b", 0, (0, 5, 0)), "t", static=True)
    b.set_transform(tf("a", "c", 0, (0, 0, 1)), "t", static=True)
    assert xyz_of(b.lookup_transform("world", "c", Time())) == pytest.approx((1, 0, 1))
    b.set_transform(tf("b", "c", 0, (0, 0, 2)), "t", static=True)  # c moves under b
    assert xyz_of(b.lookup_transform("world", "c", Time())) == pytest.approx((0, 5, 2))


def test_a_root_that_gains_a_parent_is_seen():
    b = Buffer()
    b.set_transform(tf("odom", "base", 0, (1, 0, 0)), "t", static=True)
    assert xyz_of(b.lookup_transform("odom", "base", Time())) == pytest.approx((1, 0, 0))
    b.set_transform(tf("map", "odom", 0, (0, 2, 0), yaw_q(math.pi / 2)), "t", static=True)
    assert xyz_of(b.lookup_transform("map", "base", Time())) == pytest.approx((0, 3, 0))
    assert xyz_of(b.lookup_transform("odom", "base", Time())) == pytest.approx((1, 0, 0))


def test_time_varying_parents_fall_back_to_the_full_walk():
    # geometry2 buffer_core: a frame's parent is looked up at the requested time
    b = Buffer()
    b.set_transform(tf("world", "p1", 0, (1, 0, 0)), "t", static=True)
    b.set_transform(tf("world", "p2", 0, (2, 0, 0)), "t", static=True)
    b.set_transform(tf("p1", "c", 1, (0, 0, 0)), "t")
    b.set_transform(tf("p1", "c", 2, (0, 0, 0)), "t")
    b.set_transform(tf("p2", "c", 3, (0, 0, 0)), "t")
    b.set_transform(tf("p2", "c", 4, (0, 0, 0)), "t")
    assert xyz_of(b.lookup_transform("world", "c", Time(seconds=1.5)))[0] == pytest.approx(1)
    assert xyz_of(b.lookup_transform("world", "c", Time(seconds=3.5)))[0] == pytest.approx(2)
    assert xyz_of(b.lookup_transform("world", "c", Time(seconds=1.5)))[0] == pytest.approx(1)


def test_errors_after_a_cached_lookup_are_tf2s():
    b = Buffer()
    b.set_transform(tf("odom", "base", 1, (0, 0, 0)), "t")
    b.set_transform(tf("odom", "base", 2, (1, 0, 0)), "t")
    assert xyz_of(b.lookup_transform("odom", "base", Time(seconds=1.5)))[0] == pytest.approx(0.5)
    with pytest.raises(ExtrapolationException, match="extrapolation into the future"):
        b.lookup_transform("odom", "base", Time(seconds=3))
    b.clear()
    with pytest.raises((ExtrapolationException, LookupException)):
        b.lookup_transform("odom", "base", Time(seconds=1.5))


def test_time_zero_on_a_dynamic_link_stamped_zero_means_the_latest():
    # tf2: time zero is "the latest"; a replayed walk must not read it as the stamp 0
    b = Buffer()
    b.set_transform(tf("odom", "base", 0, (1, 0, 0)), "t")
    for _ in range(2):  # traced, then replayed
        assert xyz_of(b.lookup_transform("odom", "base", Time()))[0] == pytest.approx(1)
