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
