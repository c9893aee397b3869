"""Lookups across geometry2's test trees: test_tf2/test/buffer_core_test.cpp's configurations.

Each tree is built at an evaluation time, with one sample at that time or two
samples straddling it (the "interpolation space"), and every ordered pair of
frames is looked up, as the upstream Permuter does.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from _tf_helpers import q_of, tf, xyz_of

from aiorobot import Time
from aiorobot.tf import Buffer

EVAL_TIMES = (1.0, 10.0, 0.0)
SPACES = (1.0, 0.001, 0.1)

# child: (parent, dx, dy) -- push_back_i / _v / _y / _1 of buffer_core_test.cpp
TREES = {
    "i": {"b": ("a", 1, 0), "c": ("b", 1, 0)},
    "y": {"b": ("a", 1, 0), "c": ("b", 1, 0), "d": ("b", 0, 1), "e": ("d", 0, 1)},
    "v": {"b": ("a", 1, 0), "c": ("b", 1, 0), "f": ("a", 0, 1), "g": ("f", 0, 1)},
    "1_v": {"2": ("1", 1, 0), "b": ("a", 1, 0), "c": ("b", 1, 0), "f": ("a", 0, 1), "g": ("f", 0, 1)},
}


def insert(buffer: Buffer, parent, child, eval_time, space, xyz, q=(0.0, 0.0, 0.0, 1.0)):
    """setupTree's stamping: one sample at eval_time - space/2 (or 0), a second at eval_time."""
    half = space * 0.5
    first = eval_time - half if eval_time > half else 0.0
    assert buffer.set_transform(tf(parent, child, first, xyz, q), "authority") is True
    if space > 0:
        assert buffer.set_transform(tf(parent, child, eval_time, xyz, q), "authority") is True


def position(tree, frame):
    x = y = 0.0
    while frame in tree:
        parent, dx, dy = tree[frame]
        x, y, frame = x + dx, y + dy, parent
    return x, y, frame


@pytest.mark.parametrize("mode", sorted(TREES))
def test_translation_trees(mode):
    # buffer_core_test.cpp::BufferCore_lookupTransform.i_configuration, .y_configuration, .v_configuration,
    # .multi_configuration (the "1_v" tree: two unconnected trees)
    from aiorobot.tf import ConnectivityException

    tree = TREES[mode]
    frames = sorted(set(tree) | {p for p, _, _ in tree.values()})
    for eval_time, space in itertools.product(EVAL_TIMES, SPACES):
        buffer = Buffer()
        for child, (parent, dx, dy) in tree.items():
            insert(buffer, parent, child, eval_time, space, (dx, dy, 0.0))
        for a, b in itertools.product(frames, repeat=2):
            ax, ay, aroot = position(tree, a)
            bx, by, broot = position(tree, b)
            t = Time(seconds=eval_time)
            if aroot != broot:
                with pytest.raises(ConnectivityException):
                    buffer.lookup_transform(a, b, t)
                assert not buffer.can_transform(a, b, t)
                continue
            out = buffer.lookup_transform(a, b, t)
            assert (out.header.frame_id, out.child_frame_id) == (a, b)
            assert Time.from_msg(out.header.stamp) == t
            assert xyz_of(out) == pytest.approx((bx - ax, by - ay, 0.0), abs=1e-6)
            assert q_of(out) == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-6)


RING = "abcdefghi"
STEP = math.pi / 4


def test_ring_45_configuration():
    # buffer_core_test.cpp::BufferCore_lookupTransform.ring_45_configuration: a ring of frames every 45 degrees
    # on the unit circle; a frame k links down the ring is at (cos(k 45) - 1, sin(k 45)), turned k 45 degrees.
    link = (math.sqrt(2) / 2 - 1, math.sqrt(2) / 2, 0.0)
    link_q = (0.0, 0.0, math.sin(STEP / 2), math.cos(STEP / 2))
    for eval_time, space in itertools.product(EVAL_TIMES, SPACES):
        buffer = Buffer()
        for parent, child in zip(RING, RING[1:]):
            insert(buffer, parent, child, eval_time, space, link, link_q)
        t = Time(seconds=eval_time)
        for a, b in itertools.product(RING, repeat=2):
            k = RING.index(b) - RING.index(a)
            out = buffer.lookup_transform(a, b, t)
            assert (out.header.frame_id, out.child_frame_id) == (a, b)
            assert Time.from_msg(out.header.stamp) == t
            angle = k * STEP
            assert xyz_of(out) == pytest.approx((math.cos(angle) - 1, math.sin(angle), 0.0), abs=1e-6)
            expected_q = np.array((0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)))
            got = np.array(q_of(out))
            assert min(np.abs(got - expected_q).max(), np.abs(got + expected_q).max()) < 1e-6
