"""``sweep``: one bag replayed into several parameter variants of the same nodes, in parallel processes.

Each variant is a lock-step replay (:func:`._replay.replay`) in its own worker process (spawned,
so the variants share nothing), as fast as the machine goes. For every output topic the table
gives the messages, the rate (per second of recording) and the latency (recording time of the
publish minus the header stamp, sim time); for ``nav_msgs/msg/Odometry`` outputs also the RMSE
of the position (x, y) against a reference topic (``/ground_truth/odom`` when the bag has it),
the reference interpolated at each output's stamp and aligned to the output's frame by the
rigid 2-D transform that maps the reference's pose onto the output's at the first output (an
odometry frame starts wherever the robot was).

:func:`odometry_rmse` and :func:`topic_figures` are the pure core; :func:`sweep` the process pool.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["TopicFigures", "VariantResult", "odometry_rmse", "sweep", "topic_figures", "variants_from_params"]

_ODOMETRY = "nav_msgs/msg/Odometry"


@dataclass(frozen=True, slots=True)
class TopicFigures:
    """One output topic of one variant: messages, rate (Hz of recording time), mean latency (s), RMSE (m, or NaN)."""

    topic: str
    messages: int
    rate_hz: float
    latency_sec: float
    rmse_m: float = math.nan


@dataclass(frozen=True, slots=True)
class VariantResult:
    """A variant's parameters (``NAME:=VALUE``) and its figures per output topic; ``error`` when it failed."""

    params: tuple[str, ...]
    figures: tuple[TopicFigures, ...]
    wall_sec: float
    error: str = ""


def variants_from_params(params: Sequence[str]) -> list[tuple[str, ...]]:
    """``-p`` items -> the variants: a name given several times is swept, the product over names.

    ``["a:=1", "a:=2", "b:=x"]`` -> ``[("a:=1", "b:=x"), ("a:=2", "b:=x")]``. Order kept as given.
    """
    by_name: dict[str, list[str]] = {}
    for item in params:
        name, sep, _ = item.partition(":=")
        if not sep or not name:
            raise ValueError(f"-p: expected NAME:=VALUE, found {item!r}")
        by_name.setdefault(name, []).append(item)
    return [tuple(combo) for combo in itertools.product(*by_name.values())] if by_name else [()]


def _stamp_ns(msg: Any, fallback: int) -> int:
    header = getattr(msg, "header", None)
    if header is None:
        return fallback
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _poses(messages: Sequence[tuple[int, Any]]) -> tuple[np.ndarray, np.ndarray]:
    """``(stamps_ns (N,), poses (N, 3) as x, y, yaw)`` of Odometry messages, sorted by stamp."""
    rows = sorted((_stamp_ns(m, t), m.pose.pose.position.x, m.pose.pose.position.y, _yaw(m.pose.pose.orientation)) for t, m in messages)
    arr = np.asarray(rows, dtype=np.float64).reshape(-1, 4)
    return arr[:, 0].astype(np.int64), arr[:, 1:]


def odometry_rmse(estimate: Sequence[tuple[int, Any]], reference: Sequence[tuple[int, Any]]) -> float:
    """RMSE (m) of the estimate's x, y against the reference interpolated at the estimate's stamps.

    Both are ``(time_ns, Odometry)``. The reference is moved into the estimate's frame by the 2-D
    rigid transform matching their poses at the first estimate. Estimates stamped outside the
    reference's time span are left out; NaN when none is inside.
    """
    if not estimate or len(reference) < 2:
        return math.nan
    t_est, est = _poses(estimate)
    t_ref, ref = _poses(reference)
    inside = (t_est >= t_ref[0]) & (t_est <= t_ref[-1])
    if not inside.any():
        return math.nan
    t_est, est = t_est[inside], est[inside]
    x = np.interp(t_est, t_ref, ref[:, 0])
    y = np.interp(t_est, t_ref, ref[:, 1])
    yaw = np.interp(t_est, t_ref, np.unwrap(ref[:, 2]))
    # estimate_from_reference: rotate by (yaw_est0 - yaw_ref0) about the reference's first pose, then translate
    dyaw = est[0, 2] - yaw[0]
    c, s = math.cos(dyaw), math.sin(dyaw)
    dx, dy = x - x[0], y - y[0]
    ax = est[0, 0] + c * dx - s * dy
    ay = est[0, 1] + s * dx + c * dy
    return float(np.sqrt(np.mean((est[:, 0] - ax) ** 2 + (est[:, 1] - ay) ** 2)))


