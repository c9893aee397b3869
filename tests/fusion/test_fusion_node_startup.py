"""The EKF node pays Numba's first-call cost where it is built, never on the loop it runs on."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_kernels_are_loaded_when_the_node_is_built():
    # A fresh interpreter: nothing has called a kernel yet. Building the node (in the thread that
    # builds the graph) must leave every kernel the message path uses ready, so the first /odom on
    # the priority loop does not import Numba and read its cache there (tens of ms: a stall).
    script = textwrap.dedent("""
        from aiorobot.fusion import EkfNode
        from aiorobot.fusion import _kernels as k
        assert not k.predict_inplace.signatures and not k.correct_inplace.signatures
        EkfNode(parameter_overrides={"odom0": "/odom", "print_diagnostics": False})
        for kernel in (k.predict_inplace, k.correct_inplace, k.covariance_status):
            assert kernel.signatures, kernel
        print("ok")
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stdout + result.stderr


def test_ukf_messages_use_the_kernels_compiled_at_construction():
    # the message path must call the UKF kernels with the argument types warm_up used, or Numba
    # compiles a second version on the priority loop at the first message
    import numpy as np

    from aiorobot.fusion import UkfNode
    from aiorobot.fusion import _ukf_kernels as k
    from aiorobot.msgs.nav_msgs import Odometry

    node = UkfNode(parameter_overrides={"odom0": "/odom", "print_diagnostics": False, "two_d_mode": True,
                                        "odom0_config": [True] * 6 + [True] * 6 + [False] * 3})  # fmt: skip
    kernels = (k.predict_inplace, k.correct_inplace)
    compiled = [len(kernel.signatures) for kernel in kernels]
    assert all(compiled)
    [cfg] = node.inputs
    stamp = node.now().nanoseconds
    for step in range(3):
        msg = Odometry()
        ns = stamp + step * 20_000_000
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(ns, 1_000_000_000)
        msg.header.frame_id, msg.child_frame_id = "odom", "base_link"
        msg.twist.twist.linear.x = 0.5
        msg.pose.covariance = (np.eye(6) * 1e-2).reshape(36)
        msg.twist.covariance = (np.eye(6) * 1e-4).reshape(36)
        node.on_message(cfg, msg)
    assert node.timeline.accepted == {"odom0_pose": 3, "odom0_twist": 3}
    assert [len(kernel.signatures) for kernel in kernels] == compiled
