"""docs/api.md lists the public API and is linked from the README, as is coming-from-rclpy."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import aiorobot

ROOT = Path(__file__).resolve().parents[2]


def test_every_public_name_is_in_the_api_reference():
    text = (ROOT / "docs" / "api.md").read_text()
    missing = [name for name in aiorobot.__all__ if f"### `aiorobot.{name}`" not in text]
    assert not missing, f"regenerate docs/api.md with python tools/gen_api_docs.py; missing {missing}"


def test_the_generator_documents_every_public_name():
    spec = importlib.util.spec_from_file_location("gen_api_docs", ROOT / "tools" / "gen_api_docs.py")
    assert spec is not None and spec.loader is not None
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    text = gen.render()
    assert all(f"### `aiorobot.{name}`" in text for name in aiorobot.__all__)
    assert "class `Runtime(*, transport" in text and "shutdown_timeout" in text


def test_readme_links_the_reference_and_the_rclpy_page_and_the_docstring_points_to_it():
    readme = (ROOT / "README.md").read_text()
    assert "(docs/api.md)" in readme and "(docs/coming-from-rclpy.md)" in readme
    assert (ROOT / "docs" / "coming-from-rclpy.md").exists()
    assert "docs/api.md" in (aiorobot.__doc__ or "") and "See API.md" not in (aiorobot.__doc__ or "")
