"""Lookups on random trees agree with an independent 4x4-matrix reference."""

from __future__ import annotations

import numpy as np
import pytest
from _tf_helpers import q_of, tf, xyz_of

from aiorobot import Time
from aiorobot.tf import (
    Buffer,
    canonical_quaternion,
    concat,
    invert_transform,
    matrix_from_quaternion,
    quaternion_slerp,
    transform_from_pq,
)


def random_unit_quaternion(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def root2frame(parents: dict[str, str], child2parent: dict[str, np.ndarray], frame: str) -> np.ndarray:
    """frame2root as a 4x4 matrix, by walking up the reference tree."""
    frame2root = np.eye(4)
    while frame in parents:
        frame2root = concat(frame2root, child2parent[frame])
        frame = parents[frame]
    return frame2root


@pytest.mark.parametrize("seed", range(5))
def test_static_random_tree_lookups_match_matrix_products(seed):
    rng = np.random.default_rng(seed)
    frames = ["f0"]
    parents: dict[str, str] = {}
    child2parent: dict[str, np.ndarray] = {}
    buffer = Buffer()
    for i in range(1, 25):
        child, parent = f"f{i}", frames[rng.integers(len(frames))]
        p, q = rng.normal(size=3), random_unit_quaternion(rng)
        frames.append(child)
        parents[child] = parent
        child2parent[child] = transform_from_pq(p, q)
        buffer.set_transform(tf(parent, child, 0, p, q), "random", static=True)
    for _ in range(50):
        source, target = rng.choice(frames, size=2)
        expected = concat(root2frame(parents, child2parent, source), invert_transform(root2frame(parents, child2parent, target)))
        out = buffer.lookup_transform(target, source, Time(seconds=1))
        np.testing.assert_allclose(xyz_of(out), expected[:3, 3], atol=1e-9)
        np.testing.assert_allclose(matrix_from_quaternion(q_of(out)), expected[:3, :3], atol=1e-9)
        # and the sign is tf2's canonical one
        np.testing.assert_allclose(q_of(out), canonical_quaternion(q_of(out)), atol=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_interpolated_chain_matches_per_link_interpolation(seed):
    rng = np.random.default_rng(100 + seed)
    chain = ["map", "odom", "base_link", "arm", "tool"]
    buffer = Buffer()
    samples = {}
    for parent, child in zip(chain, chain[1:]):
        a = (rng.normal(size=3), random_unit_quaternion(rng))
        b = (rng.normal(size=3), random_unit_quaternion(rng))
        buffer.set_transform(tf(parent, child, 1.0, *a), "random")
        buffer.set_transform(tf(parent, child, 2.0, *b), "random")
        samples[child] = (a, b)
    for fraction in rng.uniform(0, 1, size=10):
        tool2map = np.eye(4)
        for child in reversed(chain[1:]):
            (p0, q0), (p1, q1) = samples[child]
            link = transform_from_pq((1 - fraction) * p0 + fraction * p1, quaternion_slerp(q0, q1, fraction))
            tool2map = concat(tool2map, link)
        out = buffer.lookup_transform("map", "tool", Time(nanoseconds=int(1e9 + fraction * 1e9)))
        np.testing.assert_allclose(xyz_of(out), tool2map[:3, 3], atol=1e-6)
        np.testing.assert_allclose(matrix_from_quaternion(q_of(out)), tool2map[:3, :3], atol=1e-6)
