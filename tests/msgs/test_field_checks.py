"""Constructor field checks, as rclpy's generated message classes make them (issue 10 item 12).

rclpy's generated ``__init__`` assigns through property setters that check each value's type
and range (rosidl_generator_py's _msg.py.em); these cases restate what they reject.
"""

import numpy as np
import pytest

from aiorobot.msgs.geometry_msgs import Twist, Vector3
from aiorobot.msgs.sensor_msgs import JointState
from aiorobot.msgs.std_msgs import Bool, Float32, Int32, String, UInt8
from aiorobot.msgs.visualization_msgs import MarkerArray


@pytest.mark.parametrize(
    ("make", "error", "text"),
    [
        (lambda: Int32(data="five"), TypeError, r"std_msgs/msg/Int32\.data expects an int \(int32\), got str 'five'"),
        (lambda: Int32(data=2**40), ValueError, r"std_msgs/msg/Int32\.data: 1099511627776 is out of range for int32"),
        (lambda: Int32(data=1.5), TypeError, r"Int32\.data expects an int"),
        (lambda: UInt8(data=-1), ValueError, r"out of range for uint8 \[0, 255\]"),
        (lambda: Twist(linear=5), TypeError, r"geometry_msgs/msg/Twist\.linear expects a geometry_msgs/msg/Vector3 message"),
        (lambda: Vector3(x="1"), TypeError, r"Vector3\.x expects a float"),
        (lambda: Float32(data=1e39), ValueError, r"Float32\.data: 1e\+39 is out of range for float32"),
        (lambda: Bool(data=1), TypeError, r"Bool\.data expects a bool"),
        (lambda: String(data=b"x"), TypeError, r"String\.data expects a str"),
        (lambda: JointState(name=["a", 2]), TypeError, r"JointState\.name\[1\] expects a str"),
        (lambda: JointState(position="ab"), ValueError, r"JointState\.position expects a sequence of float64"),
        (lambda: MarkerArray(markers=[Vector3()]), TypeError, r"MarkerArray\.markers\[0\] expects a visualization_msgs/msg/Marker"),
    ],
)
def test_bad_constructor_arguments_name_the_field(make, error, text):
    with pytest.raises(error, match=text):
        make()


def test_good_values_are_accepted_and_normalised():
    assert Vector3(x=1).x == 1.0 and isinstance(Vector3(x=1).x, float)  # rclpy difference: ints accepted
    assert Vector3(x=np.float32(0.5)).x == 0.5 and type(Vector3(x=np.float32(0.5)).x) is float
    assert Int32(data=np.int64(7)).data == 7 and type(Int32(data=np.int64(7)).data) is int
    assert Float32(data=float("inf")).data == float("inf")  # inf and nan pass, as in rclpy
    assert Bool(data=np.bool_(True)).data is True
    assert JointState(name=("a", "b")).name == ["a", "b"]
    assert Int32(data=-(2**31)).data == -(2**31)
