"""aiorobot.fusion: robot_localization's EKF and a complementary filter, for the priority loop.

Pure cores (numpy in, numpy out, no runtime): :class:`Ekf` (robot_localization's 15-state
omnidirectional model, Numba kernels), :class:`FilterTimeline` (measurements applied at their own
stamps, rewind-and-replay for lagged data), :class:`ComplementaryEstimator`.

Nodes: :class:`EkfNode` (robot_localization's ``ekf_node`` parameters and topics),
:class:`ComplementaryFilter`. See ``docs/fusion.md``.
"""

from __future__ import annotations

from ._complementary import ComplementaryEstimator
from ._complementary_node import ComplementaryFilter
from ._ekf import DEFAULT_PROCESS_NOISE, STATE_NAMES, STATE_SIZE, Correction, Ekf, check_covariance, force_two_d
from ._ekf_node import EkfNode
from ._timeline import FilterTimeline, Measurement

__all__ = [
    "DEFAULT_PROCESS_NOISE",
    "STATE_NAMES",
    "STATE_SIZE",
    "ComplementaryEstimator",
    "ComplementaryFilter",
    "Correction",
    "Ekf",
    "EkfNode",
    "FilterTimeline",
    "Measurement",
    "check_covariance",
    "force_two_d",
]
