"""``aiorobot bench``: the benchmarks behind the README's figures.

``aiorobot bench latency`` runs the seed experiment (a 50 Hz control loop beside
150 ms of perception work every 100 ms) under three executor models, the
priority loop's 1 kHz timer precision, publish -> callback latency and
throughput, the CPU cost of a 100 Hz publisher and tf figures. From Python::

    from aiorobot.bench import run_benchmark
    doc = run_benchmark(["seed"], quick=True)

Each part lives in its own module (``_seed``, ``_timer``, ``_latency``, ``_cpu``,
``tf``); pure statistics in ``_stats``, machine noise in ``_noise``.
"""

from __future__ import annotations

from ._runner import PARTS, run_benchmark

__all__ = ["PARTS", "run_benchmark"]