def topic_figures(topic: str, messages: Sequence[tuple[int, Any]], type_name: str, duration_ns: int,
                  reference: Sequence[tuple[int, Any]] | None) -> TopicFigures:
    """The figures of one output topic: ``messages`` are ``(publish time_ns, decoded message)``."""
    n = len(messages)
    rate = n / (duration_ns / 1e9) if duration_ns > 0 else math.nan
    latencies = [(t - _stamp_ns(m, t)) / 1e9 for t, m in messages]
    latency = float(np.mean(latencies)) if latencies else math.nan
    rmse = odometry_rmse(messages, reference) if type_name == _ODOMETRY and reference else math.nan
    return TopicFigures(topic, n, rate, latency, rmse)


def _run_variant(path: str, build: Callable[[tuple[str, ...]], list[Any]], variant: tuple[str, ...],
                 outputs: tuple[str, ...] | None, reference: str) -> VariantResult:
    """In a worker process: build the variant's nodes, replay, compute the figures."""
    import asyncio
    import time

    from aiorobot.msgs import deserialize

    from ._reader import BagReader
    from ._replay import replay

    start = time.perf_counter()
    try:
        nodes = build(variant)
        result = asyncio.run(replay(path, [lambda n=n: n for n in nodes], outputs=outputs))
        ref: list[tuple[int, Any]] = []
        with BagReader(path) as reader:
            if reference and any(t.name == reference for t in reader.topics):
                ref_type = reader.message_type(reference)
                ref = [(t, deserialize(d, ref_type)) for _, t, d in reader.messages([reference])]
        figures = []
        for topic, msgs in result.outputs.items():
            if topic == reference:
                continue
            msg_type = result.types[topic]
            decoded = [(t, deserialize(d, msg_type)) for t, d in msgs]
            figures.append(topic_figures(topic, decoded, msg_type.__msgtype__, result.sim_ns, ref))
        return VariantResult(variant, tuple(figures), time.perf_counter() - start)
    except Exception as err:  # noqa: BLE001 - one variant's failure is a row of the table, not the end of the sweep
        text = str(err).splitlines()[0] if str(err) else type(err).__name__
        return VariantResult(variant, (), time.perf_counter() - start, f"{type(err).__name__}: {text}")


def sweep(
    path: str,
    build: Callable[[tuple[str, ...]], list[Any]],
    variants: Sequence[Sequence[str]],
    *,
    outputs: Sequence[str] | None = None,
    reference: str = "/ground_truth/odom",
    jobs: int = 0,
) -> list[VariantResult]:
    """Replay ``path`` once per variant into the nodes ``build(variant)`` returns, ``jobs`` processes at a time.

    ``build`` must be picklable (a module-level function or a ``functools.partial`` of one): it
    runs in the worker, with the variant's ``NAME:=VALUE`` overrides. Results come back in the
    variants' order; a variant that fails is a result with ``error`` set.
    """
    import multiprocessing
    import os
    from concurrent.futures import ProcessPoolExecutor

    workers = max(1, min(jobs or os.cpu_count() or 1, len(variants)))
    out = None if outputs is None else tuple(outputs)
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = [pool.submit(_run_variant, str(path), build, tuple(v), out, reference) for v in variants]
        return [f.result() for f in futures]
