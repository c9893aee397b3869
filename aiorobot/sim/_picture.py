"""Draw the built-in worlds (``python -m aiorobot.sim._picture docs/sim-worlds.png``): maps, markers, a scan, a camera frame."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

__all__ = ["draw_worlds"]


def draw_worlds(path: Path) -> Path:
    """Save a PNG with the ``box`` and ``warehouse`` maps, their landmarks, a scan and the camera view."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ._camera import CameraModel, MarkerRenderer, camera_pose_matrix
    from ._sensors import LidarModel
    from ._simulator import CAMERA_XYZ
    from ._world import World

    fig, axes = plt.subplots(1, 3, figsize=(16, 5.2), gridspec_kw={"width_ratios": [1, 1.9, 1.25]})
    rng = np.random.default_rng(1)
    for ax, name in zip(axes[:2], ("box", "warehouse")):
        world = World.load(name)
        ox, oy, _ = world.origin
        extent = (ox, ox + world.width_m, oy, oy + world.height_m)
        ax.imshow(world.to_image(), cmap="gray", extent=extent, vmin=0, vmax=255)
        x, y, yaw = world.start
        lidar = LidarModel()
        ranges = lidar.measure(world, x, y, yaw, rng)
        ok = np.isfinite(ranges)
        angles = lidar.angles[ok] + yaw
        ax.scatter(x + ranges[ok] * np.cos(angles), y + ranges[ok] * np.sin(angles), s=2, c="tab:red", label="/scan")
        ax.arrow(x, y, 0.5 * math.cos(yaw), 0.5 * math.sin(yaw), width=0.06, color="tab:blue", label="robot start")
        for lm in world.landmarks:
            corners = lm.corners()
            ax.plot(corners[:2, 0], corners[:2, 1], color="tab:green", linewidth=4)
            ax.annotate(str(lm.id), (lm.x + 0.35 * math.cos(lm.yaw), lm.y + 0.35 * math.sin(lm.yaw)),
                        ha="center", va="center", fontsize=8, color="tab:green")
        ax.set_title(f"{name}: {world.width_m:g} m x {world.height_m:g} m, {len(world.landmarks)} ArUco markers")
        ax.set_xlabel("x (m, map)")
        ax.set_ylabel("y (m, map)")
        ax.legend(loc="lower right", fontsize=8)
    world = World.load("box")
    image, _ = MarkerRenderer(world.landmarks, CameraModel()).render(
        camera_pose_matrix(1.0 + CAMERA_XYZ[0], 0.2, CAMERA_XYZ[2], 0.15))
    axes[2].imshow(image)
    axes[2].set_title("/camera/image_raw in box at (1.0, 0.2), facing marker 0")
    axes[2].axis("off")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


if __name__ == "__main__":
    print(draw_worlds(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/sim-worlds.png")))
