"""Draw docs/slam-warehouse.png: the warehouse as it is, beside the map SLAM built of it from scratch.

    python docs/scripts/plot_slam.py [output.png]

Uses the seeded warehouse loop the accuracy tests use (``aiorobot.demo._slam_figures``): 10 Hz scans of
the simulator's lidar along a 48 m loop, wheel odometry with a 3 % scale error.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np


def main(out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aiorobot.demo._slam_figures import WAREHOUSE_LOOP, WAREHOUSE_START, map_agreement, scripted_mapping_run
    from aiorobot.sim import World

    world = World.load("warehouse")
    run = scripted_mapping_run(world, WAREHOUSE_START, WAREHOUSE_LOOP)
    built = run.slam.occupancy_map()
    agreement = map_agreement(built, world, run.truth[run.node_scans, :2])
    errors = np.hypot(run.estimates[:, 0] - run.truth[:, 0], run.estimates[:, 1] - run.truth[:, 1])
    x0, y0, th0 = WAREHOUSE_START
    c, s = math.cos(th0), math.sin(th0)
    odom = np.column_stack([x0 + c * run.odom[:, 0] - s * run.odom[:, 1], y0 + s * run.odom[:, 0] + c * run.odom[:, 1]])
    h, w = world.occupancy.shape
    wext = (world.origin[0], world.origin[0] + w * world.resolution, world.origin[1], world.origin[1] + h * world.resolution)
    bh, bw = built.data.shape
    bext = (built.origin[0], built.origin[0] + bw * built.resolution, built.origin[1], built.origin[1] + bh * built.resolution)
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.6))
    shade = {100: 0.0, 0: 1.0, -1: 0.75}
    for ax, (grid, extent, title) in zip(axes, [
        (world.occupancy, wext, "the warehouse (the simulator's world)"),
        (built.data, bext, f"built from scratch by SLAM: {agreement.precision * 100:.0f} % of its walls within 0.1 m of "
                           f"true ones,\n{agreement.recall * 100:.0f} % of the walls seen marked, "
                           f"{run.slam.statistics().loop_closures} loop closures"),
    ]):
        image = np.full(grid.shape, 0.75)
        for value, tone in shade.items():
            image[grid == value] = tone
        ax.imshow(image, cmap="gray", origin="lower", extent=extent, vmin=0, vmax=1, interpolation="nearest")
        ax.set_xlim(wext[0] - 0.5, wext[1] + 0.5)
        ax.set_ylim(wext[2] - 0.5, wext[3] + 0.5)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=10)
    axes[0].plot(run.truth[:, 0], run.truth[:, 1], color="tab:blue", lw=2, label="ground truth (48 m loop)")
    axes[0].plot(odom[:, 0], odom[:, 1], color="tab:red", lw=1, ls="--", label="wheel odometry (3 % scale error)")
    axes[1].plot(run.estimates[:, 0], run.estimates[:, 1], color="tab:orange", lw=1.5,
                 label=f"SLAM map -> base_link: RMSE {math.sqrt(float(np.mean(errors ** 2))) * 100:.1f} cm")
    for ax in axes:
        ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print(f"{out}: RMSE {math.sqrt(float(np.mean(errors ** 2))) * 100:.1f} cm, final {errors[-1] * 100:.1f} cm, {agreement}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "slam-warehouse.png")
