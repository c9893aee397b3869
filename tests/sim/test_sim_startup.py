"""The simulator pays Numba's first-call cost where it is built, never on the running loop."""

from __future__ import annotations

import subprocess
import sys
import textwrap


def test_ray_casting_kernels_are_loaded_when_the_node_is_built():
    # A fresh interpreter: nothing has called a kernel yet. The first run after installing compiles
    # them (seconds); on the running main loop that is a stall the loop monitor reports with a page of
    # Numba's stack. Building the node (before any loop runs) must leave them ready.
    script = textwrap.dedent("""
        from aiorobot.sim import Simulator
        from aiorobot.sim import _raycast_kernel as k
        assert not k.cast_rays.signatures and not k.cast_rays_skipping.signatures
        Simulator(parameter_overrides={"world": "box"})
        assert k.cast_rays.signatures and k.cast_rays_skipping.signatures
        print("ok")
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stdout + result.stderr
