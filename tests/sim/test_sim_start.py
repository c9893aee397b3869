"""Where the robot starts on maps that carry no start: Nav2's map_server files (issue 26, item 9).

Each test writes its own map_server YAML + PGM shaped like nav2_bringup's maps: a mapped
arena of free cells (254) walled by occupied cells (0) in unknown space (205); a pillar at
the origin whose inside is unknown (``turtlebot3_world``, ``tb3_sandbox``); or the origin at
the map's corner (``depot``). Thresholds, ``negate`` and ``mode`` as Nav2 writes them.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from aiorobot.sim import World, WorldError, nearest_free_spot, parse_start, resolve_start

FREE, OCCUPIED, UNKNOWN = 254, 0, 205
RES = 0.05


def _arena(size: int = 120, pillar: bool = True) -> np.ndarray:
    """Image rows top-down: unknown, a walled free square inside, a hollow pillar at the centre."""
    image = np.full((size, size), UNKNOWN, dtype=np.uint8)
    image[10:-10, 10:-10] = OCCUPIED
    image[12:-12, 12:-12] = FREE
    if pillar:
        c = size // 2
        image[c - 4:c + 4, c - 4:c + 4] = OCCUPIED  # a 0.4 m pillar: its ring seen by the lidar...
        image[c - 2:c + 2, c - 2:c + 2] = UNKNOWN  # ...its inside never seen
    return image


def _write_map(directory: Path, name: str, image: np.ndarray, origin: list[float], *, negate: int = 0,
               free_thresh: float = 0.196, mode: str | None = "trinary") -> Path:
    h, w = image.shape
    pixels = 255 - image if negate else image
    (directory / f"{name}.pgm").write_bytes(f"P5\n{w} {h}\n255\n".encode() + pixels.tobytes())
    text = (f"image: {name}.pgm\n" + (f"mode: {mode}\n" if mode else "") +
            f"resolution: {RES}\norigin: {origin}\nnegate: {negate}\noccupied_thresh: 0.65\nfree_thresh: {free_thresh}\n")
    path = directory / f"{name}.yaml"
    path.write_text(text)
    return path


def _known_free_disc(world: World, x: float, y: float, radius: float) -> bool:
    """Independent check: every cell that the disc touches is free (0) and on the map."""
    r0, c0 = world.cell(x - radius, y - radius)
    r1, c1 = world.cell(x + radius, y + radius)
    h, w = world.occupancy.shape
    if r0 < 0 or c0 < 0 or r1 >= h or c1 >= w:
        return False
    ox, oy, _ = world.origin
    for row in range(r0, r1 + 1):
        for col in range(c0, c1 + 1):
            cx, cy = ox + col * RES, oy + row * RES
            nx, ny = min(max(x, cx), cx + RES), min(max(y, cy), cy + RES)
            if math.hypot(nx - x, ny - y) <= radius and world.occupancy[row, col] != 0:
                return False
    return True


@pytest.mark.parametrize("negate", [0, 1])
def test_a_pillar_on_the_origin_moves_the_start_to_the_nearest_free_cell(tmp_path: Path, negate: int) -> None:
    path = _write_map(tmp_path, "tb3_like", _arena(), [-3.0, -3.0, 0.0], negate=negate, mode=None)
    world = World.load(path)
    assert world.start == (0.0, 0.0, 0.0)  # a Nav2 map has no start: the origin
    assert world.occupancy[world.cell(0.0, 0.0)] == -1  # inside the pillar, never seen
    choice = resolve_start(world, None, 0.22)
    x, y, yaw = choice.pose
    assert choice.moved_from == (0.0, 0.0, 0.0) and yaw == 0.0
    assert _known_free_disc(world, x, y, 0.22) and world.is_free_disc(x, y, 0.22)
    # the nearest such cell: no cell centre closer to the origin qualifies
    found = math.hypot(x, y)
    for row in range(world.occupancy.shape[0]):
        for col in range(world.occupancy.shape[1]):
            cx, cy = -3.0 + (col + 0.5) * RES, -3.0 + (row + 0.5) * RES
            if math.hypot(cx, cy) < found - 1e-9:
                assert not _known_free_disc(world, cx, cy, 0.22), (cx, cy)
    assert choice.warning == (
        f"{path}: the origin (0, 0) is inside an obstacle (an occupied cell within robot_radius 0.22 m); starting at "
        f"the free cell nearest to it, ({x:g}, {y:g}, 0); give a start (--start X,Y,YAW, or the simulator's start "
        "parameter) to choose another"
    )


def test_an_origin_on_the_map_corner_moves_inside_by_nav2_thresholds(tmp_path: Path) -> None:
    # depot's free_thresh 0.25 reads unknown grey (205: p = 0.196) as free, as Nav2's map_server does
    path = _write_map(tmp_path, "depot_like", _arena(60, pillar=False), [0.0, 0.0, 0.0], free_thresh=0.25)
    world = World.load(path)
    assert world.occupancy[0, 0] == 0
    choice = resolve_start(world, None, 0.22)
    assert choice.reason == "within robot_radius 0.22 m of the map's edge"
    # the first cell centre whose disc clears both edges: (4 + 0.5) cells in
    assert choice.pose == pytest.approx((0.225, 0.225, 0.0))
    # under 0.196 the grey is unknown: the start moves into the walled arena (free from 12 cells in)
    path.write_text(path.read_text().replace("free_thresh: 0.25", "free_thresh: 0.196"))
    world = World.load(path)
    assert world.occupancy[0, 0] == -1
    x, y, _ = resolve_start(world, None, 0.22).pose
    assert x == pytest.approx(y) and 12 * RES + 0.22 < x < 12 * RES + 0.22 + RES and _known_free_disc(world, x, y, 0.22)


def test_a_free_start_stays_and_a_given_start_is_checked(tmp_path: Path) -> None:
    path = _write_map(tmp_path, "open", _arena(pillar=False), [-3.0, -3.0, 0.0])
    world = World.load(path)
    assert resolve_start(world, None, 0.22).moved_from is None
    assert resolve_start(world, None, 0.22).pose == (0.0, 0.0, 0.0)
    assert resolve_start(world, [-1.0, 0.5, 1.5], 0.22).pose == (-1.0, 0.5, 1.5)
    with pytest.raises(WorldError, match=r"open\.yaml: start \(-2\.4, 0\.01\) is inside an obstacle .*; the nearest free "
                                         r"spot is \(-2\.175, 0\.025\)"):
        resolve_start(world, [-2.4, 0.01, 0.0], 0.22)
    with pytest.raises(WorldError, match=r"start \(9, 0\) is off the map \(x -3\.\.3, y -3\.\.3\)"):
        resolve_start(world, [9.0, 0.0, 0.0], 0.22)
    with pytest.raises(WorldError, match=r"start: expected \[x, y, yaw\]"):
        resolve_start(world, [1.0, 2.0], 0.22)
    assert nearest_free_spot(World.load(_write_map(tmp_path, "void", np.full((20, 20), UNKNOWN, np.uint8),
                                                   [0.0, 0.0, 0.0])), 0.0, 0.0, 0.22) is None
    assert parse_start("-1,2") == (-1.0, 2.0, 0.0) and parse_start(" -1, 2, 1.5") == (-1.0, 2.0, 1.5)
    with pytest.raises(ValueError, match=r"expected X,Y or X,Y,YAW numbers .* found '1,2,3,4'"):
        parse_start("1,2,3,4")


def test_a_world_with_no_free_spot_says_so(tmp_path: Path) -> None:
    path = _write_map(tmp_path, "void", np.full((20, 20), UNKNOWN, np.uint8), [-0.5, -0.5, 0.0])
    with pytest.raises(WorldError, match=r"void\.yaml: the start \(0, 0\) is in unknown space \(an unknown cell "
                                         r"within robot_radius 0\.22 m\), and no known-free spot"):
        resolve_start(World.load(path), None, 0.22)


def test_the_simulator_takes_a_start_parameter_and_moves_a_blocked_origin(tmp_path: Path) -> None:
    from aiorobot.sim import Simulator

    path = _write_map(tmp_path, "tb3_like", _arena(), [-3.0, -3.0, 0.0])
    sim = Simulator(parameter_overrides={"world": str(path), "real_time_factor": 0.0, "camera_rate": 0.0})
    assert sim.start == resolve_start(sim.world, None, 0.22).pose != (0.0, 0.0, 0.0)
    assert tuple(sim.body.pose) == pytest.approx(sim.start)
    sim = Simulator(parameter_overrides={"world": str(path), "real_time_factor": 0.0, "camera_rate": 0.0,
                                         "start": [-1.0, -2.0, 0.5]})
    assert sim.start == (-1.0, -2.0, 0.5) and tuple(sim.body.pose) == pytest.approx((-1.0, -2.0, 0.5))
    with pytest.raises(WorldError, match=r"start \(0\.1, 0\) is inside an obstacle"):
        Simulator(parameter_overrides={"world": str(path), "start": [0.1, 0.0, 0.0]})


def _sim(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "aiorobot.cli", "sim", "--rtf", "0", "--duration", "0.5", *args],
                          capture_output=True, text=True, timeout=60)


def test_aiorobot_sim_runs_a_nav2_map_with_one_warning_or_at_a_negative_start(tmp_path: Path) -> None:
    path = _write_map(tmp_path, "tb3_like", _arena(), [-3.0, -3.0, 0.0])
    done = _sim("--world", str(path))
    assert done.returncode == 0, done.stderr
    warnings = [line for line in done.stderr.splitlines() if "WARN" in line]
    assert len(warnings) == 1 and "the origin (0, 0) is inside an obstacle" in warnings[0], done.stderr
    assert "Traceback" not in done.stderr
    done = _sim("--world", str(path), "--start", "-1.5,-2,1.5708")
    assert done.returncode == 0, done.stderr
    assert "WARN" not in done.stderr and "final pose (-1.500, -2.000, +90.0 deg)" in done.stdout
    done = _sim("--world", str(path), "--start", "-0.1,0")
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert f"aiorobot sim: error: {path}: start (-0.1, 0) is inside an obstacle" in done.stderr
