"""Parameters: declare, override, types, ranges, read-only, callbacks."""

import pytest

from aiorobot import (
    InvalidParameterValueError,
    Node,
    Parameter,
    ParameterAlreadyDeclaredError,
    ParameterNotDeclaredError,
    ParameterType,
    SetParametersResult,
)


def test_declare_returns_default_and_get_reads_it():
    node = Node("n")
    assert node.declare_parameter("speed", 0.5).value == 0.5
    assert node.get_parameter("speed").value == 0.5
    assert node.describe_parameter("speed").type is ParameterType.DOUBLE


def test_override_replaces_default():
    node = Node("n", parameter_overrides={"speed": 2.0})
    assert node.declare_parameter("speed", 0.5).value == 2.0


def test_int_override_is_accepted_for_a_double():
    node = Node("n", parameter_overrides={"speed": 2})
    value = node.declare_parameter("speed", 0.5).value
    assert value == 2.0 and isinstance(value, float)


def test_wrongly_typed_override_raises_with_name_and_reason():
    node = Node("n", parameter_overrides={"speed": "fast"})
    with pytest.raises(InvalidParameterValueError) as info:
        node.declare_parameter("speed", 0.5)
    assert info.value.name == "speed"
    assert info.value.reason == "expected double, found string 'fast'"


def test_out_of_range_override_raises():
    node = Node("n", parameter_overrides={"speed": 5.0})
    with pytest.raises(InvalidParameterValueError, match=r"outside the range \[0.0, 1.0\]"):
        node.declare_parameter("speed", 0.5, range=(0.0, 1.0))


def test_unclaimed_overrides_are_reported():
    node = Node("n", parameter_overrides={"speed": 1.0, "typo": 3})
    node.declare_parameter("speed", 0.5)
    assert node.unclaimed_parameter_overrides() == ["typo"]


def test_declaring_twice_raises():
    node = Node("n")
    node.declare_parameter("a", 1)
    with pytest.raises(ParameterAlreadyDeclaredError):
        node.declare_parameter("a", 1)


def test_undeclared_parameter_raises_naming_the_declared_ones():
    node = Node("n")
    node.declare_parameter("a", 1)
    with pytest.raises(ParameterNotDeclaredError, match=r"'b' is not declared by /n \(declared: a, use_sim_time\)"):
        node.get_parameter("b")


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        ("x", "expected double, found string 'x'"),
        (3.0, "outside the range"),
        (0.15, "not 0.0 plus a multiple of the step 0.1"),
    ],
)
def test_rejected_value_keeps_the_old_one(value, reason):
    node = Node("n")
    node.declare_parameter("gain", 0.5, range=(0.0, 1.0, 0.1))
    [result] = node.set_parameters([Parameter("gain", value)])
    assert not result.successful and reason in result.reason
    assert node.get_parameter("gain").value == 0.5


def test_read_only_parameter_cannot_be_set():
    node = Node("n")
    node.declare_parameter("frame", "base_link", read_only=True)
    [result] = node.set_parameters([Parameter("frame", "odom")])
    assert result == SetParametersResult(False, "parameter 'frame' is read-only")


def test_one_result_per_parameter_applied_individually():
    node = Node("n")
    node.declare_parameter("a", 1)
    node.declare_parameter("b", "x")
    results = node.set_parameters([Parameter("a", 2), Parameter("b", 3)])
    assert [r.successful for r in results] == [True, False]
    assert node.get_parameter("a").value == 2 and node.get_parameter("b").value == "x"
    # rclpy test_node.py::test_node_set_undeclared_parameters: an undeclared name raises,
    # after the parameters before it are applied
    with pytest.raises(ParameterNotDeclaredError, match="'c' not declared by /n"):
        node.set_parameters([Parameter("a", 3), Parameter("c", 1), Parameter("a", 4)])
    assert node.get_parameter("a").value == 3


def test_callback_can_reject_and_the_value_stays():
    node = Node("n")
    node.declare_parameter("mode", "auto")
    seen = []

    def vet(params):
        seen.extend(params)
        ok = all(p.value in ("auto", "manual") for p in params)
        return SetParametersResult(ok, "" if ok else "mode must be auto or manual")

    node.add_on_set_parameters_callback(vet)
    assert node.set_parameters([Parameter("mode", "manual")])[0].successful
    [result] = node.set_parameters([Parameter("mode", "warp")])
    assert result == SetParametersResult(False, "mode must be auto or manual")
    assert node.get_parameter("mode").value == "manual"
    assert [p.value for p in seen] == ["manual", "warp"]


async def test_async_callback_is_awaited_by_set_parameters_async():
    node = Node("n")
    node.declare_parameter("a", 1)

    async def vet(params):
        return SetParametersResult(params[0].value < 10, "too big")

    node.add_on_set_parameters_callback(vet)
    results = await node.set_parameters_async([Parameter("a", 5), Parameter("a", 50)])
    assert [r.successful for r in results] == [True, False]
    assert node.get_parameter("a").value == 5
    with pytest.raises(TypeError, match="set_parameters_async"):
        node.set_parameters([Parameter("a", 6)])


def test_array_parameters_keep_their_element_type():
    node = Node("n", parameter_overrides={"gains": [1, 2, 3]})
    assert node.declare_parameter("gains", [0.1, 0.2, 0.3]).value == [1.0, 2.0, 3.0]
    [result] = node.set_parameters([Parameter("gains", ["a"])])
    assert not result.successful


def test_default_keyword_of_api_md_still_works():
    node = Node("n")
    assert node.declare_parameter("speed", default=0.5).value == 0.5
    with pytest.raises(TypeError, match="value or default, not both"):
        node.declare_parameter("x", 1, default=2)
