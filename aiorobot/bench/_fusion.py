"""Fusion figures for ``aiorobot bench fusion``.

``run()`` measures, in one process and one run:

- one EKF step (predict 20 ms + update with a 6-value odometry measurement: x, y, yaw, vx, vy,
  vyaw) of :class:`aiorobot.fusion.Ekf`, beside filterpy's ``ExtendedKalmanFilter`` on the same
  model (robot_localization's transfer function and Jacobian) and data: median, p99, ratio;
- one :class:`aiorobot.fusion.ComplementaryEstimator` step;
- end to end: ``/odom`` published on the main loop -> ``odometry/filtered`` received by a node on
  the priority loop, with :class:`aiorobot.fusion.EkfNode` on the priority loop.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

import numpy as np

__all__ = ["run", "table"]


def _stats(samples_ns: list[int]) -> dict[str, float]:
    a = np.asarray(samples_ns, dtype=np.float64) / 1000.0
    return {"median_us": float(np.median(a)), "p99_us": float(np.percentile(a, 99)), "n": int(a.size)}


def _odometry_stream(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    z = np.zeros((n, 15))
    z[:, 0] = np.arange(n) * 0.01 + rng.normal(0, 0.01, n)
    z[:, 6] = 0.5 + rng.normal(0, 0.01, n)
    z[:, 11] = 0.1 + rng.normal(0, 0.01, n)
    R = np.eye(15) * 1e-3
    mask = np.zeros(15, bool)
    mask[[0, 1, 5, 6, 7, 11]] = True
    return z, R, mask


def _ekf_step(n: int) -> dict[str, float]:
    from aiorobot.fusion import Ekf

    z, R, mask = _odometry_stream(n)
    ekf = Ekf(initial_covariance=np.eye(15) * 0.1)
    for i in range(50):  # compile / warm up
        ekf.predict(0.02)
        ekf.update(z[i], R, mask)
    samples = []
    clock = time.perf_counter_ns
    for i in range(n):
        t0 = clock()
        ekf.predict(0.02)
        ekf.update(z[i], R, mask)
        samples.append(clock() - t0)
    return _stats(samples)


def _filterpy_step(n: int) -> dict[str, float] | None:
    try:
        from filterpy.kalman import ExtendedKalmanFilter
    except ImportError:
        return None
    from aiorobot.fusion import DEFAULT_PROCESS_NOISE
    from aiorobot.fusion._kernels import transfer

    z, R, mask = _odometry_stream(n)
    idx = np.flatnonzero(mask)
    H = np.zeros((idx.size, 15))
    H[np.arange(idx.size), idx] = 1.0
    Rs = R[np.ix_(idx, idx)]
    f = ExtendedKalmanFilter(dim_x=15, dim_z=idx.size)
    f.P = np.eye(15) * 0.1
    T = np.zeros((15, 15))
    J = np.zeros((15, 15))
    dt = 0.02

    def step(i: int) -> None:
        transfer(f.x.reshape(-1), dt, T, J)
        f.F = J
        f.Q = DEFAULT_PROCESS_NOISE * dt
        f.predict()
        f.x = T @ f.x  # the nonlinear state transition (predict() above propagated P with J)
        f.update(z[i][idx].reshape(-1, 1), lambda x: H, lambda x: H @ x, Rs)

    for i in range(50):
        step(i)
    samples = []
    clock = time.perf_counter_ns
    for i in range(n):
        t0 = clock()
        step(i)
        samples.append(clock() - t0)
    return _stats(samples)


def _complementary_step(n: int) -> dict[str, float]:
    from aiorobot.fusion import ComplementaryEstimator

    f = ComplementaryEstimator()
    f.set_odometry_yaw(0.1)
    samples = []
    clock = time.perf_counter_ns
    for i in range(n):
        t0 = clock()
        f.step(0.01 * i, 0.01, -0.02, 0.3, 0.1, 0.2, 9.8)
        samples.append(clock() - t0)
    return _stats(samples[100:])


async def _end_to_end(count: int, period_sec: float) -> dict[str, float]:
    from aiorobot import Node, Runtime
    from aiorobot.fusion import EkfNode
    from aiorobot.msgs.nav_msgs import Odometry

    sent: dict[int, int] = {}
    latencies: list[int] = []
    done = asyncio.Event()
    loop = asyncio.get_running_loop()

    class Receiver(Node):
        def __init__(self) -> None:
            super().__init__("fusion_bench_receiver")
            self.create_subscription(Odometry, "odometry/filtered", self.on_filtered, 100)

        def on_filtered(self, msg: Any) -> None:
            now = time.perf_counter_ns()
            key = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            start = sent.pop(key, None)
            if start is not None:
                latencies.append(now - start)
                if len(latencies) >= count:
                    loop.call_soon_threadsafe(done.set)

    config = [False] * 6 + [True, True, False, False, False, True] + [False] * 3
    async with Runtime() as rt:
        pub_node = rt.add_node(Node("fusion_bench_odom"))
        pub = pub_node.create_publisher(Odometry, "/odom", 100)
        rt.add_node(Receiver(), executor="priority")
        rt.add_node(
            EkfNode(
                parameter_overrides={
                    "odom0": "/odom", "odom0_config": config, "two_d_mode": True, "publish_tf": True,
                    "print_diagnostics": False, "sensor_timeout": 1000.0,
                }  # fmt: skip
            ),
            executor="priority",
        )
        await asyncio.sleep(0.2)
        base = rt.now().nanoseconds
        msg = Odometry()
        msg.header.frame_id, msg.child_frame_id = "odom", "base_link"
        msg.twist.twist.linear.x = 0.5
        msg.twist.covariance = (np.eye(6) * 1e-3).reshape(36)
        for i in range(count + 20):
            stamp = base + i * int(period_sec * 1e9)
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp, 1_000_000_000)
            if i >= 20:
                sent[stamp] = time.perf_counter_ns()
            pub.publish(msg)
            await asyncio.sleep(period_sec)
            if done.is_set():
                break
        try:
            await asyncio.wait_for(done.wait(), 5.0)
        except TimeoutError:
            pass
    return _stats(latencies) if latencies else {"median_us": float("nan"), "p99_us": float("nan"), "n": 0}


def run(quick: bool = False) -> dict[str, Any]:
    n = 2000 if quick else 20000
    ekf = _ekf_step(n)
    fp = _filterpy_step(n // 4)
    out: dict[str, Any] = {"ekf_step": ekf, "complementary_step": _complementary_step(n)}
    if fp is not None:
        out["filterpy_step"] = fp
        out["filterpy_ratio_median"] = fp["median_us"] / ekf["median_us"]
    out["end_to_end"] = asyncio.run(_end_to_end(200 if quick else 1000, 0.01))
    return out


def table(part: dict[str, Any]) -> Any:
    from ._report import figure_table

    rows = [("EKF predict+update, 6-value odometry", part["ekf_step"]["median_us"], part["ekf_step"]["p99_us"])]
    if "filterpy_step" in part:
        rows.append(("filterpy ExtendedKalmanFilter, same model", part["filterpy_step"]["median_us"], part["filterpy_step"]["p99_us"]))
    rows.append(("complementary filter step", part["complementary_step"]["median_us"], part["complementary_step"]["p99_us"]))
    rows.append(("/odom -> odometry/filtered (priority loop)", part["end_to_end"]["median_us"], part["end_to_end"]["p99_us"]))
    caption = None
    if "filterpy_ratio_median" in part:
        caption = f"filterpy / aiorobot median: {part['filterpy_ratio_median']:.1f}x (same run)"
    return figure_table("fusion", ("step", "median us", "p99 us"), rows, caption=caption)
