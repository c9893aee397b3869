"""Per-frame transform histories: tf2's ``TimeCache`` and ``StaticCache``.

A cache holds the transforms from one child frame to its parent. Times are
integer nanoseconds; ``0`` means "the latest". A sample is the tuple
``(parent_id, tx, ty, tz, qx, qy, qz, qw)``. Errors come back as
``(None, reason)`` instead of exceptions: the buffer adds the frame names and
chooses the exception type, as tf2 does.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right

from ._math import _slerp

__all__ = ["StaticCache", "TimeCache", "display_time", "Sample"]

Sample = tuple[int, float, float, float, float, float, float, float]


def display_time(stamp_ns: int) -> str:
    """Seconds with six decimals, as tf2's ``displayTimePoint``."""
    return f"{stamp_ns / 1e9:.6f}"


def _extrapolation_single(t: int, only: int) -> str:
    return (
        f"Lookup would require extrapolation at time {display_time(t)}, "
        f"but only time {display_time(only)} is in the buffer"
    )


def _extrapolation_future(t: int, latest: int) -> str:
    return (
        f"Lookup would require extrapolation into the future.  Requested time {display_time(t)} "
        f"but the latest data is at time {display_time(latest)}"
    )


def _extrapolation_past(t: int, earliest: int) -> str:
    return (
        f"Lookup would require extrapolation into the past.  Requested time {display_time(t)} "
        f"but the earliest data is at time {display_time(earliest)}"
    )


