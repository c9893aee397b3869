"""``UkfNode``: robot_localization's ``ukf_node``, :class:`EkfNode` with the unscented core."""

from __future__ import annotations

from typing import Any

from aiorobot import compile_kernels

from ._ekf_node import EkfNode
from ._ukf import Ukf

__all__ = ["UkfNode"]


class UkfNode(EkfNode):
    """robot_localization's ``ukf_node``: the inputs, timeline, outputs, tf, services and parameters
    of :class:`EkfNode`, plus ukf_node's ``alpha`` (0.001), ``kappa`` (0) and ``beta`` (2), on a
    :class:`Ukf` core. robot_localization's ukf.yaml loads as it is (``--params-file``).

    rclpy difference: as :class:`EkfNode`; the correction wraps the angle members of the state
    difference, where ukf.cpp wraps it at the measurement's position (docs/rclpy-differences.md).
    """

    _OTHER_FILTER_PARAMETERS: tuple[str, ...] = ()

    def __init__(self, name: str = "ukf_filter_node", **kw: Any) -> None:
        super().__init__(name, **kw)

    def _make_filter(self, p: dict[str, Any]) -> Ukf:
        d = self.declare_parameter
        alpha = d("alpha", 0.001, description="spread of the sigma points around the state").value
        kappa = d("kappa", 0.0, description="secondary scaling of the sigma points").value
        beta = d("beta", 2.0, description="prior knowledge of the distribution (2: Gaussian)").value
        compile_kernels(self.get_logger(), Ukf.warm_up)  # here, not on the priority loop at the first message
        return Ukf(
            process_noise=p["process_noise_covariance"],
            initial_covariance=p["initial_estimate_covariance"],
            initial_state=p["initial_state"],
            alpha=alpha,
            kappa=kappa,
            beta=beta,
        )
