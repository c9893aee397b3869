"""Cached chain walks: the links a lookup from source to target visits, remembered per frame pair.

``BufferCore._walk`` (tf2's ``walkToTopParent``) follows parents from the
source to the root and from the target up to where the source's walk ended,
composing every link it passes. Frames rarely change parents, so a
:class:`ChainPlan` records the links one walk visited (the caches and the
parent each is expected to have) and :func:`walk_plan` replays them in the
same order with the same maths (interpolation constants computed once per
sample interval), so the result is the full walk's to rounding: a few ulp,
held to 1e-12 by the tests. Each link's parent at the requested time is checked; any
difference (re-parenting at that time, missing data, an error) makes
``walk_plan`` return ``None`` and the caller takes the full walk, which raises
tf2's exact errors. The buffer drops every plan when the tree's shape may have
changed (a new frame's cache, a new parent).
"""

from __future__ import annotations

from bisect import bisect_right
from math import sin
from typing import TYPE_CHECKING, Any

from ._math import Quat, Vec, _qinv, _qmul, _qrot

if TYPE_CHECKING:
    from ._cache import Sample, StaticCache, TimeCache

__all__ = ["ChainPlan", "TARGET_IS_ANCESTOR", "SOURCE_IS_ANCESTOR", "FULL_PATH", "trace_plan", "walk_plan"]

TARGET_IS_ANCESTOR = 0
SOURCE_IS_ANCESTOR = 1
FULL_PATH = 2


#: (cache, expected parent, and for a TimeCache its stamps, samples and interval lists -- the very
#: lists the cache mutates in place, held here to spare the attribute lookups on every replay)
Link = tuple[Any, int, Any, Any, Any]


def _link(cache: TimeCache | StaticCache, parent: int) -> Link:
    if cache.is_static:
        return (cache, parent, None, None, None)
    return (cache, parent, cache.stamps, cache.samples, cache._intervals)  # type: ignore[union-attr]


class ChainPlan:
    """The links of one walk: ``kind``, the source side, the target side, and the link checked last."""

    __slots__ = ("check", "kind", "source_links", "target_links")

    def __init__(self, kind: int, source_links: list[Link], target_links: list[Link], check: Link) -> None:
        self.kind = kind
        self.source_links = source_links
        self.target_links = target_links
        self.check = check

    def __repr__(self) -> str:
        return f"<ChainPlan kind={self.kind} source={len(self.source_links)} target={len(self.target_links)}>"


def trace_plan(
    caches: list[TimeCache | StaticCache | None], target_id: int, source_id: int, t: int, max_depth: int
) -> ChainPlan | None:
    """The plan of the walk ``_walk(target_id, source_id, t)`` takes, or ``None`` if that walk fails."""
    source_links: list[Link] = []
    frame = source_id
    top_parent = frame
    depth = 0
    while frame != 0:
        cache = caches[frame]
        if cache is None:
            top_parent = frame
            break
        st, _ = cache.get_data(t)
        if st is None or st[0] == 0:
            return None  # the full walk decides (extrapolation, maybe a path from the target)
        if frame == target_id:
            return ChainPlan(TARGET_IS_ANCESTOR, source_links, [], _link(cache, st[0]))
        source_links.append(_link(cache, st[0]))
        top_parent = frame
        frame = st[0]
        depth += 1
        if depth > max_depth:
            return None
    target_links: list[Link] = []
    frame = target_id
    depth = 0
    while frame != top_parent:
        cache = caches[frame]
        if cache is None:
            return None  # disconnected: the full walk raises
        st, _ = cache.get_data(t)
        if st is None or st[0] == 0:
            return None
        if frame == source_id:
            return ChainPlan(SOURCE_IS_ANCESTOR, [], target_links, _link(cache, st[0]))
        target_links.append(_link(cache, st[0]))
        frame = st[0]
        depth += 1
        if depth > max_depth:
            return None
    return ChainPlan(FULL_PATH, source_links, target_links, (None, 0, None, None, None))


