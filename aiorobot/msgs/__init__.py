"""ROS 2 (Jazzy) interface types and their CDR wire format.

``aiorobot.msgs.<ros_package>`` holds the types under their ROS names::

    from aiorobot.msgs.geometry_msgs import Twist
    from aiorobot.msgs.std_srvs import Trigger             # Trigger.Request, Trigger.Response
    from aiorobot.msgs.example_interfaces import Fibonacci  # .Goal, .Result, .Feedback, ...

Every message type constructs with no arguments (zeros, ``''``, empty numpy arrays),
takes keyword or positional fields in definition order, compares by value and names
its ROS type in ``__msgtype__``. ``serialize``/``deserialize`` speak ROS 2 CDR,
byte-identical to ROS 2. Classes are generated on first use, so importing a
package module costs next to nothing.

Your own interface packages (a folder with package.xml and msg/, srv/, action/ files)::

    msgs.register_package("src/my_msgs")                   # or a workspace folder of packages
    from aiorobot.msgs.my_msgs import Foo                  # or msgs.get("my_msgs/msg/Foo")
"""

from __future__ import annotations

from ._cdr import DeserializationError, SerializationError, deserialize, serialize
from ._classgen import Action, Message, ReadOnlyMessageError, Service
from ._describe import message_definition, register_type_description, type_description, type_hash
from ._registry import get, register_action, register_file, register_msg, register_srv
from ._ros_packages import register_from_env, register_package

__all__ = [
    "Action",
    "DeserializationError",
    "Message",
    "ReadOnlyMessageError",
    "SerializationError",
    "Service",
    "deserialize",
    "get",
    "message_definition",
    "register_action",
    "register_file",
    "register_from_env",
    "register_msg",
    "register_package",
    "register_srv",
    "register_type_description",
    "serialize",
    "type_description",
    "type_hash",
]
