"""rclpy's test_node.py parameter cases, restated for aiorobot.Node (upstream: ros2/rclpy 8.0.0)."""

from __future__ import annotations

import pytest

from aiorobot import (
    FloatingPointRange,
    IntegerRange,
    InvalidParameterTypeError,
    InvalidParameterValueError,
    Node,
    Parameter,
    ParameterAlreadyDeclaredError,
    ParameterDescriptor,
    ParameterImmutableError,
    ParameterNotDeclaredError,
    ParameterUninitializedError,
    SetParametersResult,
)
from aiorobot.lifecycle import LifecycleNode
from aiorobot.msgs import rcl_interfaces as ri


def reject_parameter_callback(params):
    return SetParametersResult(successful=not any(p.name == "reject_me" for p in params), reason="reject_me")


def make_node(**kw):
    overrides = {"initial_foo": 4321, "initial_fizz": "param_file_override", "initial_bar": "ignored", "initial_baz": 3.14}
    return Node("my_node", namespace="/my_ns", parameter_overrides=overrides, **kw)


def test_declare_parameter():
    # rclpy test_node.py::test_declare_parameter
    node = make_node()
    with pytest.raises(ValueError):
        node.declare_parameter("initial_foo", ri.ParameterValue(), ParameterDescriptor())
    assert node.declare_parameter("initial_foo", ri.ParameterValue(), ParameterDescriptor(dynamic_typing=True)).value == 4321
    assert node.declare_parameter("initial_bar", "ignoring_override", ParameterDescriptor(), ignore_override=True).value == (
        "ignoring_override"
    )
    assert node.declare_parameter("initial_fizz", "default", ParameterDescriptor()).value == "param_file_override"
    assert node.declare_parameter("initial_baz", 0.0, ParameterDescriptor()).value == 3.14
    assert node.declare_parameter("foo", 42, ParameterDescriptor()).value == 42
    not_set = node.declare_parameter("value_not_set")
    assert not_set.value is None and node.has_parameter("value_not_set")
    assert node.get_parameter("value_not_set").value is None

    with pytest.raises(ParameterAlreadyDeclaredError):
        node.declare_parameter("foo", "raise", ParameterDescriptor())
    with pytest.raises(InvalidParameterValueError):
        node.declare_parameter("", "raise", ParameterDescriptor())
    node.add_on_set_parameters_callback(reject_parameter_callback)
    # item 1: the on-set callback vets declarations too
    with pytest.raises(InvalidParameterValueError, match="reject_me"):
        node.declare_parameter("reject_me", "raise", ParameterDescriptor())
    assert not node.has_parameter("reject_me")
    # item 8: a name that is not a str is a TypeError
    with pytest.raises(TypeError):
        node.declare_parameter(1, "wrong_name_type", ParameterDescriptor())  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        node.declare_parameter("wrong_parameter_value_type", ri.ParameterValue(), ParameterDescriptor())
    with pytest.raises(TypeError):
        node.declare_parameter("wrong_parameter_descriptor_type", 1, ri.ParameterValue())
    with pytest.raises(ValueError):
        node.declare_parameter("static_typing_wo_default_value", descriptor=ParameterDescriptor(type=Parameter.Type.STRING))
    with pytest.raises(ValueError):
        node.declare_parameter(
            "dynamic_typing_and_static_type", Parameter.Type.DOUBLE, descriptor=ParameterDescriptor(dynamic_typing=True)
        )


def test_declare_parameter_accepts_the_rcl_interfaces_descriptor():
    node = Node("n")
    d = ri.ParameterDescriptor(read_only=True, integer_range=[ri.IntegerRange(from_value=0, to_value=10, step=2)])
    node.declare_parameter("even", 4, d)
    assert node.describe_parameter("even").read_only
    [result] = node.set_parameters([Parameter("even", 6)])
    assert not result.successful and "read-only" in result.reason


