"""Interface definition files shipped with aiorobot: ``<pkg>__<Name>.msg|srv|action``.

Upstream ROS 2 Jazzy definitions of the packages rosbags' Jazzy store lacks
(services, actions, example_interfaces).
"""

__all__: list[str] = []
