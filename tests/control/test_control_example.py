"""``aiorobot run examples/mecanum_serial.toml`` drives the simulated base and prints odometry."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "mecanum_serial.toml"


def _runtime_available() -> bool:
    try:
        from aiorobot import Runtime  # noqa: F401
        import aiorobot.cli  # noqa: F401
    except ImportError:
        return False
    return True


@pytest.mark.skipif(not _runtime_available(), reason="needs the runtime and the aiorobot CLI")
def test_mecanum_serial_example_drives_the_square_and_prints_odometry(tmp_path):
    # the example as shipped, with its pty link moved into tmp_path so parallel runs do not share it
    text = EXAMPLE.read_text()
    assert text.count("/tmp/aiorobot-mecanum-serial") == 2
    config = tmp_path / "mecanum_serial.toml"
    config.write_text(text.replace("/tmp/aiorobot-mecanum-serial", str(tmp_path / "ttyMOTORS")))
    shutil.copy(EXAMPLE.parent / "square_cmd_vel.py", tmp_path / "square_cmd_vel.py")
    result = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "run", str(config), "--duration", "3"],
        capture_output=True,
        text=True,
        timeout=50,
    )
    assert result.returncode == 0, result.stderr
    lines = re.findall(r"odom x=([+-]\d+\.\d+) y=([+-]\d+\.\d+)", result.stdout)
    assert len(lines) >= 2, result.stdout
    # the square starts along +x, then turns to +y
    assert max(float(x) for x, _ in lines) > 0.15
    assert max(float(y) for _, y in lines) > 0.1
    summary = re.search(r"frames ok (\d+), CRC (\d+), truncated (\d+), garbage (\d+), oversize (\d+)", result.stdout)
    assert summary is not None, result.stdout
    ok, *bad = (int(v) for v in summary.groups())
    assert ok > 50 and bad == [0, 0, 0, 0]
    assert "Traceback" not in result.stderr
