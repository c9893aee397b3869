"""Part ``seed``: the seed experiment under each executor model, in one run.

A 50 Hz control timer beside a perception timer doing 150 ms of work every
100 ms, for ``periods`` control periods after ``warmup``; two perception kinds
(``sleep`` releases the GIL, ``cpu`` holds it). The models:

- ``single``: one asyncio loop, perception inline (rclpy's SingleThreadedExecutor);
- ``threads``: rclpy's MultiThreadedExecutor(4) with one callback group each;
- ``aiorobot``: control on the priority loop, perception through ``Node.offload``;
- ``aiorobot-rt``: the same on ``Runtime(priority_realtime=True)`` (SCHED_FIFO).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

from ._noise import NoiseMeter
from ._seedconfig import SeedConfig
from ._stats import period_stats, periods_from_stamps
from ._workload import KINDS

__all__ = ["MODELS", "REFERENCE", "run"]

MODELS = ("single", "threads", "aiorobot", "aiorobot-rt")

#: The seed's published rclpy figures (ms), printed as reference rows.
REFERENCE: dict[str, dict[str, float | str]] = {
    "rclpy SingleThreadedExecutor": {"model": "single", "mean_ms": 35.2, "stdev_ms": 48.3, "max_ms": 172.1},
    "rclpy MultiThreadedExecutor + groups": {"model": "threads", "mean_ms": 20.1, "stdev_ms": 1.2, "max_ms": 23.4},
}


def _model_runner(model: str) -> Callable[..., list[float]]:
    if model == "single":
        from ._model_single import run_single

        return run_single
    if model == "threads":
        from ._model_threads import run_threads

        return run_threads
    if model == "aiorobot":
        from ._model_aiorobot import run_aiorobot

        return run_aiorobot
    if model == "aiorobot-rt":
        from ._model_aiorobot import run_aiorobot_rt

        return run_aiorobot_rt
    raise ValueError(f"executor model must be one of {MODELS}, received {model!r}")


def run_model(model: str, kind: str, cfg: SeedConfig) -> dict[str, Any]:
    """One model under one perception kind: period figures, raw periods and noise."""
    runner = _model_runner(model)
    applied: list[str] = []
    with NoiseMeter() as meter:
        t0 = time.perf_counter()
        if model.startswith("aiorobot"):
            stamps = runner(kind, cfg, applied=applied)
        else:
            stamps = runner(kind, cfg)
        stamps = stamps[: cfg.stamps_needed]
        wall = time.perf_counter() - t0
    if len(stamps) < cfg.stamps_needed:
        raise RuntimeError(
            f"model {model!r} ({kind}) recorded {len(stamps)} control callbacks, expected {cfg.stamps_needed}"
        )
    periods = periods_from_stamps(stamps, cfg.warmup)
    assert meter.result is not None
    return {
        "stats": period_stats(periods, cfg.nominal_ms).as_dict(),
        "periods_ms": [round(p, 4) for p in periods],
        "wall_sec": round(wall, 3),
        "scheduling": " ".join(applied) or "default",
        "noise": meter.result.as_dict(),
    }


def run(
    quick: bool = False,
    periods: int | None = None,
    models: tuple[str, ...] = MODELS,
    progress: Callable[[float], None] | None = None,
) -> dict[str, Any]:
    """Run every model under both perception kinds.

    Parameters
    ----------
    quick
        A smoke run: 5 periods after 2 warm-up (unless ``periods`` is given).
    periods
        Control periods measured per model and kind (default 200).
    progress
        Called with the fraction (0..1) of model runs done, after each.
    """
    if quick:
        cfg = SeedConfig(periods=periods or 5, warmup=2)
    else:
        cfg = SeedConfig(periods=periods or 200)
    results: dict[str, dict[str, Any]] = {}
    if progress is not None:
        progress(0.0)
    with NoiseMeter() as meter:
        for model in models:
            results[model] = {}
            for kind in KINDS:
                try:
                    results[model][kind] = run_model(model, kind, cfg)
                except Exception as err:  # a model that cannot run is reported, the others still run
                    results[model][kind] = {"error": f"{type(err).__name__}: {err}"}
                if progress is not None:
                    progress(sum(map(len, results.values())) / (len(models) * len(KINDS)))
    assert meter.result is not None
    return {
        "config": cfg.as_dict(),
        "models": results,
        "reference": REFERENCE,
        "switch_interval_sec": sys.getswitchinterval(),
        "noise": meter.result.as_dict(),
    }
