"""URDF parsing: joint transforms as robot_state_publisher computes them, and clear errors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from aiorobot.tf import URDFError, load_urdf, parse_urdf

ARM = Path(__file__).resolve().parents[2] / "examples" / "urdf" / "two_dof_arm.urdf"


def robot(joints: str, links: str = '<link name="a"/><link name="b"/>') -> str:
    return f'<robot name="r">{links}{joints}</robot>'


REVOLUTE = (
    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
    '<origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 2"/>'
    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
)


def test_the_example_arm_parses_into_fixed_and_moving_joints():
    model = load_urdf(ARM)
    assert model.name == "two_dof_arm"
    assert model.root == "base_link"
    assert sorted(j.name for j in model.moving_joints) == ["elbow_joint", "shoulder_joint"]
    assert sorted(j.name for j in model.fixed_joints) == ["lidar_joint", "mount_joint", "tool_joint"]
    elbow = model.joints["elbow_joint"]
    assert (elbow.parent, elbow.child, elbow.lower, elbow.upper) == ("upper_arm", "forearm", -2.0, 2.0)


def test_revolute_joint_is_origin_then_rotation_about_the_normalised_axis():
    joint = parse_urdf(robot(REVOLUTE)).joints["j"]
    assert joint.axis == (0.0, 0.0, 1.0)
    t, q = joint.transform(math.pi / 2)
    assert t == pytest.approx((1.0, 0.0, 0.0))
    assert q == pytest.approx((0.0, 0.0, math.sin(math.pi / 2), math.cos(math.pi / 2)))  # 90 + 90 deg about z


def test_prismatic_joint_moves_along_the_axis_in_the_joint_frame():
    joint = parse_urdf(
        robot(
            '<joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>'
            '<origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/><axis xyz="1 0 0"/>'
            '<limit lower="0" upper="1" effort="1" velocity="1"/></joint>'
        )
    ).joints["slide"]
    t, q = joint.transform(0.5)
    assert t == pytest.approx((0.0, 0.5, 1.0))  # the joint frame is turned 90 deg: x becomes y
    assert q == pytest.approx((0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))


def test_continuous_joint_needs_no_limits_and_defaults_its_axis_to_x():
    joint = parse_urdf(robot('<joint name="wheel" type="continuous"><parent link="a"/><child link="b"/></joint>')).joints[
        "wheel"
    ]
    _, q = joint.transform(math.pi)
    assert q == pytest.approx((1.0, 0.0, 0.0, 0.0), abs=1e-12)


def test_fixed_joint_ignores_the_position():
    joint = parse_urdf(robot('<joint name="f" type="fixed"><parent link="a"/><child link="b"/><origin xyz="1 2 3"/></joint>')).joints["f"]
    assert joint.transform(5.0) == ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))


def test_mimic_is_read():
    text = robot(
        '<joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="continuous"><parent link="b"/><child link="c"/>'
        '<mimic joint="j1" multiplier="-2" offset="0.1"/></joint>',
        links='<link name="a"/><link name="b"/><link name="c"/>',
    )
    mimic = parse_urdf(text).joints["j2"].mimic
    assert (mimic.joint, mimic.multiplier, mimic.offset) == ("j1", -2.0, 0.1)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"^robot_description: the robot description is empty; expected URDF XML text$"),
        ("<robot><link name='a'>", r"^robot_description: not well-formed XML at line 1, column \d+: no element found$"),
        ("<model/>", r"^robot_description: the root element is <model>, expected <robot>$"),
        ("<robot/>", r"no <link> elements"),
        ('<robot><link/></robot>', r"<link> without a name attribute"),
        (robot('<joint name="j" type="hinge"><parent link="a"/><child link="b"/></joint>'), r'^robot_description: joint "j": type \'hinge\' is not a joint type; expected one of continuous, fixed, floating, planar, prismatic, revolute$'),
        (robot('<joint name="j" type="fixed"><child link="b"/></joint>'), r'joint "j": missing <parent link="..."/>'),
        (robot('<joint name="j" type="fixed"><parent link="a"/><child link="z"/></joint>'), r'joint "j": child link "z" is not defined by any <link>'),
        (robot('<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>'), r'joint "j": a revolute joint needs <limit'),
        (robot('<joint name="j" type="fixed"><parent link="a"/><child link="b"/><origin xyz="1 2"/></joint>'), r'joint "j" <origin xyz>: expected 3 numbers, got 2 in \'1 2\''),
        (robot('<joint name="j" type="fixed"><parent link="a"/><child link="b"/><origin rpy="0 0 x"/></joint>'), r"<origin rpy>: expected 3 numbers, got '0 0 x'"),
        (robot('<joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 0"/></joint>'), r"<axis xyz> is the zero vector"),
        (
            robot(
                '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
                '<joint name="j2" type="fixed"><parent link="a"/><child link="b"/></joint>'
            ),
            r'link "b" has two parents: joint "j1" and joint "j2" both name it as child',
        ),
        (robot('<joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>' * 2), r'joint "j" is defined twice'),
        (robot('<joint name="j" type="fixed"><parent link="a"/><child link="a"/></joint>'), r'parent and child are both "a"'),
        (robot(""), r"2 root links \(a, b\): connect them with joints"),
        (
            robot(
                '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
                '<joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>'
            ),
            r"every link has a parent, so the joints form a loop",
        ),
        (
            robot('<joint name="j" type="continuous"><parent link="a"/><child link="b"/><mimic joint="ghost"/></joint>'),
            r'joint "j" mimics joint "ghost", which does not exist',
        ),
    ],
)
def test_malformed_descriptions_raise_urdf_error_naming_the_problem(text, message):
    with pytest.raises(URDFError, match=message):
        parse_urdf(text)


def test_a_loop_in_a_detached_part_is_found():
    text = robot(
        '<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="fixed"><parent link="c"/><child link="d"/></joint>'
        '<joint name="j3" type="fixed"><parent link="d"/><child link="c"/></joint>',
        links='<link name="a"/><link name="b"/><link name="c"/><link name="d"/>',
    )
    with pytest.raises(URDFError, match=r"the joints form a loop through link"):
        parse_urdf(text)


def test_load_urdf_names_the_path(tmp_path):
    missing = tmp_path / "nope.urdf"
    with pytest.raises(URDFError, match=rf"^{missing}: cannot read the robot description"):
        load_urdf(missing)
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot>")
    with pytest.raises(URDFError, match=rf"^{bad}: not well-formed XML"):
        load_urdf(bad)
