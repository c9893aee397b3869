"""A small workspace of two interface packages written by the tests, the second using the first."""

from __future__ import annotations

from pathlib import Path

_MANIFEST = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.1.0</version>
  <description>test interfaces</description>
  <maintainer email="dev@example.com">dev</maintainer>
  <license>Apache-2.0</license>
  {depends}
  <member_of_group>rosidl_interface_packages</member_of_group>
</package>
"""


def write_package(root: Path, name: str, files: dict[str, str], depends: tuple[str, ...] = ()) -> Path:
    """``root/name`` with a package.xml and ``files`` (``msg/Foo.msg`` -> text)."""
    folder = root / name
    folder.mkdir(parents=True)
    deps = "\n  ".join(f"<depend>{d}</depend>" for d in depends)
    (folder / "package.xml").write_text(_MANIFEST.format(name=name, depends=deps))
    for rel, text in files.items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_text(text)
    return folder


def write_workspace(root: Path, tag: str) -> tuple[str, str]:
    """``<tag>_geometry`` (a message) and ``<tag>_robot`` (msg, srv, action using it) under ``root``.

    The registry is process-wide, so each test uses its own ``tag``. Returns the two names.
    """
    base, robot = f"{tag}_geometry", f"{tag}_robot"
    write_package(root, base, {"msg/Pair.msg": "# a pair\nfloat64 x\nfloat64 y 2.5\n"})
    write_package(root, robot, {
        "msg/Status.msg": (f"uint8 MODE_IDLE=0\nuint8 MODE_RUN=1\n{base}/Pair offset\nLimits limits\n"
                           "std_msgs/Header header\nstring note \"hi # there\"\n"),
        "msg/Limits.msg": "float32 max_speed 1.5\nint32[<=4] codes\n",
        "srv/GetStatus.srv": "string name\n---\nStatus status\nbool ok\n",
        "action/Count.action": f"int32 order\n---\nint32[] sequence\n---\n{base}/Pair last\n",
    }, depends=(base, "std_msgs"))
    return base, robot
