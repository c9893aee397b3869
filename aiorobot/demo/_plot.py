"""``aiorobot demo --plot``: the map, the true / estimated / planned paths, landmarks and waypoints;
with ``--slam``, the map SLAM built (its walls in red, what it saw free in white) over the true one."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_demo"]


def plot_demo(summary: Any, world_name: str, waypoints: list[tuple[float, float, float]], output: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aiorobot.sim import World

    world = World.load(world_name)
    occ = np.asarray(world.occupancy)
    h, w = occ.shape
    x0, y0 = world.origin[0], world.origin[1]
    extent = (x0, x0 + w * world.resolution, y0, y0 + h * world.resolution)
    built = getattr(summary, "slam_map", None)
    fig, ax = plt.subplots(figsize=(10, 10 * h / max(w, 1) + 0.8), dpi=100)
    if built is None:
        image = np.where(occ >= 65, 0.15, np.where(occ < 0, 0.7, 1.0))
        ax.imshow(image, cmap="gray", origin="lower", extent=extent, vmin=0, vmax=1)
    else:  # the true walls grey on the unexplored (darker) background, SLAM's free space white, its walls red
        ax.imshow(np.where(occ >= 65, 0.3, 0.55), cmap="gray", origin="lower", extent=extent, vmin=0, vmax=1)
        bh, bw = built.data.shape
        bx, by = built.origin[0], built.origin[1]
        bext = (bx, bx + bw * built.resolution, by, by + bh * built.resolution)
        rgba = np.zeros((bh, bw, 4))
        rgba[built.data == 0] = (1.0, 1.0, 1.0, 0.85)
        rgba[built.data == 100] = (0.85, 0.1, 0.1, 1.0)
        ax.imshow(rgba, origin="lower", extent=bext, interpolation="nearest")
        ax.plot([], [], color=(0.85, 0.1, 0.1), linewidth=4, label="walls SLAM built")
        ax.plot([], [], color="0.3", linewidth=4, label="true walls")
        ax.set_xlim(extent[0], extent[1])
        ax.set_ylim(extent[2], extent[3])
    for i, plan in enumerate(summary.plans):
        if len(plan) > 1:
            p = np.asarray(plan)
            ax.plot(p[:, 0], p[:, 1], color="tab:green", alpha=0.35, linewidth=1, label="planned" if i == 0 else None)
    if summary.truth:
        t = np.asarray(summary.truth)
        ax.plot(t[:, 0], t[:, 1], color="tab:blue", linewidth=2, label="ground truth")
    if summary.estimate:
        e = np.asarray(summary.estimate)
        ax.plot(e[:, 0], e[:, 1], color="tab:orange", linewidth=1, linestyle="--",
                label="SLAM estimate" if built is not None else f"{summary.localisation} estimate")
    for lm in world.landmarks:
        ax.plot(lm.x, lm.y, marker="s", color="tab:purple", markersize=6)
        ax.annotate(str(lm.id), (lm.x, lm.y), textcoords="offset points", xytext=(4, 4), fontsize=7, color="tab:purple")
    for i, (x, y, _) in enumerate(waypoints):
        missed = i in summary.missed
        ax.plot(x, y, marker="x" if missed else "o", color="tab:red", markersize=9, fillstyle="none")
        ax.annotate(f"{i + 1}", (x, y), textcoords="offset points", xytext=(6, -10), fontsize=9, color="tab:red")
    sx, sy, _ = summary.start
    ax.plot(sx, sy, marker="^", color="black", markersize=9, label="start")
    slam = "" if built is None else (f"\nmap built from scratch by SLAM: {summary.slam_loop_closures} loop closures, "
                                     f"{(summary.slam_map_precision or 0) * 100:.0f} % of its walls within 0.1 m of true ones")
    ax.set_title(
        f"aiorobot demo — {world.name}: {summary.waypoints_reached}/{summary.waypoints_total} waypoints, "
        f"localisation RMSE {summary.localisation_rmse_m * 100:.1f} cm, {summary.sim_sec:.0f} s sim in {summary.wall_sec:.0f} s"
        + slam
    )
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(output)
    plt.close(fig)