def test_declare_parameters_with_namespace():
    # rclpy test_node.py::test_declare_parameters
    node = make_node()
    result = node.declare_parameters(
        "ns",
        [("initial_foo", 0, ParameterDescriptor()), ("foo", 42, ParameterDescriptor()), ("baz", 2.41), ("value_not_set",)],
    )
    assert [p.name for p in result] == ["ns.initial_foo", "ns.foo", "ns.baz", "ns.value_not_set"]
    assert [p.value for p in result] == [0, 42, 2.41, None]
    with pytest.raises(ParameterAlreadyDeclaredError):
        node.declare_parameters("ns", [("foo", 1)])
    with pytest.raises(TypeError):
        node.declare_parameters("", [(1, "x")])
    with pytest.raises(TypeError):
        node.declare_parameters("", [("a", 1, ParameterDescriptor(), "extra")])


def test_typed_declaration_without_default():
    # rclpy test_node.py::test_node_get_uninitialized_parameter_or, ::test_node_declare_static_parameter
    node = Node("n", parameter_overrides={"from_override": 3})
    node.declare_parameter("uninitialized_foo", Parameter.Type.INTEGER)
    with pytest.raises(ParameterUninitializedError, match="declared as INTEGER but has no value"):
        node.get_parameter("uninitialized_foo")
    alt = node.get_parameter_or("uninitialized_foo", Parameter("foo", Parameter.Type.INTEGER, 152))
    assert (alt.name, alt.value) == ("foo", 152)
    node.declare_parameter("uninitialized_bar", None, ParameterDescriptor(dynamic_typing=True))
    assert node.get_parameter_or("uninitialized_bar", Parameter("foo", value=153)).value == 153
    assert node.declare_parameter("from_override", Parameter.Type.INTEGER).value == 3
    assert node.set_parameters([Parameter("uninitialized_foo", value=5)])[0].successful
    assert not node.set_parameters([Parameter("uninitialized_foo", value="asd")])[0].successful
    assert node.get_parameter("uninitialized_foo").value == 5


def test_wrong_typed_override_raises_invalid_parameter_type():
    node = Node("n", parameter_overrides={"speed": "fast"})
    with pytest.raises(InvalidParameterTypeError, match="expected double, found string 'fast'"):
        node.declare_parameter("speed", 0.5)


def test_node_undeclare_parameter_has_parameter():
    # rclpy test_node.py::test_node_undeclare_parameter_has_parameter
    node = Node("n")
    with pytest.raises(ParameterNotDeclaredError):
        node.undeclare_parameter("foo")
    node.declare_parameter("foo", "hello", ParameterDescriptor())
    node.undeclare_parameter("foo")
    assert not node.has_parameter("foo")
    node.declare_parameter("immutable_foo", "I am immutable", ParameterDescriptor(read_only=True))
    with pytest.raises(ParameterImmutableError):
        node.undeclare_parameter("immutable_foo")
    assert node.get_parameter("immutable_foo").value == "I am immutable"


def test_node_set_undeclared_parameters():
    # rclpy test_node.py::test_node_set_undeclared_parameters / ::..._atomically / ::test_node_get_undeclared_parameter
    node = Node("n")
    params = [Parameter("foo", Parameter.Type.INTEGER, 42), Parameter("bar", Parameter.Type.STRING, "hello")]
    with pytest.raises(ParameterNotDeclaredError):
        node.set_parameters(params)
    with pytest.raises(ParameterNotDeclaredError):
        node.set_parameters_atomically(params)
    with pytest.raises(ParameterNotDeclaredError):
        node.get_parameter("initial_foo")
    with pytest.raises(TypeError):
        node.set_parameters([42])  # rclpy test_node.py::test_node_cannot_set_invalid_parameters


def modify_parameter_callback(params):
    extra = [Parameter("bar", Parameter.Type.STRING, "hello")] if any(p.name == "foo" for p in params) else []
    return list(params) + extra


