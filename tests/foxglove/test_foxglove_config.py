"""``[runtime] foxglove = { asset_roots = [...] }``: folders relative to the config file, a missing
one named with its key path before anything starts."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from aiorobot.launch import ConfigError, load_config


def _write(tmp_path: Path, roots: str) -> Path:
    path = tmp_path / "graph.toml"
    path.write_text(f'[runtime]\nfoxglove = {{ port = 0, asset_roots = {roots} }}\n[[nodes]]\nuse = "m:C"\n', encoding="utf-8")
    return path


def test_asset_roots_resolve_relative_to_the_config_file(tmp_path: Path) -> None:
    (tmp_path / "robot" / "meshes").mkdir(parents=True)
    config = load_config(_write(tmp_path, '["robot", "robot/meshes"]'))
    assert config.foxglove is not None
    assert config.foxglove.asset_roots == (str(tmp_path / "robot"), str(tmp_path / "robot" / "meshes"))


def test_a_missing_asset_root_is_a_config_error_with_its_key(tmp_path: Path) -> None:
    path = _write(tmp_path, '["nope"]')
    expected = f"{path}: runtime.foxglove.asset_roots[0]: expected a folder, found no folder at {tmp_path / 'nope'}"
    with pytest.raises(ConfigError, match=rf"^{re.escape(expected)}$"):
        load_config(path)