def _accumulate(links: list[Link], t: int) -> tuple[Vec, Quat] | None:
    """Compose the links' transforms at ``t`` (child to top), or ``None`` when one does not match the plan.

    The arithmetic of ``TimeCache.get_data`` (lerp and slerp, with each
    interval's slerp constants computed once by ``TimeCache.interval``), ``_qrot``
    and ``_qmul`` written out inline: a lookup spends most of its time here and
    Python calls cost more than the maths. Results agree with the full walk to
    rounding (a few ulp).
    """
    vx = vy = vz = 0.0
    rx = ry = rz = 0.0
    rw = 1.0
    first = True
    for cache, parent, stamps, samples, intervals in links:
        st: Sample | None = None
        if stamps is None:
            st = cache.sample  # static
        else:
            i = bisect_right(stamps, t) - 1
            if not 0 <= i < len(stamps) - 1 or t == 0:
                st, _ = cache.get_data(t)  # the last stamp, edges, time zero, errors: the general path
            else:
                st = samples[i]
                if stamps[i] != t and st[0] == samples[i + 1][0]:
                    # between two samples of the same parent: interpolate as TimeCache.get_data
                    if st[0] != parent:
                        return None
                    theta, qx, qy, qz, qw, bx, by, bz, bw, t0, inv_dt, px, py, pz, dx, dy, dz = (
                        intervals.get(i) or cache.interval(i)
                    )
                    ratio = (t - t0) * inv_dt
                    if theta != 0.0:
                        s0 = sin((1.0 - ratio) * theta)
                        s1 = sin(ratio * theta)
                        qx, qy, qz, qw = qx * s0 + bx * s1, qy * s0 + by * s1, qz * s0 + bz * s1, qw * s0 + bw * s1
                    px += ratio * dx
                    py += ratio * dy
                    pz += ratio * dz
                    st = None
                    parent = -1  # marks "interpolated" for the check below
        if parent != -1:
            if st is None or st[0] != parent:
                return None
            _, px, py, pz, qx, qy, qz, qw = st
        if first:  # composed with the identity: the link itself
            vx, vy, vz, rx, ry, rz, rw = px, py, pz, qx, qy, qz, qw
            first = False
            continue
        # vec = q * vec * q^-1 + p, as v + w t + u x t with t = 2 u x v (u the vector part of q)
        tx = 2.0 * (qy * vz - qz * vy)
        ty = 2.0 * (qz * vx - qx * vz)
        tz = 2.0 * (qx * vy - qy * vx)
        vx, vy, vz = (
            vx + qw * tx + (qy * tz - qz * ty) + px,
            vy + qw * ty + (qz * tx - qx * tz) + py,
            vz + qw * tz + (qx * ty - qy * tx) + pz,
        )
        # rot = _qmul(q, rot)
        rx, ry, rz, rw = (
            qw * rx + qx * rw + qy * rz - qz * ry,
            qw * ry + qy * rw + qz * rx - qx * rz,
            qw * rz + qz * rw + qx * ry - qy * rx,
            qw * rw - qx * rx - qy * ry - qz * rz,
        )
    return (vx, vy, vz), (rx, ry, rz, rw)


def walk_plan(plan: ChainPlan, t: int) -> tuple[Vec, Quat] | None:
    """Replay ``plan`` at time ``t``: source2target as ``_walk`` computes it, or ``None`` to fall back."""
    kind = plan.kind
    if kind != FULL_PATH:
        cache, parent = plan.check[0], plan.check[1]
        st, _ = cache.get_data(t)
        if st is None or st[0] != parent:
            return None
    if kind == TARGET_IS_ANCESTOR:
        return _accumulate(plan.source_links, t)
    if kind == SOURCE_IS_ANCESTOR:
        target = _accumulate(plan.target_links, t)
        if target is None:
            return None
        qi = _qinv(target[1])
        tv = target[0]
        return _qrot(qi, (-tv[0], -tv[1], -tv[2])), qi
    source = _accumulate(plan.source_links, t)
    if source is None or not plan.target_links:
        return source  # the target is the root: target2top is the identity
    target = _accumulate(plan.target_links, t)
    if target is None:
        return None
    s_vec, s_q = source
    t_vec, t_q = target
    qi = _qinv(t_q)
    iv = _qrot(qi, (-t_vec[0], -t_vec[1], -t_vec[2]))
    r = _qrot(qi, s_vec)
    return (r[0] + iv[0], r[1] + iv[1], r[2] + iv[2]), _qmul(qi, s_q)
