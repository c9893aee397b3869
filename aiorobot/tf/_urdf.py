"""A URDF reader for robot state publishing: links, joints, origins, axes, mimics.

Pure: ``parse_urdf(text)`` returns a :class:`UrdfModel`, whose joints compute
their ``child2parent`` transform for a joint position, as ROS 2's
robot_state_publisher does through KDL (``origin * motion(position)``, the axis
in the joint frame, normalised). Everything the publisher relies on is checked
once here, and a malformed description raises :class:`URDFError` naming the
element and the problem.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from ._math import Quat, Vec, _q_from_rpy, _qmul, _qrot

__all__ = ["URDFError", "UrdfJoint", "UrdfModel", "load_urdf", "parse_urdf"]

MOVING_TYPES = frozenset({"revolute", "continuous", "prismatic"})
# KDL (and so robot_state_publisher) turns floating and planar joints into fixed ones
FIXED_TYPES = frozenset({"fixed", "floating", "planar"})
JOINT_TYPES = MOVING_TYPES | FIXED_TYPES


class URDFError(ValueError):
    """A robot description that cannot be used, with the element and the problem named."""


@dataclass(frozen=True, slots=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True, slots=True)
class UrdfJoint:
    """One joint: ``child2parent = origin * motion(position)``."""

    name: str
    type: str
    parent: str
    child: str
    xyz: Vec = (0.0, 0.0, 0.0)
    rpy: Vec = (0.0, 0.0, 0.0)
    axis: Vec = (1.0, 0.0, 0.0)
    lower: float | None = None
    upper: float | None = None
    mimic: Mimic | None = None

    @property
    def is_moving(self) -> bool:
        return self.type in MOVING_TYPES

    def transform(self, position: float = 0.0) -> tuple[Vec, Quat]:
        """(translation, rotation) of the child link in the parent link at ``position``.

        ``position`` is radians for revolute and continuous joints, metres for
        prismatic ones, ignored for fixed ones.
        """
        q0 = _q_from_rpy(*self.rpy)
        if self.type in ("revolute", "continuous"):
            half = 0.5 * position
            s = math.sin(half)
            ax, ay, az = self.axis
            return self.xyz, _qmul(q0, (ax * s, ay * s, az * s, math.cos(half)))
        if self.type == "prismatic":
            ax, ay, az = self.axis
            d = _qrot(q0, (ax * position, ay * position, az * position))
            x, y, z = self.xyz
            return (x + d[0], y + d[1], z + d[2]), q0
        return self.xyz, q0


@dataclass(frozen=True, slots=True)
class UrdfModel:
    """A parsed robot: its links, its joints by name, and the root link."""

    name: str
    links: tuple[str, ...]
    joints: dict[str, UrdfJoint]
    root: str

    @property
    def fixed_joints(self) -> list[UrdfJoint]:
        return [j for j in self.joints.values() if not j.is_moving]

    @property
    def moving_joints(self) -> list[UrdfJoint]:
        return [j for j in self.joints.values() if j.is_moving]


def _floats(text: str | None, count: int, where: str, default: tuple[float, ...]) -> tuple[float, ...]:
    if text is None:
        return default
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise URDFError(f"{where}: expected {count} numbers, got {text!r}") from None
    if len(values) != count:
        raise URDFError(f"{where}: expected {count} numbers, got {len(values)} in {text!r}")
    if not all(math.isfinite(v) for v in values):
        raise URDFError(f"{where}: expected finite numbers, got {text!r}")
    return values


def _float_attr(elem: ET.Element, name: str, where: str, default: float | None) -> float | None:
    text = elem.get(name)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise URDFError(f"{where}: attribute {name}={text!r} is not a number") from None
    if math.isnan(value):
        raise URDFError(f"{where}: attribute {name} is NaN")
    return value


def _parse_joint(elem: ET.Element, links: set[str]) -> UrdfJoint:
    name = elem.get("name")
    if not name:
        raise URDFError("<joint> without a name attribute: every joint needs name=\"...\"")
    where = f'joint "{name}"'
    jtype = elem.get("type")
    if jtype not in JOINT_TYPES:
        raise URDFError(
            f"{where}: type {jtype!r} is not a joint type; expected one of {', '.join(sorted(JOINT_TYPES))}"
        )
    ends = {}
    for tag in ("parent", "child"):
        e = elem.find(tag)
        link = e.get("link") if e is not None else None
        if not link:
            raise URDFError(f'{where}: missing <{tag} link="..."/>')
        if link not in links:
            raise URDFError(f'{where}: {tag} link "{link}" is not defined by any <link>')
        ends[tag] = link
    if ends["parent"] == ends["child"]:
        raise URDFError(f'{where}: parent and child are both "{ends["parent"]}"')
    origin = elem.find("origin")
    xyz = _floats(origin.get("xyz") if origin is not None else None, 3, f"{where} <origin xyz>", (0.0, 0.0, 0.0))
    rpy = _floats(origin.get("rpy") if origin is not None else None, 3, f"{where} <origin rpy>", (0.0, 0.0, 0.0))
    axis_e = elem.find("axis")
    axis = _floats(axis_e.get("xyz") if axis_e is not None else None, 3, f"{where} <axis xyz>", (1.0, 0.0, 0.0))
    norm = math.sqrt(sum(a * a for a in axis))
    if jtype in MOVING_TYPES and norm == 0.0:
        raise URDFError(f"{where}: <axis xyz> is the zero vector; give the joint's axis, e.g. \"0 0 1\"")
    if norm:
        axis = tuple(a / norm for a in axis)
    lower = upper = None
    limit = elem.find("limit")
    if jtype in ("revolute", "prismatic"):
        if limit is None:
            raise URDFError(f"{where}: a {jtype} joint needs <limit lower=... upper=... effort=... velocity=.../>")
        lower = _float_attr(limit, "lower", f"{where} <limit>", 0.0)
        upper = _float_attr(limit, "upper", f"{where} <limit>", 0.0)
    mimic = None
    mimic_e = elem.find("mimic")
    if mimic_e is not None:
        other = mimic_e.get("joint")
        if not other:
            raise URDFError(f'{where}: <mimic> needs joint="..."')
        mimic = Mimic(
            other,
            _float_attr(mimic_e, "multiplier", f"{where} <mimic>", 1.0),  # type: ignore[arg-type]
            _float_attr(mimic_e, "offset", f"{where} <mimic>", 0.0),  # type: ignore[arg-type]
        )
    return UrdfJoint(name, jtype, ends["parent"], ends["child"], xyz, rpy, axis, lower, upper, mimic)  # type: ignore[arg-type]


def parse_urdf(text: str, *, source: str = "robot_description") -> UrdfModel:
    """Parse a URDF document.

    Parameters
    ----------
    text
        The XML text.
    source
        Where it came from (a parameter or a path), used in error messages.

    Raises
    ------
    URDFError
        Naming ``source`` and the problem: XML syntax (with line and column), a
        root that is not ``<robot>``, missing or duplicate names, unknown joint
        types, joints naming undefined links, a link with two parents, loops,
        several or no root links, malformed numbers, mimics of unknown joints.
    """
    if not isinstance(text, str) or not text.strip():
        raise URDFError(f"{source}: the robot description is empty; expected URDF XML text")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, column = exc.position
        reason = str(exc).split(":")[0]  # expat's message without its own position
        raise URDFError(f"{source}: not well-formed XML at line {line}, column {column + 1}: {reason}") from None
    try:
        return _build(root)
    except URDFError as exc:
        raise URDFError(f"{source}: {exc}") from None


def _build(root: ET.Element) -> UrdfModel:
    if root.tag != "robot":
        raise URDFError(f"the root element is <{root.tag}>, expected <robot>")
    name = root.get("name", "")
    links: list[str] = []
    for link in root.findall("link"):
        lname = link.get("name")
        if not lname:
            raise URDFError('<link> without a name attribute: every link needs name="..."')
        if lname in links:
            raise URDFError(f'link "{lname}" is defined twice')
        links.append(lname)
    if not links:
        raise URDFError("no <link> elements: a robot needs at least one link")
    link_set = set(links)
    joints: dict[str, UrdfJoint] = {}
    parent_of: dict[str, str] = {}
    for elem in root.findall("joint"):
        joint = _parse_joint(elem, link_set)
        if joint.name in joints:
            raise URDFError(f'joint "{joint.name}" is defined twice')
        if joint.child in parent_of:
            raise URDFError(
                f'link "{joint.child}" has two parents: joint "{parent_of[joint.child]}" and joint '
                f'"{joint.name}" both name it as child (a URDF is a tree)'
            )
        joints[joint.name] = joint
        parent_of[joint.child] = joint.name
    for joint in joints.values():
        if joint.mimic is not None and joint.mimic.joint not in joints:
            raise URDFError(f'joint "{joint.name}" mimics joint "{joint.mimic.joint}", which does not exist')
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        if not roots:
            raise URDFError("every link has a parent, so the joints form a loop; a URDF needs one root link")
        raise URDFError(
            f"{len(roots)} root links ({', '.join(roots)}): connect them with joints so one link is the root"
        )
    # every link must reach the root: otherwise a loop hides in a detached part
    child_parent = {j.child: j.parent for j in joints.values()}
    for link_name in links:
        seen = set()
        current = link_name
        while current in child_parent:
            if current in seen:
                raise URDFError(f'the joints form a loop through link "{current}"')
            seen.add(current)
            current = child_parent[current]
    return UrdfModel(name, tuple(links), joints, roots[0])


def load_urdf(path: str | Path) -> UrdfModel:
    """Read and parse a URDF file; errors name the path."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise URDFError(f"{p}: cannot read the robot description: {exc.strerror or exc}") from None
    return parse_urdf(text, source=str(p))
