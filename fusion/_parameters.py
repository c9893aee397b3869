"""robot_localization's ``ekf_node`` and ``ukf_node`` parameter names: the valid set and the nearest-name hint."""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable

__all__ = [
    "GLOBAL_PARAMETERS",
    "IGNORED_PARAMETERS",
    "INPUT_SUFFIXES",
    "UKF_PARAMETERS",
    "check_parameter_names",
    "input_names",
]

#: the names aiorobot reads, with robot_localization's meaning (docs/fusion.md)
GLOBAL_PARAMETERS = (
    "frequency", "sensor_timeout", "two_d_mode", "map_frame", "odom_frame", "base_link_frame",
    "world_frame", "publish_tf", "print_diagnostics", "smooth_lagged_data", "history_length",
    "process_noise_covariance", "initial_estimate_covariance", "initial_state",
    "disabled_at_startup", "gravitational_acceleration", "future_tolerance_sec",
)  # fmt: skip
#: robot_localization names accepted for compatibility but without effect (a warning says so)
IGNORED_PARAMETERS = (
    "transform_time_offset", "transform_timeout", "debug", "debug_out_file",
    "permit_corrected_publication", "publish_acceleration", "use_control", "stamped_control",
    "control_timeout", "control_config", "acceleration_limits", "deceleration_limits",
    "acceleration_gains", "deceleration_gains", "dynamic_process_noise_covariance",
    "use_dynamic_process_noise_covariance", "predict_to_current_time", "reset_on_time_jump",
)  # fmt: skip
#: ukf_node's own parameters (ukf_node.cpp): the unscented transform's spread and prior
UKF_PARAMETERS = ("alpha", "kappa", "beta")
INPUT_SUFFIXES = {
    "odom": ("", "_config", "_differential", "_relative", "_queue_size", "_pose_rejection_threshold",
             "_twist_rejection_threshold", "_pose_use_child_frame"),
    "pose": ("", "_config", "_differential", "_relative", "_queue_size", "_rejection_threshold",
             "_pose_use_child_frame"),
    "twist": ("", "_config", "_queue_size", "_rejection_threshold"),
    "imu": ("", "_config", "_differential", "_relative", "_queue_size", "_pose_rejection_threshold",
            "_twist_rejection_threshold", "_linear_acceleration_rejection_threshold",
            "_remove_gravitational_acceleration"),
}  # fmt: skip
_INPUT = re.compile(r"^(odom|imu|pose|twist)(\d+)$")


def input_names(names: list[str]) -> list[tuple[str, str]]:
    """``(name, kind)`` of each input topic parameter (``odom0`` -> ``("odom0", "odom")``), sorted."""
    found = []
    for name in names:
        m = _INPUT.match(name)
        if m:
            found.append((name, m.group(1), int(m.group(2))))
    return [(name, kind) for name, kind, _ in sorted(found, key=lambda f: (f[1], f[2]))]


def check_parameter_names(
    names: list[str], *, filter_parameters: tuple[str, ...] = (), source: Callable[[str], str | None] | None = None
) -> None:
    """Raise ``ValueError`` naming the first parameter that belongs to neither filter, where it was
    given (``source(name)``: a file and key, or ``-p``) and the nearest valid name.

    Valid: the shared names, the ignored ones, the inputs' options, ``use_sim_time`` and
    ``filter_parameters`` (both filters' own names: a node warns about the other filter's).
    """
    inputs = input_names(names)
    valid = set(GLOBAL_PARAMETERS) | set(IGNORED_PARAMETERS) | set(filter_parameters)
    for name, kind in inputs:
        valid.update(name + suffix for suffix in INPUT_SUFFIXES[kind])
    for name in sorted(names):
        if name in valid or name == "use_sim_time":
            continue
        candidates = sorted(valid)
        m = re.match(r"^(odom|imu|pose|twist)(\d+)_", name)
        if m:  # an input's option: suggest from that input kind's options
            candidates += [m.group(1) + m.group(2) + s for s in INPUT_SUFFIXES[m.group(1)] if s]
        close = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
        hint = f'; did you mean "{close[0]}"?' if close else ""
        where = source(name) if source is not None else None
        origin = f" (from {where})" if where else ""
        raise ValueError(f'unknown robot_localization parameter "{name}"{origin}{hint}')
