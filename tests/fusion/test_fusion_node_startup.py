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