def test_allow_undeclared_parameters():
    # rclpy test_node.py TestNode (allow_undeclared_parameters=True)::test_node_set_parameters,
    # ::test_node_set_parameters_atomically, ::test_node_undeclared_parameters_are_dynamically_typed,
    # ::test_node_cannot_declare_after_set, ::test_describe_undeclared_parameter(s),
    # ::test_node_get_parameter_returns_parameter_not_set
    node = Node("n", allow_undeclared_parameters=True)
    results = node.set_parameters(
        [Parameter("foo", Parameter.Type.INTEGER, 42), Parameter("bar", Parameter.Type.STRING, "hello")]
    )
    assert all(r.successful for r in results)
    assert node.get_parameter("foo").value == 42
    node.undeclare_parameter("foo")
    node.undeclare_parameter("bar")
    node.add_pre_set_parameters_callback(modify_parameter_callback)
    results = node.set_parameters([Parameter("foo", Parameter.Type.INTEGER, 42), Parameter("baz", value=2.41)])
    node.remove_pre_set_parameters_callback(modify_parameter_callback)
    assert len(results) == 2 and all(r.successful for r in results)
    assert node.get_parameter("bar").value == "hello"
    assert node.set_parameters_atomically([Parameter("x", value=1), Parameter("y", value=2)]).successful
    assert node.set_parameters([Parameter("my_param", value=5)])[0].successful
    assert node.set_parameters([Parameter("my_param", value="asd")])[0].successful
    assert node.get_parameter("my_param").value == "asd"
    with pytest.raises(ParameterAlreadyDeclaredError):
        node.declare_parameter("my_param", 5)
    assert node.describe_parameter("nope") == ParameterDescriptor()
    assert node.describe_parameters(["a", "b"]) == [ParameterDescriptor(), ParameterDescriptor()]
    assert node.get_parameter("unset").type_ == Parameter.Type.NOT_SET


def test_automatically_declare_parameters_from_overrides():
    node = Node("n", parameter_overrides={"a": 1, "b.c": "x"}, automatically_declare_parameters_from_overrides=True)
    assert node.get_parameter("a").value == 1 and node.get_parameter("b.c").value == "x"
    assert node.unclaimed_parameter_overrides() == []
    rclpy_list = Node("m", parameter_overrides=[Parameter("a", value=2)])
    assert rclpy_list.declare_parameter("a", 0).value == 2


def test_node_get_parameters_by_prefix():
    # rclpy test_node.py::test_node_get_parameters_by_prefix
    node = Node("n")
    node.declare_parameters(
        "",
        [
            ("foo_prefix.foo", 43),
            ("foo_prefix.bar", "hello"),
            ("foo_prefix.baz", 2.41),
            ("bar_prefix.foo", 1),
            ("bar_prefix.bar", 12.3),
            ("bar_prefix.baz", "world"),
        ],
    )
    by = node.get_parameters_by_prefix("foo_prefix")
    assert by == {k: node.get_parameter(f"foo_prefix.{k}") for k in ("foo", "bar", "baz")}
    assert set(node.get_parameters_by_prefix("")) == {
        "foo_prefix.foo", "foo_prefix.bar", "foo_prefix.baz", "bar_prefix.foo", "bar_prefix.bar", "bar_prefix.baz", "use_sim_time",
    }
    assert node.get_parameters_by_prefix("baz") == {}


def test_node_list_parameters():
    # rclpy test_node.py::test_node_list_parameters
    node = Node("n")
    names = ["foo_prefix.foo", "foo_prefix.bar", "foo_prefix.baz", "bar_prefix.foo", "bar_prefix.bar", "bar_prefix.baz"]
    node.declare_parameters("", [(n, 1) for n in names])
    result = node.list_parameters([], 0)
    assert isinstance(result, ri.ListParametersResult)
    assert sorted(result.names) == sorted([*names, "use_sim_time"])
    assert sorted(result.prefixes) == ["bar_prefix", "foo_prefix"]
    result = node.list_parameters(prefixes=["foo_prefix", "bar_prefix"], depth=0)
    assert sorted(result.names) == sorted(names)
    result = node.list_parameters(prefixes=["foo_prefix"], depth=0)
    assert sorted(result.names) == sorted(names[:3]) and result.prefixes == ["foo_prefix"]
    result = node.list_parameters(prefixes=[], depth=1)
    assert result.names == ["use_sim_time"] and result.prefixes == []
    result = node.list_parameters(prefixes=[], depth=2)
    assert sorted(result.names) == sorted([*names, "use_sim_time"])
    node.declare_parameter("foo_prefix.deep.x", 1)
    result = node.list_parameters(prefixes=["foo_prefix"], depth=1)
    assert "foo_prefix.deep.x" not in result.names and "foo_prefix.foo" in result.names
    with pytest.raises(TypeError):
        node.list_parameters(prefixes="foo", depth=0)  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        node.list_parameters([], -1)


