"""aiorobot.tf: a tf2-exact transform buffer, transform maths and batch transforms.

``Buffer`` answers every query the way tf2's ``BufferCore`` does (see
``lookup_transform``); the broadcasters, listener and robot state publisher
wire it to ``/tf`` and ``/tf_static``. Transform maths use ``A2B`` naming: a
transform from frame A to frame B maps coordinates expressed in A into B.
"""

from __future__ import annotations

from ._broadcasters import StaticTransformBroadcaster, TransformBroadcaster
from ._buffer import Buffer
from ._buffer_core import BufferCore
from ._conversions import do_transform
from ._exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from ._math import (
    apply_transform,
    canonical_quaternion,
    concat,
    euler_from_quaternion,
    invert_transform,
    matrix_from_quaternion,
    pq_from_transform,
    quaternion_from_euler,
    quaternion_from_matrix,
    quaternion_inverse,
    quaternion_multiply,
    quaternion_slerp,
    rotate_vectors,
    transform_from_pq,
)
from ._listener import TransformListener
from ._robot_state_publisher import RobotStatePublisher
from ._static_publisher import StaticTransformPublisher
from ._urdf import URDFError, UrdfJoint, UrdfModel, load_urdf, parse_urdf
from ._views import FrameInfo

__all__ = [
    "Buffer",
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "FrameInfo",
    "InvalidArgumentException",
    "LookupException",
    "RobotStatePublisher",
    "StaticTransformBroadcaster",
    "StaticTransformPublisher",
    "TransformBroadcaster",
    "TransformException",
    "TransformListener",
    "URDFError",
    "UrdfJoint",
    "UrdfModel",
    "apply_transform",
    "canonical_quaternion",
    "concat",
    "do_transform",
    "euler_from_quaternion",
    "invert_transform",
    "load_urdf",
    "matrix_from_quaternion",
    "parse_urdf",
    "pq_from_transform",
    "quaternion_from_euler",
    "quaternion_from_matrix",
    "quaternion_inverse",
    "quaternion_multiply",
    "quaternion_slerp",
    "rotate_vectors",
    "transform_from_pq",
]
