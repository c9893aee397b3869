"""Measurements applied at their own stamps, in stamp order, with rewind-and-replay for lagged data.

The part of robot_localization's ``RosFilter`` that is not ROS: its measurement queue,
``smooth_lagged_data`` + ``history_length`` (``revertTo`` and replay), ``sensor_timeout``
prediction and ``two_d_mode`` (``forceTwoD``), on top of :class:`~aiorobot.fusion.Ekf`.
"""

from __future__ import annotations

import bisect
import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ._ekf import Correction, Ekf, force_two_d

__all__ = ["Measurement", "FilterTimeline"]


@dataclass
class Measurement:
    """One measurement in state space.

    Attributes
    ----------
    stamp_sec : float
        Time the measurement was taken (header stamp), seconds.
    source : str
        The input it came from (``odom0``, ``imu0``...), for counters and warnings.
    z : ndarray, shape (15,)
    covariance : ndarray, shape (15, 15)
    mask : ndarray of bool, shape (15,)
        robot_localization's update vector (``<input>_config`` after the message's own gaps).
    mahalanobis_threshold : float
        Rejection threshold in standard deviations (``inf`` accepts all).
    """

    stamp_sec: float
    source: str
    z: NDArray[np.float64]
    covariance: NDArray[np.float64]
    mask: NDArray[np.bool_]
    mahalanobis_threshold: float = math.inf
    sequence: int = field(default=0, compare=False)


@dataclass
class _Entry:
    stamp_sec: float
    measurement: Measurement
    state: NDArray[np.float64]
    covariance: NDArray[np.float64]
    result: Correction


