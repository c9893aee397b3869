"""The aiorobot.tf package surface: one front door, light to import."""

from __future__ import annotations

import subprocess
import sys

import aiorobot.tf as tf


def test_every_public_name_is_exported_once_and_sorted():
    assert tf.__all__ == sorted(tf.__all__)
    assert len(set(tf.__all__)) == len(tf.__all__)
    for name in tf.__all__:
        assert getattr(tf, name) is not None


def test_importing_tf_does_not_import_numba_or_message_packages():
    code = (
        "import sys, aiorobot.tf; "
        "print(sorted(m for m in ('numba', 'aiorobot.msgs.geometry_msgs') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
