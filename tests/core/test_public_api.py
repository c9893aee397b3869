"""The public surface: every public module has __all__, and its names import."""

import importlib
import pkgutil

import aiorobot


def _public_modules():
    yield aiorobot
    for info in pkgutil.walk_packages(aiorobot.__path__, "aiorobot."):
        parts = info.name.split(".")
        if any(p.startswith("_") for p in parts) or parts[1] in ("bench", "cli", "examples"):
            continue
        yield importlib.import_module(info.name)


def test_every_public_module_has_all_and_its_names_exist():
    for module in _public_modules():
        assert hasattr(module, "__all__"), module.__name__
        for name in module.__all__:
            assert hasattr(module, name), f"{module.__name__}.{name}"


def test_api_md_names_import_from_aiorobot():
    for name in [
        "Node", "Runtime", "QoSProfile", "ReliabilityPolicy", "DurabilityPolicy", "HistoryPolicy",
        "qos_profile_sensor_data", "qos_profile_system_default", "QoSIncompatibleError",
        "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup", "Parameter", "Time", "Duration",
        "ServiceError", "run",
    ]:
        assert hasattr(aiorobot, name), name


def test_import_aiorobot_is_light_and_names_load_on_use():
    import subprocess
    import sys

    code = (
        "import sys, aiorobot\n"
        "heavy = [m for m in ('numpy', 'numba', 'cv2', 'scipy', 'rosbags', 'asyncio') if m in sys.modules]\n"
        "assert heavy == [], heavy\n"
        "from aiorobot import Node\n"
        "assert aiorobot.msgs.get('geometry_msgs/msg/Twist').__msgtype__ == 'geometry_msgs/msg/Twist'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_one_list_of_public_names_and_the_type_checking_imports_agree_with_it():
    """``_EXPORTS`` is the list; ``__all__`` is derived from it and the TYPE_CHECKING imports restate it."""
    import ast
    import importlib
    from pathlib import Path

    assert aiorobot.__all__ == sorted(aiorobot._EXPORTS, key=str.lower)
    tree = ast.parse(Path(aiorobot.__file__).read_text())
    blocks = [n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", None) == "TYPE_CHECKING"]
    assert len(blocks) == 1
    typed = {}
    for stmt in blocks[0].body:
        assert isinstance(stmt, ast.ImportFrom) and stmt.level == 1, ast.dump(stmt)
        for alias in stmt.names:
            assert alias.asname is None, alias.name
            assert alias.name not in typed, f"{alias.name} imported twice"
            typed[alias.name] = stmt.module
    assert typed == aiorobot._EXPORTS
    for name, module in aiorobot._EXPORTS.items():
        assert hasattr(importlib.import_module(f"aiorobot.{module}"), name), f"aiorobot.{module}.{name}"
