"""ROS packages of interface files, read as rosidl reads them: ``register_package(DIR, ...)``.

A package is a folder with a ``package.xml`` (its ``<name>`` is the package name) and
``msg/*.msg``, ``srv/*.srv``, ``action/*.action`` files: a source package, or its
installed ``share/<pkg>`` folder. A folder that is no package is searched for packages
(a workspace's ``src``, an ``install`` tree), skipping folders marked ``COLCON_IGNORE`` or
``AMENT_IGNORE``. Every package found in one call is registered together, so packages
that use each other's types may come in any order; types of packages aiorobot ships
(ROS 2 Jazzy) resolve too. ``AIOROBOT_INTERFACES`` lists such folders, separated as
``PATH`` is (``os.pathsep``), for ``aiorobot exec`` and :func:`register_from_env`.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path
from typing import NamedTuple

from ._registry import register_many

__all__ = ["ENV_VAR", "InterfacePackage", "find_packages", "register_from_env", "register_package"]

ENV_VAR = "AIOROBOT_INTERFACES"
_KINDS = ("msg", "srv", "action")
_PACKAGE_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_TYPE_NAME = re.compile(r"^[A-Z][A-Za-z0-9]*$")
_IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE")


class InterfacePackage(NamedTuple):
    """A package folder and its interface files, ``(type name, file)`` in name order."""

    name: str
    path: Path
    files: tuple[tuple[str, Path], ...]


def _package_name(manifest: Path) -> str:
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(manifest).getroot()
    except (ET.ParseError, OSError) as err:
        raise ValueError(f"{manifest}: expected a package.xml (XML), cannot read it: {err}") from None
    name = (root.findtext("name") or "").strip()
    if not _PACKAGE_NAME.match(name):
        raise ValueError(f"{manifest}: expected <name> to be a package name like 'my_msgs' "
                         f"(lowercase letters, digits, '_'), found {name!r}")
    return name


def _read_package(folder: Path) -> InterfacePackage:
    name = _package_name(folder / "package.xml")
    files: list[tuple[str, Path]] = []
    unread: list[str] = []
    for kind in _KINDS:
        sub = folder / kind
        if not sub.is_dir():
            continue
        stems = set()
        for path in sorted(sub.glob(f"*.{kind}")):
            if not _TYPE_NAME.match(path.stem):
                raise ValueError(f"{path}: expected a type name in CamelCase (like 'MyType.{kind}'), "
                                 f"found {path.stem!r}")
            files.append((f"{name}/{kind}/{path.stem}", path))
            stems.add(path.stem)
        unread += [str(p) for p in sorted(sub.glob("*.idl")) if p.stem not in stems]
    if unread:
        warnings.warn(f"{folder}: {len(unread)} .idl file(s) without a .msg/.srv/.action beside them are not "
                      f"read (aiorobot reads .msg, .srv and .action files): {', '.join(unread)}",
                      UserWarning, stacklevel=4)
    return InterfacePackage(name, folder, tuple(files))


def find_packages(path: str | os.PathLike[str]) -> list[InterfacePackage]:
    """The interface packages at ``path``: the package itself, or those found below it.

    Raises ``ValueError`` (naming the path) when there is no such folder, when ``path``
    is a package without interface files, or when no interface package is found below it.
    """
    root = Path(path)
    if not root.is_dir():
        raise ValueError(f"{path}: expected a ROS package folder (package.xml with msg/, srv/ or action/) "
                         "or a folder of such packages; no such folder")
    if (root / "package.xml").is_file():
        package = _read_package(root)
        if not package.files:
            raise ValueError(f"{path}: package {package.name!r} has no interface files "
                             "(expected msg/*.msg, srv/*.srv or action/*.action)")
        return [package]
    found: list[InterfacePackage] = []
    for dirpath, dirnames, filenames in os.walk(root):
        if any(marker in filenames for marker in _IGNORE_MARKERS):
            dirnames[:] = []
            continue
        if "package.xml" in filenames:
            dirnames[:] = []
            package = _read_package(Path(dirpath))
            if package.files:
                found.append(package)
            continue
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
    if not found:
        raise ValueError(f"{path}: expected a ROS package folder (package.xml with msg/, srv/ or action/) "
                         "or a folder of such packages; found no package with interface files")
    return found


def register_package(*paths: str | os.PathLike[str]) -> list[str]:
    """Register the interface packages at ``paths`` (package folders or folders of them).

    Returns the registered type names (``pkg/msg/Name``, ``pkg/srv/Name``, ``pkg/action/Name``);
    their classes are then ``aiorobot.msgs.get(name)`` and ``aiorobot.msgs.<pkg>.<Name>``,
    and under ``aiorobot exec`` ``from <pkg>.msg import <Name>``. The same package found
    twice must define the same types. Raises ``ValueError`` (a bad folder, file or
    definition, a type defined differently from one aiorobot has) or ``LookupError`` (a
    field of a type no given package nor aiorobot defines), naming the file; nothing is
    registered then.
    """
    if not paths:
        raise ValueError("register_package: expected at least one folder")
    definitions: list[tuple[str, str, str]] = []
    seen: dict[str, tuple[str, Path]] = {}
    for path in paths:
        for package in find_packages(path):
            for name, file in package.files:
                text = file.read_text(encoding="utf-8")
                if name in seen:
                    if seen[name][0] != text:
                        raise ValueError(f"{file}: {name} is also defined, differently, in {seen[name][1]}; "
                                         "give one copy of each package")
                    continue
                seen[name] = (text, file)
                definitions.append((name, text, str(file)))
    names = register_many(definitions)
    from ._package import install_registered_finder

    install_registered_finder()
    return names


def register_from_env(environ: dict[str, str] | None = None) -> list[str]:
    """Register the folders ``AIOROBOT_INTERFACES`` lists (``os.pathsep``-separated); [] if unset."""
    value = (os.environ if environ is None else environ).get(ENV_VAR, "")
    folders = [p for p in value.split(os.pathsep) if p]
    if not folders:
        return []
    try:
        return register_package(*folders)
    except (ValueError, LookupError) as err:
        raise type(err)(f"{ENV_VAR}: {err}") from None