def test_pre_on_post_set_callbacks():
    # rclpy test_node.py::test_add_remove_pre_set_parameter_callback, ::test_node_add_on_set_parameter_callback,
    # ::test_add_remove_post_set_parameter_callback
    node = Node("n")
    node.declare_parameter("a", 1)
    seen: list[str] = []

    def pre(params):
        seen.append("pre")
        return [Parameter(p.name, value=p.value * 10) for p in params]

    def on(params):
        seen.append(f"on {params[0].value}")
        return SetParametersResult(successful=True)

    def post(params):
        seen.append(f"post {params[0].value}")

    node.add_pre_set_parameters_callback(pre)
    node.add_on_set_parameters_callback(on)
    node.add_post_set_parameters_callback(post)
    assert node.set_parameters([Parameter("a", value=2)])[0].successful
    assert node.get_parameter("a").value == 20
    assert seen == ["pre", "on 20", "post 20"]
    node.remove_pre_set_parameters_callback(pre)
    node.remove_on_set_parameters_callback(on)
    node.remove_post_set_parameters_callback(post)
    node.set_parameters([Parameter("a", value=3)])
    assert len(seen) == 3
    with pytest.raises(ValueError):
        node.remove_post_set_parameters_callback(post)
    node.add_pre_set_parameters_callback(lambda params: [])
    [result] = node.set_parameters([Parameter("a", value=4)])
    assert not result.successful and "cannot be empty" in result.reason


def test_node_set_parameters_atomically_rejection_and_read_only():
    # rclpy test_node.py::test_node_set_parameters_atomically_rejection, ::..._read_only
    node = Node("n")
    node.declare_parameter("reject_me", 1)
    node.declare_parameter("other", 1)
    node.declare_parameter("ro", "x", ParameterDescriptor(read_only=True))
    node.add_on_set_parameters_callback(reject_parameter_callback)
    result = node.set_parameters_atomically([Parameter("other", value=2), Parameter("reject_me", value=2)])
    assert not result.successful
    assert node.get_parameter("other").value == 1  # all or nothing
    result = node.set_parameters_atomically([Parameter("other", value=2), Parameter("ro", value="y")])
    assert not result.successful and node.get_parameter("ro").value == "x"
    assert node.get_parameter("other").value == 1


def test_node_set_parameters_implicit_undeclare():
    # rclpy test_node.py::test_node_set_parameters_implicit_undeclare
    node = Node("n")
    node.declare_parameter("static", 1)
    node.declare_parameter("dynamic", 1, ParameterDescriptor(dynamic_typing=True))
    [result] = node.set_parameters([Parameter("static", Parameter.Type.NOT_SET)])
    assert not result.successful and "cannot be undeclared" in result.reason
    assert node.set_parameters([Parameter("dynamic", Parameter.Type.NOT_SET)])[0].successful
    assert not node.has_parameter("dynamic")


def test_integer_and_floating_point_ranges():
    # rclpy test_node.py::test_node_set_parameters_* with integer_range / floating_point_range (_apply_*_range)
    node = Node("n")
    node.declare_parameter("i", 4, ParameterDescriptor(integer_range=[IntegerRange(0, 10, 2)]))
    node.declare_parameter("f", 0.5, ParameterDescriptor(floating_point_range=[FloatingPointRange(0.0, 1.0, 0.25)]))
    ok = [Parameter("i", value=v) for v in (0, 6, 10)] + [Parameter("f", value=v) for v in (0.0, 0.75, 1.0, 1.0 + 1e-9)]
    assert all(r.successful for r in node.set_parameters(ok))
    bad = [Parameter("i", value=v) for v in (-2, 3, 12)] + [Parameter("f", value=v) for v in (-0.1, 0.3, 1.5)]
    assert not any(r.successful for r in node.set_parameters(bad))
    with pytest.raises(InvalidParameterValueError, match="outside the range"):
        node.declare_parameter("j", 11, ParameterDescriptor(integer_range=[IntegerRange(0, 10, 1)]))
    assert node.describe_parameter("i").to_msg().integer_range[0].step == 2


