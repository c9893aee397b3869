import pytest

from aiorobot import InvalidNameError, Node
from aiorobot._core._names import expand_name, resolve_name, validate_namespace


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("chatter", "/ns/chatter"),
        ("/chatter", "/chatter"),
        ("~/state", "/ns/talker/state"),
        ("~", "/ns/talker"),
        ("{node}/x", "/ns/talker/x"),
        ("a/b_2", "/ns/a/b_2"),
    ],
)
def test_names_expand_as_in_ros2(name, expected):
    assert expand_name(name, "talker", "/ns") == expected


def test_relative_name_in_root_namespace():
    assert expand_name("chatter", "talker", "/") == "/chatter"


@pytest.mark.parametrize(
    ("name", "reason", "caret"),
    [
        ("a b", "character ' ' is not allowed", 1),
        ("1abc", "must not start with a digit", 0),
        ("a/~b", "'~' is only allowed at the start", 2),
        ("~x", "'~' must be followed by '/'", 1),
        ("x/", "must not end with '/'", 1),
        ("a-b", "character '-' is not allowed", 1),
    ],
)
def test_invalid_name_points_at_the_bad_character(name, reason, caret):
    with pytest.raises(InvalidNameError) as info:
        expand_name(name, "n", "/ns")
    err = info.value
    assert reason in str(err)
    assert err.index == caret
    assert str(err).splitlines()[-1] == "  " + " " * caret + "^"


def test_empty_name_is_rejected():
    with pytest.raises(InvalidNameError, match="must not be empty"):
        expand_name("", "n", "/")


def test_remap_applies_to_expanded_names():
    remaps = {"chatter": "/other", "/abs": "rel"}
    assert resolve_name("chatter", "n", "/ns", remaps) == "/other"
    assert resolve_name("/ns/chatter", "n", "/ns", remaps) == "/other"
    assert resolve_name("/abs", "n", "/ns", remaps) == "/ns/rel"
    assert resolve_name("untouched", "n", "/ns", remaps) == "/ns/untouched"


def test_namespace_is_normalised_to_absolute():
    assert validate_namespace("") == "/"
    assert validate_namespace("robot1") == "/robot1"
    with pytest.raises(InvalidNameError):
        validate_namespace("/robot 1")


def test_node_applies_namespace_private_names_and_remaps():
    node = Node("talker", namespace="robot", remappings={"/robot/cmd": "/base/cmd"})
    assert node.get_fully_qualified_name() == "/robot/talker"
    assert node.resolve_topic_name("cmd") == "/base/cmd"
    assert node.resolve_topic_name("~/debug") == "/robot/talker/debug"


def test_node_and_namespace_remaps_override_the_code():
    node = Node("talker", remappings={"__node": "speaker", "__ns": "/r2"})
    assert node.get_fully_qualified_name() == "/r2/speaker"


@pytest.mark.parametrize("bad", ["", "9lives", "my-node", "a/b"])
def test_invalid_node_name_is_rejected(bad):
    with pytest.raises(InvalidNameError):
        Node(bad)


def test_invalid_topic_is_rejected_when_creating_a_publisher():
    from aiorobot.msgs.std_msgs import String

    node = Node("n")
    with pytest.raises(InvalidNameError, match=r"^topic name 'bad topic' is invalid: "):
        node.create_publisher(String, "bad topic", 10)
