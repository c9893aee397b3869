"""aiorobot.fusion: robot_localization's EKF and UKF and a complementary filter, for the priority loop.

Pure cores (numpy in, numpy out, no runtime): :class:`Ekf` (robot_localization's 15-state
omnidirectional model, Numba kernels), :class:`Ukf` (the same model through the unscented
transform), :class:`FilterTimeline` (measurements applied at their own stamps, rewind-and-replay
for lagged data), :class:`ComplementaryEstimator`.

Nodes: :class:`EkfNode` and :class:`UkfNode` (robot_localization's ``ekf_node`` and ``ukf_node``
parameters and topics), :class:`ComplementaryFilter`. See ``docs/fusion.md``.
"""

from __future__ import annotations

from ._complementary import ComplementaryEstimator
from ._complementary_node import ComplementaryFilter
from ._ekf import DEFAULT_PROCESS_NOISE, STATE_NAMES, STATE_SIZE, Correction, Ekf, check_covariance, force_two_d
from ._ekf_node import EkfNode
from ._timeline import FilterTimeline, Measurement
from ._ukf import Ukf
from ._ukf_node import UkfNode

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
    "Ukf",
    "UkfNode",
    "check_covariance",
    "force_two_d",
]
