"""``aiorobot run examples/perception.toml`` builds the detection map from camera markers and lidar obstacles."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_perception_example_maps_the_four_markers():
    result = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "run", "perception.toml", "--duration", "6"],
        capture_output=True, text=True, timeout=55, cwd=EXAMPLES,
    )
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    found = {int(m[0]): tuple(map(float, m[1:])) for m in
             re.findall(r"detection map: marker (\d+) at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) in map", output)}
    # demo_sensors: camera at map (1.1, 0, 0.3) looking along +x, markers 2.5 m ahead
    expected = {3: (3.6, 0.6, 0.7), 11: (3.6, -0.6, 0.7), 27: (3.6, 0.6, -0.2), 42: (3.6, -0.6, -0.2)}
    assert set(found) == set(expected), output
    for marker_id, position in expected.items():
        assert max(abs(a - b) for a, b in zip(found[marker_id], position)) <= 0.03, (marker_id, found[marker_id])
    assert "Traceback" not in output
    # the ring's segment is gone (at exit the resource tracker would warn about a leaked segment)
    assert "leaked" not in output


def test_perception_on_the_simulator_maps_the_marker_in_view():
    """examples/perception_sim.toml: the simulator's camera through the ArUco worker into the map."""
    result = subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", "run", "perception_sim.toml", "--duration", "5"],
        capture_output=True, text=True, timeout=90, cwd=EXAMPLES,
    )
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    found = {int(m[0]): tuple(map(float, m[1:])) for m in
             re.findall(r"detection map: marker (\d+) at \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) in map", output)}
    # box world: the robot at the origin facing +x sees marker 0, centred on the x = 3 m wall, 0.25 m up
    assert set(found) == {0}, output
    assert max(abs(a - b) for a, b in zip(found[0], (3.0, 0.0, 0.25))) <= 0.03, found
    assert "Traceback" not in output
