"""tf figures for ``aiorobot bench``: buffer lookups and batch point transforms.

``run()`` measures, in one process and one run:

- lookups per second of ``Buffer.lookup_transform`` across a 4-link chain of
  dynamic transforms, each at a random time between samples (so every link is
  interpolated: lerp + slerp), result messages included;
- points per second of ``Buffer.transform_points`` on 100k points: the Numba
  kernel against the same lookup followed by plain numpy (``points @ R.T + t``).

Figures are medians of repeats; the CPU steal seen during the run is reported
beside them (shared VMs steal in bursts).
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

import numpy as np

__all__ = ["run"]

_CHAIN = ("map", "odom", "base_link", "torso", "lidar_link")


def _steal_ticks() -> tuple[int, int]:
    """(steal, total) jiffies from /proc/stat, or (0, 0) where unavailable."""
    try:
        with open("/proc/stat") as f:
            fields = [int(v) for v in f.readline().split()[1:]]
    except (OSError, ValueError):
        return 0, 0
    return (fields[7] if len(fields) > 7 else 0), sum(fields)


def _chain_buffer(samples_per_link: int) -> Any:
    from aiorobot import Time
    from aiorobot.msgs.geometry_msgs import Quaternion, Transform, TransformStamped, Vector3
    from aiorobot.msgs.std_msgs import Header
    from aiorobot.tf import Buffer

    buffer = Buffer(cache_time_sec=100.0)
    rng = np.random.default_rng(0)
    for parent, child in zip(_CHAIN, _CHAIN[1:]):
        for i in range(samples_per_link):
            yaw = float(rng.uniform(-math.pi, math.pi))
            x, y, z = (float(v) for v in rng.normal(size=3))
            buffer.set_transform(
                TransformStamped(
                    header=Header(stamp=Time(seconds=1 + i * 0.1).to_msg(), frame_id=parent),
                    child_frame_id=child,
                    transform=Transform(
                        translation=Vector3(x=x, y=y, z=z),
                        rotation=Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)),
                    ),
                ),
                "bench",
            )
    return buffer


def _lookups_per_sec(buffer: Any, n: int, repeats: int) -> list[float]:
    from aiorobot import Time

    rng = np.random.default_rng(1)
    rates = []
    for _ in range(repeats):
        # times strictly between samples of the 1.0 .. 10.9 s data (never on a stamp)
        times = [Time(nanoseconds=int(v)) for v in rng.uniform(1.05e9, 10.85e9, size=n)]
        t0 = time.perf_counter()
        for t in times:
            buffer.lookup_transform("map", "lidar_link", t)
        rates.append(n / (time.perf_counter() - t0))
    return rates


def _points_per_sec(buffer: Any, points: np.ndarray, repeats: int) -> tuple[list[float], list[float]]:
    from aiorobot import Time
    from aiorobot.tf._kernels import transform_points_numpy
    from aiorobot.tf._math import _q_to_m

    stamp = Time(seconds=5.55)
    numba_rates, numpy_rates = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        buffer.transform_points(points, "map", "lidar_link", stamp)
        numba_rates.append(len(points) / (time.perf_counter() - t0))

        t0 = time.perf_counter()
        _, vec, q = buffer._lookup_raw("map", "lidar_link", stamp.nanoseconds, "bench")
        R = np.array(_q_to_m(q)).reshape(3, 3)
        transform_points_numpy(points, R, np.array(vec))
        numpy_rates.append(len(points) / (time.perf_counter() - t0))
    return numba_rates, numpy_rates


def run(quick: bool = False) -> dict[str, Any]:
    """Measure tf lookups and batch transforms; returns a flat dict of figures.

    Parameters
    ----------
    quick
        Fewer and shorter repeats (for smoke runs and CI).
    """
    repeats = 3 if quick else 7
    n_lookups = 2_000 if quick else 20_000
    n_points = 100_000
    steal0, total0 = _steal_ticks()

    buffer = _chain_buffer(samples_per_link=100)
    lookup_rates = _lookups_per_sec(buffer, n_lookups, repeats)

    points = np.random.default_rng(2).uniform(-10, 10, size=(n_points, 3))
    t0 = time.perf_counter()
    buffer.transform_points(points[:10], "map", "lidar_link", _time(5.55))  # numba load / compile
    first_call_sec = time.perf_counter() - t0
    numba_rates, numpy_rates = _points_per_sec(buffer, points, repeats * 3)

    steal1, total1 = _steal_ticks()
    lookups = statistics.median(lookup_rates)
    numba_pps = statistics.median(numba_rates)
    numpy_pps = statistics.median(numpy_rates)
    return {
        "lookup_chain_links": len(_CHAIN) - 1,
        "lookups_per_sec": round(lookups),
        "lookup_us": round(1e6 / lookups, 2),
        "transform_points_n": n_points,
        "transform_points_numba_points_per_sec": round(numba_pps),
        "transform_points_numpy_points_per_sec": round(numpy_pps),
        "transform_points_numba_speedup": round(numba_pps / numpy_pps, 2),
        "numba_first_call_sec": round(first_call_sec, 3),
        "repeats": repeats,
        "steal_pct": round(100.0 * (steal1 - steal0) / (total1 - total0), 2) if total1 > total0 else None,
    }


def _time(seconds: float) -> Any:
    from aiorobot import Time

    return Time(seconds=seconds)


if __name__ == "__main__":  # pragma: no cover
    print(run())