def test_describe_parameter_and_get_parameter_types():
    # rclpy test_node.py::test_describe_parameter, ::test_describe_parameters
    node = Node("n")
    node.declare_parameter("foo", "hello", ParameterDescriptor(description="a foo", additional_constraints="none"))
    d = node.describe_parameter("foo")
    assert (d.name, d.type, d.description, d.additional_constraints) == ("foo", Parameter.Type.STRING, "a foo", "none")
    with pytest.raises(ParameterNotDeclaredError):
        node.describe_parameter("bar")
    assert node.get_parameter_types(["foo"]) == [Parameter.Type.STRING]


def test_lifecycle_node_checks_enable_communication_interface():
    # rclpy test_lifecycle.py::test_lifecycle_node_init (item 8)
    with pytest.raises(TypeError, match="enable_communication_interface"):
        LifecycleNode("lc", enable_communication_interface="asd")  # type: ignore[arg-type]


def test_create_rate_checks_its_frequency():
    # rclpy test_rate.py / test_node.py::test_create_rate (item 8)
    node = Node("n")
    with pytest.raises(TypeError):
        node.create_rate(None)  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        node.create_rate(0.0)
    with pytest.raises(ValueError):
        node.create_rate(-1.0)


def test_declare_parameters_typed_overrides_and_partial_failures():
    # rclpy test_node.py::test_declare_parameters
    node = Node(
        "n",
        parameter_overrides={
            "initial_foo": 4321,
            "initial_decl_wrong_type": "a string",
            "initial_decl_with_type": 3.14,
            "namespace.k_initial_foo": 4321,
            "initial_bar": "override",
        },
    )
    assert node.declare_parameter("no_override", Parameter.Type.INTEGER).type_ == Parameter.Type.NOT_SET
    with pytest.raises(InvalidParameterTypeError):
        node.declare_parameter("initial_decl_wrong_type", Parameter.Type.INTEGER)
    assert node.declare_parameter("initial_decl_with_type", Parameter.Type.DOUBLE).value == 3.14
    params = [("k_initial_foo", 0, ParameterDescriptor()), ("k_foo", 42, ParameterDescriptor()), ("k_baz", 2.41),
              ("k_value_not_set",)]
    assert [p.value for p in node.declare_parameters("namespace", params)] == [4321, 42, 2.41, None]
    ignoring = [("initial_bar", "ignoring_override", ParameterDescriptor())]
    assert node.declare_parameters("", ignoring, ignore_override=True)[0].value == "ignoring_override"
    with pytest.raises(ParameterAlreadyDeclaredError):
        node.declare_parameters("", [("foobar", 43), ("initial_bar", "x")])
    assert not node.has_parameter("foobar")  # nothing declared when one name is taken
    with pytest.raises(InvalidParameterValueError):
        node.declare_parameters("", [("foobarbar", 44), ("", 2.41)])
    node.add_on_set_parameters_callback(
        lambda ps: SetParametersResult(successful=not any("reject" in p.name for p in ps))
    )
    with pytest.raises(InvalidParameterValueError):
        node.declare_parameters("", [("im_ok", 44), ("reject_me", 2.41)])
    assert node.has_parameter("im_ok") and not node.has_parameter("reject_me")  # one at a time, as rclpy
    with pytest.raises(ValueError):
        node.declare_parameter("wrong_parameter_value_type_not_set", Parameter.Type.NOT_SET)


def test_node_set_parameters_applies_those_before_an_undeclared_one():
    # rclpy test_node.py::test_node_set_parameters (the non-allow-undeclared node)
    node = Node("n")
    node.declare_parameters("", [("foo", 42, ParameterDescriptor()), ("bar", "hello"), ("baz", 2.41)])
    params = [Parameter("foo", value=24), Parameter("bar", value="bye"), Parameter("baz", value=1.42),
              Parameter("foobar", value=1.42)]
    with pytest.raises(ParameterNotDeclaredError):
        node.set_parameters(params)
    assert [node.get_parameter(n).value for n in ("foo", "bar", "baz")] == [24, "bye", 1.42]
    with pytest.raises(ParameterNotDeclaredError):
        node.get_parameter("foobar")


