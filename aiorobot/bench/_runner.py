"""Runs the benchmark's parts, repeats them and merges repeats into medians."""

from __future__ import annotations

import datetime
import importlib
import importlib.util
import inspect
import os
import platform
import sys
from collections.abc import Callable, Sequence
from typing import Any

from ._noise import NoiseMeter
from ._stats import median_of_results

__all__ = ["PARTS", "run_benchmark"]

#: Part name -> module providing ``run(quick=False, ...) -> dict``.
PARTS: dict[str, str] = {
    "seed": "aiorobot.bench._seed",
    "timer": "aiorobot.bench._timer",
    "latency": "aiorobot.bench._latency",
    "cpu": "aiorobot.bench._cpu",
    "culprit": "aiorobot.bench._culprit",
    "tf": "aiorobot.bench.tf",
    "bag": "aiorobot.bench._bag",
    "nav": "aiorobot.bench._nav",
    "sim": "aiorobot.bench._sim",
    "zenoh": "aiorobot.bench._zenoh",
    "dds": "aiorobot.bench._dds",
    "fusion": "aiorobot.bench._fusion",
    "perception": "aiorobot.bench._perception",
    "demo": "aiorobot.bench._demo",
}


def _run_part(
    name: str, quick: bool, periods: int | None, fraction: Callable[[float], None] | None = None
) -> dict[str, Any]:
    module_name = PARTS[name]
    if importlib.util.find_spec(module_name) is None:
        return {"error": f"not available: {module_name} is not installed"}
    module = importlib.import_module(module_name)
    kwargs: dict[str, Any] = {"quick": quick}
    if name == "seed":
        kwargs["periods"] = periods
    if fraction is not None and "progress" in inspect.signature(module.run).parameters:
        kwargs["progress"] = fraction  # a part that can tell how far it is: run(..., progress=callback(0..1))
    return module.run(**kwargs)


def machine_info() -> dict[str, Any]:
    return {
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
        "processor": platform.processor() or platform.machine(),
    }


def run_benchmark(
    parts: Sequence[str] = tuple(PARTS),
    *,
    quick: bool = False,
    repeat: int = 1,
    periods: int | None = None,
    command: str = "aiorobot bench latency",
    progress: Callable[[str], None] | None = None,
    fraction: Callable[[float], None] | None = None,
) -> dict[str, Any]:
    """Run ``parts`` ``repeat`` times each; every figure is the median of the repeats.

    Returns the JSON document: ``meta`` (machine, date, options), ``parts`` (the
    median figures of each part, raw samples of every repeat concatenated) and,
    when ``repeat > 1``, ``repeats`` (each repeat's own figures). ``progress`` is called with
    each part's name as it starts; ``fraction`` with how far (0..1) the running part is, for
    parts whose ``run`` takes a ``progress`` callback.
    """
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise ValueError(f"unknown part {unknown[0]!r}: expected one of {', '.join(PARTS)}")
    if repeat < 1:
        raise ValueError(f"repeat must be >= 1, received {repeat!r}")
    doc: dict[str, Any] = {
        "meta": {
            **machine_info(),
            "command": command,
            "quick": quick,
            "repeat": repeat,
            "parts": list(parts),
        },
        "parts": {},
    }
    repeats: dict[str, list[dict[str, Any]]] = {}
    with NoiseMeter() as meter:
        for name in parts:
            runs = []
            for k in range(repeat):
                if progress is not None:
                    progress(f"{name}" + (f" (repeat {k + 1}/{repeat})" if repeat > 1 else ""))
                with NoiseMeter() as part_meter:
                    try:
                        result = _run_part(name, quick, periods, fraction)
                    except Exception as err:  # one failing part must not hide the others
                        result = {"error": f"{type(err).__name__}: {err}"}
                assert part_meter.result is not None
                result = dict(result)
                result["noise"] = result.get("noise") or part_meter.result.as_dict()
                runs.append(result)
            ok = [r for r in runs if "error" not in r]
            try:
                doc["parts"][name] = median_of_results(ok) if ok else runs[0]
            except ValueError:  # repeats of different shapes (a model failed in one): keep the first
                doc["parts"][name] = ok[0]
            if repeat > 1:
                repeats[name] = runs
    assert meter.result is not None
    doc["meta"]["noise"] = meter.result.as_dict()
    doc["meta"]["wall_sec"] = round(meter.result.wall_sec, 2)
    if repeats:
        doc["repeats"] = repeats
    return doc


def python_argv() -> str:
    return " ".join(["aiorobot", *sys.argv[1:]]) if sys.argv else "aiorobot bench latency"
