"""``[record]`` and ``[runtime] foxglove`` in a graph file: `aiorobot run` records the run and serves it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from aiorobot.bag import BagReader


def test_aiorobot_run_records_the_graph_into_the_bag_the_config_names(tmp_path: Path) -> None:
    config = tmp_path / "graph.toml"
    bag = tmp_path / "run_bag"
    config.write_text(
        "[runtime]\nfoxglove = { port = 0 }\n"
        "[[nodes]]\nname = \"imu\"\nuse = \"aiorobot.examples.sensor:ImuPublisher\"\n"
        f"[record]\npath = \"{bag}\"\ntopics = [\"/imu\"]\n"
    )
    done = subprocess.run([sys.executable, "-m", "aiorobot.cli", "run", str(config), "--duration", "1.5"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    with BagReader(bag) as reader:
        assert [t.name for t in reader.topics] == ["/imu"]
        assert reader.message_count > 10
    assert "Foxglove: open ws://127.0.0.1:" in done.stderr


def test_a_bag_directory_that_exists_is_a_config_error_before_anything_starts(tmp_path: Path) -> None:
    config = tmp_path / "graph.toml"
    (tmp_path / "taken").mkdir()
    config.write_text(f"[[nodes]]\nuse = \"aiorobot.examples.sensor:ImuPublisher\"\n[record]\npath = \"{tmp_path / 'taken'}\"\n")
    done = subprocess.run([sys.executable, "-m", "aiorobot.cli", "run", str(config), "--duration", "1"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert "record.path:" in done.stderr and "exists already" in done.stderr
    assert done.stderr.count("\n") == 1