class FilterTimeline:
    """Drives an :class:`Ekf` from stamped measurements.

    A measurement newer than the last one is predicted to and corrected. An older one, with
    ``smooth_lagged_data``, rewinds the filter to the last state before its stamp (kept for
    ``history_length_sec``) and replays every later measurement in stamp order; without it, or when
    it is older than the history, it is rejected and counted (``rejected["older than ..."]``).

    Parameters
    ----------
    ekf : Ekf
    two_d_mode : bool
        Measure z, roll, pitch and their rates as 0 with every update (robot_localization's ``forceTwoD``).
    smooth_lagged_data : bool
    history_length_sec : float
    """

    def __init__(
        self,
        ekf: Ekf,
        *,
        two_d_mode: bool = False,
        smooth_lagged_data: bool = False,
        history_length_sec: float = 0.0,
    ) -> None:
        self.ekf = ekf
        self.two_d_mode = bool(two_d_mode)
        self.smooth_lagged_data = bool(smooth_lagged_data)
        self.history_length_sec = abs(float(history_length_sec))
        self.initialized = False
        #: stamp of the filter's state (last measurement or timeout prediction), seconds
        self.stamp_sec = -math.inf
        self.last_measurement_stamp_sec = -math.inf
        self.accepted: Counter[str] = Counter()
        self.rejected: Counter[tuple[str, str]] = Counter()
        self.replays = 0
        self._history: list[_Entry] = []
        self._stamps: list[float] = []
        self._sequence = 0

    def __repr__(self) -> str:
        return f"<FilterTimeline stamp={self.stamp_sec:.3f} history={len(self._history)} replays={self.replays}>"

    def reset(self) -> None:
        self.ekf.reset()
        self.initialized = False
        self.stamp_sec = self.last_measurement_stamp_sec = -math.inf
        self._history.clear()
        self._stamps.clear()

    def set_state(self, stamp_sec: float, state: NDArray[np.float64], covariance: NDArray[np.float64], mask: NDArray[np.bool_]) -> None:
        """robot_localization's ``setPose``: overwrite the members in ``mask``, forget the history."""
        self.ekf.state[mask] = state[mask]
        idx = np.flatnonzero(mask)
        self.ekf.covariance[np.ix_(idx, idx)] = covariance[np.ix_(idx, idx)]
        self.initialized = True
        self.stamp_sec = self.last_measurement_stamp_sec = float(stamp_sec)
        self._history.clear()
        self._stamps.clear()

    def predict_to(self, stamp_sec: float) -> None:
        """Predict the state forward to ``stamp_sec`` (no-op when not later than the state)."""
        if self.initialized and stamp_sec > self.stamp_sec:
            self.ekf.predict(stamp_sec - self.stamp_sec)
            self.stamp_sec = stamp_sec

    def process(self, measurement: Measurement) -> Correction:
        """Apply one measurement at its own stamp; see the class docstring."""
        self._sequence += 1
        measurement.sequence = self._sequence
        stamp = measurement.stamp_sec
        if self.initialized and stamp < self.last_measurement_stamp_sec:
            oldest = self.last_measurement_stamp_sec - self.history_length_sec
            if not self.smooth_lagged_data:
                return self._reject(measurement, "older than the last update (smooth_lagged_data is false)")
            if stamp < oldest or not self._history or stamp < self._history[0].stamp_sec:
                return self._reject(measurement, "older than history_length")
            return self._rewind_and_replay(measurement)
        return self._apply(measurement)

    def _reject(self, measurement: Measurement, reason: str) -> Correction:
        self.rejected[(measurement.source, reason)] += 1
        return Correction(False, math.nan, reason)

    def _apply(self, measurement: Measurement) -> Correction:
        z = measurement.z.copy()
        R = measurement.covariance.copy()
        mask = measurement.mask.copy()
        if self.two_d_mode:
            force_two_d(z, R, mask)
        if not self.initialized:
            # robot_localization's first measurement: copy its members into the state
            ok = mask & np.isfinite(z)
            self.ekf.state[ok] = z[ok]
            idx = np.flatnonzero(ok)
            self.ekf.covariance[np.ix_(idx, idx)] = R[np.ix_(idx, idx)]
            self.initialized = True
            result = Correction(True, 0.0)
        else:
            self.predict_to(measurement.stamp_sec)
            result = self.ekf.update(z, R, mask, mahalanobis_threshold=measurement.mahalanobis_threshold)
        self.stamp_sec = max(self.stamp_sec, measurement.stamp_sec)
        self.last_measurement_stamp_sec = max(self.last_measurement_stamp_sec, measurement.stamp_sec)
        if result.accepted:
            self.accepted[measurement.source] += 1
        else:
            self.rejected[(measurement.source, result.reason)] += 1
        if self.smooth_lagged_data:
            self._remember(measurement, result)
        return result

    def _remember(self, measurement: Measurement, result: Correction) -> None:
        state, cov = self.ekf.snapshot()
        self._history.append(_Entry(self.stamp_sec, measurement, state, cov, result))
        self._stamps.append(self.stamp_sec)
        horizon = self.last_measurement_stamp_sec - self.history_length_sec
        cut = bisect.bisect_left(self._stamps, horizon)
        if cut > 0:
            del self._history[:cut]
            del self._stamps[:cut]

    def _rewind_and_replay(self, lagged: Measurement) -> Correction:
        # the last entry strictly before the lagged stamp (robot_localization reverts to stamp - 1 ns)
        keep = bisect.bisect_left(self._stamps, lagged.stamp_sec)
        if keep == 0:
            return self._reject(lagged, "older than history_length")
        anchor = self._history[keep - 1]
        replay = [entry.measurement for entry in self._history[keep:]]
        for entry in self._history[keep:]:  # their outcome is replaced by the replayed one
            if entry.result.accepted:
                self.accepted[entry.measurement.source] -= 1
            else:
                self.rejected[(entry.measurement.source, entry.result.reason)] -= 1
        del self._history[keep:]
        del self._stamps[keep:]
        self.ekf.restore(anchor.state, anchor.covariance)
        self.stamp_sec = self.last_measurement_stamp_sec = anchor.stamp_sec
        self.replays += 1
        ordered = sorted([lagged, *replay], key=lambda m: (m.stamp_sec, m.sequence))
        result = Correction(False, math.nan)
        for measurement in ordered:
            outcome = self._apply(measurement)
            if measurement is lagged:
                result = outcome
        return result