def test_node_set_parameters_rejection_list():
    # rclpy test_node.py::test_node_set_parameters_rejection_list
    node = Node("n")
    node.declare_parameters("", [("reject", True, ParameterDescriptor()), ("accept", True, ParameterDescriptor()),
                                 ("accept", True, ParameterDescriptor())])
    node.add_on_set_parameters_callback(lambda ps: SetParametersResult(successful=not any("reject" in p.name for p in ps)))
    node.add_on_set_parameters_callback(lambda ps: SetParametersResult(successful=not any("refuse" in p.name for p in ps)))
    results = node.set_parameters([Parameter("reject", value=True), Parameter("accept", value=True),
                                   Parameter("accept", value=True)])
    assert [r.successful for r in results] == [False, True, True]


def test_node_set_parameters_read_only():
    # rclpy test_node.py::test_node_set_parameters_read_only
    node = Node("n")
    node.declare_parameters("", [("immutable_foo", 42, ParameterDescriptor(read_only=True)), ("bar", "hello"),
                                 ("immutable_baz", 2.41, ParameterDescriptor(read_only=True))])
    results = node.set_parameters([Parameter("immutable_foo", value=24), Parameter("bar", value="bye"),
                                   Parameter("immutable_baz", value=1.42)])
    assert [r.successful for r in results] == [False, True, False]
    assert [node.get_parameter(n).value for n in ("immutable_foo", "bar", "immutable_baz")] == [42, "bye", 2.41]


def test_node_set_parameters_pre_set_parameter_callback_adding_undeclared():
    # rclpy test_node.py::test_node_set_parameters_pre_set_parameter_callback
    node = Node("n")
    node.declare_parameter("foo", 0)
    node.add_pre_set_parameters_callback(modify_parameter_callback)
    with pytest.raises(ParameterNotDeclaredError):
        node.set_parameters([Parameter("foo", Parameter.Type.INTEGER, 42)])
    assert node.get_parameter("foo").value == 0 and not node.has_parameter("bar")


def test_set_descriptor():
    # rclpy test_node.py::test_set_descriptor, ::test_set_descriptor_read_only
    node = Node("n")
    with pytest.raises(ParameterNotDeclaredError):
        node.set_descriptor("foo", ParameterDescriptor())
    node.declare_parameter("foo", "hello", ParameterDescriptor())
    assert node.describe_parameter("foo") == ParameterDescriptor(name="foo", type=Parameter.Type.STRING)
    value = node.set_descriptor("foo", ParameterDescriptor(
        name="this will be ignored", type=Parameter.Type.INTEGER, additional_constraints="some constraints",
        integer_range=[IntegerRange(-10, 10, 2)], dynamic_typing=True))
    assert (value.type, value.string_value) == (int(Parameter.Type.STRING), "hello")
    d = node.describe_parameter("foo")
    assert (d.name, d.type, d.additional_constraints) == ("foo", Parameter.Type.STRING, "some constraints")
    assert d.integer_range[0] == IntegerRange(-10, 10, 2)
    node.set_descriptor("foo", ri.ParameterDescriptor(type=4, read_only=True, floating_point_range=[
        ri.FloatingPointRange(from_value=-2.0, to_value=2.0, step=0.1)]))
    d = node.describe_parameter("foo")
    assert d.read_only and d.floating_point_range[0] == FloatingPointRange(-2.0, 2.0, 0.1)
    with pytest.raises(ParameterImmutableError):
        node.set_descriptor("foo", ParameterDescriptor())
    node.declare_parameter("n", 5)
    with pytest.raises(InvalidParameterValueError):
        node.set_descriptor("n", ParameterDescriptor(type=Parameter.Type.INTEGER, integer_range=[IntegerRange(0, 3)]))
    alt = ri.ParameterValue(type=2, integer_value=3)
    assert node.set_descriptor("n", ParameterDescriptor(type=Parameter.Type.INTEGER, integer_range=[IntegerRange(0, 3)]),
                               alt).integer_value == 3
    assert node.get_parameter("n").value == 3


