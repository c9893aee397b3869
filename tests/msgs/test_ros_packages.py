"""register_package: ROS interface packages read from folders, as rosidl reads them."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import aiorobot.msgs as msgs

from ._workspace import write_package, write_workspace

_tags = (f"rp{i}" for i in itertools.count())


def test_a_workspace_of_packages_that_use_each_other_registers_in_any_order(tmp_path: Path) -> None:
    base, robot = write_workspace(tmp_path / "src", next(_tags))
    names = msgs.register_package(tmp_path)  # the workspace root: packages are searched for
    assert sorted(names) == sorted([f"{base}/msg/Pair", f"{robot}/msg/Limits", f"{robot}/msg/Status",
                                    f"{robot}/srv/GetStatus", f"{robot}/action/Count"])
    status = msgs.get(f"{robot}/msg/Status")()
    assert status.offset.y == 2.5 and status.limits.max_speed == 1.5 and status.note == "hi # there"
    assert status.MODE_RUN == 1
    count = msgs.get(f"{robot}/action/Count")
    goal = count.Goal(order=5)
    assert msgs.deserialize(msgs.serialize(goal), count.Goal) == goal
    response = msgs.get(f"{robot}/srv/GetStatus").Response(ok=True)
    assert msgs.deserialize(msgs.serialize(response), type(response)) == response
    assert msgs.type_hash(count).startswith("RIHS01_")


def test_registered_messages_hash_as_rosbags_does(tmp_path: Path) -> None:
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    base, robot = write_workspace(tmp_path, next(_tags))
    msgs.register_package(tmp_path / robot, tmp_path / base)  # two package folders, dependent first
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for pkg, name in ((base, "Pair"), (robot, "Limits"), (robot, "Status")):
        types.update(get_types_from_msg((tmp_path / pkg / "msg" / f"{name}.msg").read_text(), f"{pkg}/msg/{name}"))
    store.register(types)
    for name in (f"{base}/msg/Pair", f"{robot}/msg/Status"):
        assert msgs.type_hash(name) == store.hash_rihs01(name)


def test_registered_package_is_a_module_of_aiorobot_msgs(tmp_path: Path) -> None:
    base, robot = write_workspace(tmp_path, next(_tags))
    msgs.register_package(tmp_path)
    module = __import__(f"aiorobot.msgs.{robot}", fromlist=["Status"])
    assert module.__all__ == ["Count", "GetStatus", "Limits", "Status"]
    assert module.Status.__msgtype__ == f"{robot}/msg/Status"
    with pytest.raises(AttributeError, match=r"has no interface type 'Statuz'; did you mean 'Status'"):
        module.Statuz  # noqa: B018


def test_a_dependency_left_out_registers_nothing_and_names_the_file(tmp_path: Path) -> None:
    base, robot = write_workspace(tmp_path, next(_tags))
    status = tmp_path / robot / "msg" / "Status.msg"
    with pytest.raises(LookupError, match=(
            rf"^{status}: {robot}/msg/Status uses {base}/msg/Pair, which is unknown; add the folder "
            rf"of package '{base}' too")):
        msgs.register_package(tmp_path / robot)
    with pytest.raises(LookupError):
        msgs.get(f"{robot}/msg/Limits")  # all or nothing
    msgs.register_package(tmp_path / base, tmp_path / robot)


def test_a_type_redefined_differently_from_aiorobots_is_refused(tmp_path: Path) -> None:
    folder = write_package(tmp_path, "std_msgs", {"msg/String.msg": "string data\nint32 extra\n"})
    with pytest.raises(ValueError, match=r"String.msg: defines std_msgs/msg/String differently"):
        msgs.register_package(folder)
    same = write_package(tmp_path / "same", "std_msgs", {"msg/String.msg": "# upstream's\nstring data\n"})
    assert msgs.register_package(same) == ["std_msgs/msg/String"]  # identical: accepted, a no-op


def test_the_same_package_twice_with_different_files_is_refused(tmp_path: Path) -> None:
    tag = next(_tags)
    write_package(tmp_path / "src", f"{tag}_a", {"msg/A.msg": "int32 a\n"})
    write_package(tmp_path / "install", f"{tag}_a", {"msg/A.msg": "int64 a\n"})
    with pytest.raises(ValueError, match=rf"{tag}_a/msg/A is also defined, differently, in"):
        msgs.register_package(tmp_path)


@pytest.mark.parametrize(("make", "message"), [
    (lambda root: root / "nope", r"nope: expected a ROS package folder .* no such folder$"),
    (lambda root: root, r"found no package with interface files$"),
    (lambda root: write_package(root, "empty_pkg", {"README": "x"}),
     r"empty_pkg: package 'empty_pkg' has no interface files \(expected msg/\*.msg"),
    (lambda root: write_package(root, "Bad-Name", {"msg/A.msg": "int32 a\n"}),
     r"package.xml: expected <name> to be a package name like 'my_msgs' .* found 'Bad-Name'$"),
    (lambda root: write_package(root, "lower_pkg", {"msg/lower.msg": "int32 a\n"}),
     r"lower.msg: expected a type name in CamelCase .* found 'lower'$"),
    (lambda root: write_package(root, "typo_pkg", {"msg/A.msg": "flaot64 a\n"}),
     r"A.msg: typo_pkg/msg/A uses typo_pkg/msg/flaot64, which is unknown: package 'typo_pkg' has no "
     r"msg/flaot64.msg$"),
    (lambda root: write_package(root, "sect_pkg", {"srv/S.srv": "int32 a\n"}),
     r"S.srv: sect_pkg/srv/S: expected 2 sections separated by '---' lines, got 1$"),
])
def test_bad_folders_and_files_get_one_line_naming_them(tmp_path: Path, make, message: str) -> None:
    target = make(tmp_path)
    with pytest.raises((ValueError, LookupError), match=message) as info:
        msgs.register_package(target)
    assert "\n" not in str(info.value)


def test_ignored_folders_and_idl_only_types(tmp_path: Path) -> None:
    tag = next(_tags)
    skipped = write_package(tmp_path, f"{tag}_skipped", {"msg/A.msg": "int32 a\n"})
    (skipped / "COLCON_IGNORE").write_text("")
    write_package(tmp_path, f"{tag}_idl", {"msg/B.msg": "int32 b\n", "msg/B.idl": "...",
                                           "msg/OnlyIdl.idl": "module x {};"})
    with pytest.warns(UserWarning, match=r"1 .idl file\(s\) without a .msg/.srv/.action beside them are not read"):
        names = msgs.register_package(tmp_path)
    assert names == [f"{tag}_idl/msg/B"]


def test_register_from_env_reads_a_path_list(tmp_path: Path) -> None:
    import os

    base, robot = write_workspace(tmp_path, next(_tags))
    value = os.pathsep.join([str(tmp_path / robot), str(tmp_path / base)])
    assert len(msgs.register_from_env({"AIOROBOT_INTERFACES": value})) == 5
    assert msgs.register_from_env({}) == []
    with pytest.raises(ValueError, match=r"^AIOROBOT_INTERFACES: .*missing: expected a ROS package folder"):
        msgs.register_from_env({"AIOROBOT_INTERFACES": str(tmp_path / "missing")})

