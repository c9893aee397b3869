"""Draw docs/fusion.png: truth vs wheel odometry vs EKF (odometry + gyro + 1 Hz pose fixes).

    python docs/scripts/plot_fusion.py [output.png]

Uses the seeded figure-eight of ``aiorobot.fusion._synthetic`` (the data the accuracy tests use).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np


def main(out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aiorobot.fusion._synthetic import figure_eight, fuse_figure_eight

    data = figure_eight(0)
    fused = fuse_figure_eight(data)
    no_fix = fuse_figure_eight(data, use_fixes=False)
    rmse = float(np.sqrt(np.mean(np.sum((fused.estimate[:, :2] - data.truth[:, :2]) ** 2, axis=1))))
    fig, ax = plt.subplots(figsize=(8, 5))
    ax.plot(data.truth[:, 0], data.truth[:, 1], "k-", lw=2, label="truth")
    ax.plot(data.odom_pose[:, 0], data.odom_pose[:, 1], "C3--", label="wheel odometry (2 % scale error)")
    ax.plot(no_fix.estimate[:, 0], no_fix.estimate[:, 1], "C1-", lw=1, label="EKF: odometry + gyro")
    ax.plot(fused.estimate[:, 0], fused.estimate[:, 1], "C0-", lw=1.2, label=f"EKF: + 1 Hz fixes (RMSE {100 * rmse:.1f} cm)")
    accepted = ~data.outlier
    ax.plot(data.fixes[accepted, 0], data.fixes[accepted, 1], "C2.", ms=4, label="pose fixes")
    ax.plot(data.fixes[data.outlier, 0], data.fixes[data.outlier, 1], "rx", label="2 m outliers (rejected)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("aiorobot.fusion EKF, 60 s figure-eight (seed 0)")
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "fusion.png")