@pytest.mark.parametrize(
    ("kind", "rng", "good", "bad_step", "bad_range"),
    [
        ("float", FloatingPointRange(0.0, 10.0, 0.5), [0.0, 10.0, 4.5], 4.25, 12.0),
        ("int", IntegerRange(0, 10, 2), [0, 10, 4], 5, 12),
    ],
)
def test_range_descriptors(kind, rng, good, bad_step, bad_range):
    # rclpy test_node.py::test_floating_point_range_descriptor, ::test_integer_range_descriptor
    node = Node("n")
    field = "floating_point_range" if kind == "float" else "integer_range"
    d = lambda: ParameterDescriptor(**{field: [rng]})  # noqa: E731
    other = 123 if kind == "float" else 123.0  # a value of the other numeric type ignores the range
    result = node.declare_parameters("", [("from_value", good[0], d()), ("to_value", good[1], d()),
                                          ("in_range", good[2], d()), ("str_value", "no number", d()),
                                          ("other", other, d())])
    assert [p.value for p in result] == [*good, "no number", other]
    assert not node.set_parameters([Parameter("in_range", value=bad_range)])[0].successful
    assert not node.set_parameters([Parameter("in_range", value=bad_step)])[0].successful
    assert node.get_parameter("in_range").value == good[2]
    wide = (FloatingPointRange(-10.0, 0.0, 30.0) if kind == "float" else IntegerRange(-10, 0, 30))
    w = lambda: ParameterDescriptor(**{field: [wide]})  # noqa: E731
    with pytest.raises(InvalidParameterValueError):
        node.declare_parameters("", [("from_value_2", type(good[0])(-10), w()), ("to_value_2", type(good[0])(0), w()),
                                     ("in_range_bad_step", type(good[0])(-4), w()), ("out_of_range", type(good[0])(30), w())])
    assert node.has_parameter("from_value_2") and node.has_parameter("to_value_2")  # edges are always valid
    assert not node.has_parameter("in_range_bad_step") and not node.has_parameter("out_of_range")


def test_static_dynamic_typing():
    # rclpy test_node.py::test_static_dynamic_typing
    node = Node("n")
    node.declare_parameters("", [("int_param", 0), ("int_param_no_default", Parameter.Type.INTEGER),
                                 ("dynamic_param", None, ParameterDescriptor(dynamic_typing=True))])
    assert node.get_parameter("int_param").type_ == Parameter.Type.INTEGER
    with pytest.raises(ParameterUninitializedError):
        node.get_parameter("int_param_no_default")
    assert node.get_parameter("dynamic_param").type_ == Parameter.Type.NOT_SET
    result = node.set_parameters([Parameter("int_param", value="asd")])[0]
    assert not result.successful and result.reason.startswith("Wrong parameter type")
    assert node.set_parameters([Parameter("int_param", value=3)])[0].successful
    result = node.set_parameters([Parameter("int_param_no_default", value="asd")])[0]
    assert result.reason.startswith("Wrong parameter type")
    assert node.set_parameters([Parameter("int_param_no_default", value=3)])[0].successful
    result = node.set_parameters([Parameter("int_param_no_default", value=None)])[0]
    assert result.reason.startswith("Static parameter cannot be undeclared")
    assert node.set_parameters([Parameter("dynamic_param", value="asd")])[0].successful
    assert node.set_parameters([Parameter("dynamic_param", value=3)])[0].successful
    result = node.set_parameters_atomically([Parameter("dynamic_param", value=3), Parameter("int_param", value="asd")])
    assert result.reason.startswith("Wrong parameter type")
    assert node.set_parameters_atomically([Parameter("dynamic_param", value=None), Parameter("int_param", value=4)]).successful
    assert node.get_parameter("int_param").value == 4 and not node.has_parameter("dynamic_param")


def test_descriptor_and_shorthand_keywords_do_not_mix():
    node = Node("n")
    with pytest.raises(TypeError, match="either a descriptor or the description/read_only keywords"):
        node.declare_parameter("a", 1, ParameterDescriptor(), description="both")
    d = node.describe_parameter(node.declare_parameter("b", 2.0, description="m/s", read_only=True, range=(0, 5)).name)
    assert (d.description, d.read_only, d.floating_point_range[0]) == ("m/s", True, FloatingPointRange(0.0, 5.0, 0.0))