class TimeCache:
    """Time-stamped samples of one frame, oldest first, at most ``max_storage_ns`` long.

    Between two samples with the same parent the translation is interpolated
    linearly and the rotation by slerp; between samples of different parents the
    older sample is returned unchanged (re-parenting never interpolates).
    """

    __slots__ = ("_intervals", "_max_ns", "samples", "stamps")
    is_static = False

    def __init__(self, max_storage_ns: int) -> None:
        self._max_ns = max_storage_ns
        self.stamps: list[int] = []
        self.samples: list[Sample] = []
        # slerp constants per interval index; indices shift on every change, so any change clears it
        self._intervals: dict[int, tuple[float, ...]] = {}

    def interval(self, i: int) -> tuple[float, ...]:
        """Interpolation constants between samples ``i`` and ``i + 1`` (same parent), computed once.

        ``(theta, a' (4), b' (4), t0, 1 / (t1 - t0), p0 (3), p1 - p0 (3))`` where
        ``a' = a / sin(theta)`` and ``b'`` is ``b / sin(theta)`` with its sign flipped
        when that is the shorter way (as ``_slerp``); then
        ``slerp(a, b, r) = a' sin((1 - r) theta) + b' sin(r theta)`` and the
        translation is ``p0 + r (p1 - p0)``. With ``theta = 0`` the rotation is ``a``.
        """
        found = self._intervals.get(i)
        if found is not None:
            return found
        a = self.samples[i]
        b = self.samples[i + 1]
        ax, ay, az, aw = a[4], a[5], a[6], a[7]
        bx, by, bz, bw = b[4], b[5], b[6], b[7]
        dot = ax * bx + ay * by + az * bz + aw * bw
        s = math.sqrt((ax * ax + ay * ay + az * az + aw * aw) * (bx * bx + by * by + bz * bz + bw * bw))
        c = (-dot if dot < 0 else dot) / s
        theta = math.acos(c if c < 1.0 else 1.0)
        if theta == 0.0:
            rot: tuple[float, ...] = (0.0, ax, ay, az, aw, 0.0, 0.0, 0.0, 0.0)
        else:
            d = 1.0 / math.sin(theta)
            e = -d if dot < 0 else d
            rot = (theta, ax * d, ay * d, az * d, aw * d, bx * e, by * e, bz * e, bw * e)
        t0 = self.stamps[i]
        found = (
            *rot,
            t0, 1.0 / (self.stamps[i + 1] - t0),
            a[1], a[2], a[3], b[1] - a[1], b[2] - a[2], b[3] - a[3],
        )  # fmt: skip
        self._intervals[i] = found
        return found

    # -- queries -------------------------------------------------------------------

    def _find(self, t: int) -> tuple[int, bool, str]:
        """Index of the sample at or just before ``t``; exact hit flag; error or ''.

        Returns ``(-1, False, reason)`` when ``t`` is outside the data.
        """
        stamps = self.stamps
        n = len(stamps)
        if n == 0:
            return -1, False, ""
        if t == 0:
            return n - 1, True, ""
        if n == 1:
            if stamps[0] == t:
                return 0, True, ""
            return -1, False, _extrapolation_single(t, stamps[0])
        if t > stamps[-1]:
            return -1, False, _extrapolation_future(t, stamps[-1])
        if t < stamps[0]:
            return -1, False, _extrapolation_past(t, stamps[0])
        # the most recently inserted of equal stamps wins (it sits last among them)
        i = bisect_right(stamps, t) - 1
        return i, stamps[i] == t, ""

    def get_data(self, t: int) -> tuple[Sample | None, str]:
        i, exact, error = self._find(t)
        if i < 0:
            return None, error
        older = self.samples[i]
        if exact:
            return older, ""
        newer = self.samples[i + 1]
        if older[0] != newer[0]:
            return older, ""  # the parent changed: never interpolate across it
        t0 = self.stamps[i]
        ratio = (t - t0) / (self.stamps[i + 1] - t0)
        keep = 1.0 - ratio
        q = _slerp(older[4:8], newer[4:8], ratio)  # type: ignore[arg-type]
        return (
            older[0],
            keep * older[1] + ratio * newer[1],
            keep * older[2] + ratio * newer[2],
            keep * older[3] + ratio * newer[3],
            q[0], q[1], q[2], q[3],
        ), ""  # fmt: skip

    def get_parent(self, t: int) -> tuple[int, str]:
        i, _exact, error = self._find(t)
        if i < 0:
            return 0, error
        return self.samples[i][0], ""

    def latest_time_and_parent(self) -> tuple[int, int]:
        if not self.stamps:
            return 0, 0
        return self.stamps[-1], self.samples[-1][0]

    def latest_stamp(self) -> int:
        return self.stamps[-1] if self.stamps else 0

    def oldest_stamp(self) -> int:
        return self.stamps[0] if self.stamps else 0

    def __len__(self) -> int:
        return len(self.stamps)

    # -- updates -------------------------------------------------------------------

    def insert(self, stamp: int, sample: Sample) -> bool:
        """Insert a sample; False (and no change) when it is older than the cache length.

        As tf2's ``TimeCache::insertData`` (Jazzy): the cache is pruned *before*
        the insert, against the newest stamp held so far, so a sample older than
        the cache length survives until the next insert and interpolation just
        inside the boundary still works. An exact duplicate is not stored twice.
        """
        stamps = self.stamps
        if stamps:
            latest = stamps[-1]
            self._prune(latest)
            if stamp < latest - self._max_ns:
                return False
        i = bisect_right(stamps, stamp)
        j = i
        while j > 0 and stamps[j - 1] == stamp:
            j -= 1
            if self.samples[j] == sample:
                return True  # exact duplicate: nothing to do
        stamps.insert(i, stamp)
        self.samples.insert(i, sample)
        self._intervals.clear()
        return True

    def _prune(self, latest: int) -> None:
        """Drop samples older than ``latest`` minus the cache length (tf2's ``pruneList``)."""
        stamps = self.stamps
        k = bisect_left(stamps, latest - self._max_ns)
        if k:
            del stamps[:k]
            del self.samples[:k]
            self._intervals.clear()

    def clear(self) -> None:
        self.stamps.clear()
        self.samples.clear()
        self._intervals.clear()


class StaticCache:
    """One transform valid at every time, stamped with whatever time is asked."""

    __slots__ = ("sample", "stamp")
    is_static = True

    def __init__(self) -> None:
        self.sample: Sample | None = None
        self.stamp = 0

    def get_data(self, t: int) -> tuple[Sample | None, str]:
        return self.sample, ""

    def get_parent(self, t: int) -> tuple[int, str]:
        return (self.sample[0] if self.sample is not None else 0), ""

    def latest_time_and_parent(self) -> tuple[int, int]:
        return 0, (self.sample[0] if self.sample is not None else 0)

    def latest_stamp(self) -> int:
        return 0

    def oldest_stamp(self) -> int:
        return 0

    def __len__(self) -> int:
        return 1 if self.sample is not None else 0

    def insert(self, stamp: int, sample: Sample) -> bool:
        self.sample = sample
        self.stamp = stamp
        return True

    def clear(self) -> None:
        """Static data outlives ``Buffer.clear()``, as in tf2."""
