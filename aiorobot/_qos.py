"""Quality of service: profiles, policies, presets and the compatibility rules of ROS 2."""

from __future__ import annotations

import enum
import warnings
from dataclasses import dataclass

from ._time import Duration

__all__ = [
    "DurabilityPolicy",
    "HistoryPolicy",
    "QoSPolicyEnum",
    "QoSPresetProfiles",
    "QoSProfile",
    "ReliabilityPolicy",
    "qos_profile_sensor_data",
    "qos_profile_system_default",
    "to_qos_profile",
]


class QoSPolicyEnum(enum.IntEnum):
    """Base of the policy enums, with rclpy's short keys (``"reliable"``, ``"keep_last"``, ...)."""

    @classmethod
    def short_keys(cls) -> list[str]:
        """The members' names in lower case, as ``ros2 topic`` options spell them."""
        return [name.lower() for name in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> int:
        """The value of the member named ``name`` in any case; KeyError when there is none."""
        return int(cls[name.upper()].value)

    @property
    def short_key(self) -> str:
        return self.name.lower()


class ReliabilityPolicy(QoSPolicyEnum):
    """Values as rmw's ``rmw_qos_reliability_policy_e``."""

    RELIABLE = 1
    BEST_EFFORT = 2


class DurabilityPolicy(QoSPolicyEnum):
    TRANSIENT_LOCAL = 1
    VOLATILE = 2


class HistoryPolicy(QoSPolicyEnum):
    KEEP_LAST = 1
    KEEP_ALL = 2


@dataclass(frozen=True, slots=True)
class QoSProfile:
    """A QoS profile, as rclpy's, with ROS 2 defaults (reliable, volatile, keep last 10)."""

    reliability: ReliabilityPolicy = ReliabilityPolicy.RELIABLE
    durability: DurabilityPolicy = DurabilityPolicy.VOLATILE
    history: HistoryPolicy = HistoryPolicy.KEEP_LAST
    depth: int = 10
    deadline: Duration | None = None
    lifespan: Duration | None = None

    def __post_init__(self) -> None:
        for field, enum_type in (
            ("reliability", ReliabilityPolicy),
            ("durability", DurabilityPolicy),
            ("history", HistoryPolicy),
        ):
            value = getattr(self, field)
            if not isinstance(value, enum_type):
                try:
                    object.__setattr__(self, field, enum_type(value))
                except ValueError:
                    raise ValueError(
                        f"QoSProfile.{field}: expected a {enum_type.__name__}, got {value!r}"
                    ) from None
        if isinstance(self.depth, bool) or not isinstance(self.depth, int) or self.depth < 0:
            raise ValueError(f"QoSProfile.depth: expected an int >= 0, got {self.depth!r}")
        if self.history is HistoryPolicy.KEEP_LAST and self.depth == 0:
            # rclpy's words (rclpy/qos.py QoSProfile.__init__); the profile is kept
            warnings.warn("A zero depth with KEEP_LAST doesn't make sense; no data could be stored. "
                          "This will be interpreted as SYSTEM_DEFAULT", UserWarning, stacklevel=3)
        for field in ("deadline", "lifespan"):
            value = getattr(self, field)
            if value is not None and not isinstance(value, Duration):
                raise ValueError(f"QoSProfile.{field}: expected a Duration or None, got {value!r}")

    @property
    def queue_limit(self) -> int | None:
        """How many messages a subscription queue holds: ``depth``, or None for KEEP_ALL."""
        if self.history is not HistoryPolicy.KEEP_LAST:
            return None
        return self.depth or SYSTEM_DEFAULT_DEPTH

    def short(self) -> str:
        """A compact description, e.g. ``reliable/volatile/keep_last(10)``."""
        hist = (
            f"keep_last({self.depth})" if self.history is HistoryPolicy.KEEP_LAST else "keep_all"
        )
        return f"{self.reliability.name.lower()}/{self.durability.name.lower()}/{hist}"


#: The queue a KEEP_LAST profile of depth 0 ("system default") gets.
SYSTEM_DEFAULT_DEPTH = 10

qos_profile_sensor_data = QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT, depth=5)
qos_profile_system_default = QoSProfile()


class QoSPresetProfiles(enum.Enum):
    """rclpy's named profiles; ``QoSPresetProfiles.SENSOR_DATA.value`` is a QoSProfile.

    Equal profiles are aliases of one member (``DEFAULT`` of ``SYSTEM_DEFAULT``), as the
    values are compared by equality; every name still resolves.

    rclpy difference: no ``UNKNOWN`` and ``BEST_AVAILABLE`` members (aiorobot has no
    SYSTEM_DEFAULT/UNKNOWN/BEST_AVAILABLE policy values to express them).
    """

    SYSTEM_DEFAULT = qos_profile_system_default
    DEFAULT = QoSProfile()
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = QoSProfile()
    PARAMETERS = QoSProfile(depth=1000)
    PARAMETER_EVENTS = QoSProfile(depth=1000)
    ACTION_STATUS_DEFAULT = QoSProfile(durability=DurabilityPolicy.TRANSIENT_LOCAL, depth=1)

    @classmethod
    def short_keys(cls) -> list[str]:
        return [name.lower() for name in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        return cls[name.upper()].value  # type: ignore[no-any-return]


def to_qos_profile(qos: QoSProfile | int) -> QoSProfile:
    """Accept a profile or an int (KEEP_LAST with that depth), as rclpy does."""
    if isinstance(qos, QoSProfile):
        return qos
    if isinstance(qos, int) and not isinstance(qos, bool):
        return QoSProfile(depth=qos)
    raise TypeError(f"expected a QoSProfile or an int depth, got {qos!r}")


def incompatibility(offered: QoSProfile, requested: QoSProfile) -> str | None:
    """Why a publisher offering ``offered`` cannot serve a subscription requesting ``requested``.

    ROS 2 (DDS request/offer) rules: the subscription must not be stricter than the publisher.
    Returns None when they connect.
    """
    if (
        offered.reliability is ReliabilityPolicy.BEST_EFFORT
        and requested.reliability is ReliabilityPolicy.RELIABLE
    ):
        return "reliability: publisher offers BEST_EFFORT, subscription requests RELIABLE"
    if (
        offered.durability is DurabilityPolicy.VOLATILE
        and requested.durability is DurabilityPolicy.TRANSIENT_LOCAL
    ):
        return "durability: publisher offers VOLATILE, subscription requests TRANSIENT_LOCAL"
    if requested.deadline is not None and (
        offered.deadline is None or offered.deadline > requested.deadline
    ):
        return "deadline: publisher offers a longer deadline than the subscription requests"
    return None
