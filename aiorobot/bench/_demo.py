"""Part ``demo``: issue 15's whole-robot figures as benchmark rows, from ``run_demo`` on the box world.

Three runs of the same mission (the box world's shipped one; ``quick``: its first two waypoints):

- lock-step (real-time factor 0, direct drive, sim time): waypoints reached, localisation RMSE
  against ground truth, and wall time for the sim time (how much faster than real time);
- real time (real-time factor 1, the serial drive through the simulated firmware, system time as
  on a robot): the same, plus the priority loop's control period p50 / p99 / max while perception
  runs, beside the baseline of the same run: a bare Python thread in the same process sleeping to
  the same absolute deadlines (what the machine's scheduling and the GIL give any thread). ``quick``
  drives only to the first waypoint here, so its period figures rest on a few hundred periods.

- the same real-time run with ``realtime=True`` (``aiorobot demo --realtime``): the priority loop's
  thread SCHED_FIFO where the OS permits it (the row says when it does not).

Perception (the ArUco worker and the lidar segmentation) runs in both; its frames per wall second
are reported per run.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["run", "table"]

#: The issue's targets, beside the figures.
TARGETS = {"localisation_rmse_m": 0.05, "control_period_p99_ms": 21.0, "control_period_max_ms": 22.0}

_KEYS = ("waypoints_reached", "waypoints_total", "collisions", "localisation_rmse_m", "sim_sec", "wall_sec",
         "real_time_factor", "control_period_p50_ms", "control_period_p99_ms", "control_period_max_ms",
         "control_periods", "baseline_period_p99_ms", "baseline_period_max_ms", "perception_fps", "time_source",
         "drive", "realtime", "status")


def _mission(rtf: float, waypoints: list[tuple[float, float, float]], seed: int, realtime: bool = False) -> dict[str, Any]:
    import aiorobot
    from aiorobot.demo import run_demo

    summary = aiorobot.run(run_demo("box", waypoints, rtf=rtf, seed=seed, timeout_sim_sec=180.0, realtime=realtime))
    figures = summary.figures()
    return {key: figures[key] for key in _KEYS}


def run(quick: bool = False, progress: Callable[[float], None] | None = None) -> dict[str, Any]:
    from aiorobot.demo import MISSIONS

    mission = MISSIONS["box"]
    lockstep_waypoints = mission[:2] if quick else mission
    realtime_waypoints = mission[:1] if quick else mission
    lockstep = _mission(0.0, lockstep_waypoints, seed=1)
    if progress is not None:
        progress(0.2 if quick else 0.1)
    realtime = _mission(1.0, realtime_waypoints, seed=1)
    if progress is not None:
        progress(0.6 if quick else 0.55)
    fifo = _mission(1.0, realtime_waypoints, seed=1, realtime=True)
    if progress is not None:
        progress(1.0)
    return {"world": "box", "rows": [{"run": "lock-step (rtf 0)", **lockstep}, {"run": "real time (rtf 1)", **realtime},
                                     {"run": "real time (rtf 1), --realtime", **fifo}],
            "targets": dict(TARGETS)}


def _pair(p99: float | None, worst: float | None) -> str:
    return "n/a" if p99 is None or worst is None else f"{p99:.2f} / {worst:.2f}"


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    rows = []
    for r in part["rows"]:
        def ms(key: str) -> Any:
            value = r[key]
            return "n/a" if value is None else value

        rows.append((
            f"{r['run']}, {r['drive']} drive, {r['time_source']} time"
            + (", SCHED_FIFO" if r.get("realtime") else ", SCHED_FIFO refused" if "--realtime" in r["run"] else ""),
            f"{r['waypoints_reached']} / {r['waypoints_total']}" + (f" ({r['collisions']} coll.)" if r["collisions"] else ""),
            r["localisation_rmse_m"] * 100,
            f"{r['sim_sec']:.1f} / {r['wall_sec']:.1f}",
            ms("control_period_p50_ms"), ms("control_period_p99_ms"), ms("control_period_max_ms"),
            _pair(r.get("baseline_period_p99_ms"), r.get("baseline_period_max_ms")),
            "off" if r["perception_fps"] is None else r["perception_fps"],
        ))
    t = part["targets"]
    rows.append(("[dim]target[/dim]", "[dim]all[/dim]", f"[dim]<= {t['localisation_rmse_m'] * 100:g}[/dim]", "",
                 "", f"[dim]<= {t['control_period_p99_ms']:g}[/dim]", f"[dim]<= {t['control_period_max_ms']:g}[/dim]", "", ""))
    periods = [r["control_periods"] for r in part["rows"] if r["control_period_p99_ms"] is not None]
    caption = (f"aiorobot demo on the {part['world']} world, perception on; control period = the priority loop's "
               f"50 Hz base controller, measured at rtf 1 only (lock-step periods are sim time); bare thread = a plain "
               f"Python thread sleeping to the same deadlines in the same run, the machine's own jitter ("
               + (f"{periods[0]} periods)" if periods else "no periods)"))
    return figure_table("demo: the whole simulated robot", ("run", "waypoints", "RMSE cm", "sim / wall s",
                                                           "period p50 ms", "p99 ms", "max ms",
                                                           "bare thread p99 / max ms", "perception fps"),
                        rows, caption=caption)
