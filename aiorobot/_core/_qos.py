"""Quality of service: profiles, policies, presets and the compatibility rules of ROS 2."""

from __future__ import annotations

import enum
import warnings
from dataclasses import dataclass

from ._time import Duration, Infinite

__all__ = [
    "DurabilityPolicy",
    "HistoryPolicy",
    "LivelinessPolicy",
    "QoSPolicyEnum",
    "QoSPolicyKind",
    "QoSPresetProfiles",
    "QoSProfile",
    "ReliabilityPolicy",
    "qos_profile_sensor_data",
    "qos_policy_name_from_kind",
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


class LivelinessPolicy(QoSPolicyEnum):
    """How a publisher shows it is alive (values as rmw's ``rmw_qos_liveliness_policy_e``).

    ``AUTOMATIC``: the runtime does, for as long as the publisher exists.
    ``MANUAL_BY_TOPIC``: the publisher must publish or call ``assert_liveliness()``
    at least once per ``liveliness_lease_duration``.
    """

    AUTOMATIC = 1
    MANUAL_BY_TOPIC = 3


class QoSPolicyKind(enum.IntEnum):
    """Which policy made two endpoints incompatible (rclpy's and rmw's values)."""

    INVALID = 1 << 0
    DURABILITY = 1 << 1
    DEADLINE = 1 << 2
    LIVELINESS = 1 << 3
    RELIABILITY = 1 << 4
    HISTORY = 1 << 5
    LIFESPAN = 1 << 6
    DEPTH = 1 << 7
    LIVELINESS_LEASE_DURATION = 1 << 8
    AVOID_ROS_NAMESPACE_CONVENTIONS = 1 << 9


def qos_policy_name_from_kind(policy_kind: QoSPolicyKind | int) -> str:
    """The policy's name (``"DURABILITY"``), as rclpy's."""
    return QoSPolicyKind(policy_kind).name


def finite_ns(duration: Duration | None) -> int | None:
    """A deadline, lifespan or lease in nanoseconds, or None when it is infinite (None, zero or
    ``Infinite``: rmw's "default" and "infinite" both mean no limit)."""
    if duration is None:
        return None
    ns = duration.nanoseconds
    if ns <= 0 or ns >= Infinite.nanoseconds:
        return None
    return ns


@dataclass(frozen=True, slots=True)
class QoSProfile:
    """A QoS profile, as rclpy's, with ROS 2 defaults (reliable, volatile, keep last 10)."""

    reliability: ReliabilityPolicy = ReliabilityPolicy.RELIABLE
    durability: DurabilityPolicy = DurabilityPolicy.VOLATILE
    history: HistoryPolicy = HistoryPolicy.KEEP_LAST
    depth: int = 10
    deadline: Duration | None = None
    lifespan: Duration | None = None
    liveliness: LivelinessPolicy = LivelinessPolicy.AUTOMATIC
    liveliness_lease_duration: Duration | None = None

    def __post_init__(self) -> None:
        for field, enum_type in (
            ("reliability", ReliabilityPolicy),
            ("durability", DurabilityPolicy),
            ("history", HistoryPolicy),
            ("liveliness", LivelinessPolicy),
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
        for field in ("deadline", "lifespan", "liveliness_lease_duration"):
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


def incompatible_policy(offered: QoSProfile, requested: QoSProfile) -> tuple[QoSPolicyKind, str] | None:
    """The policy for which a publisher offering ``offered`` cannot serve a subscription
    requesting ``requested``, and why; None when they connect.

    ROS 2 (DDS request/offer) rules: the subscription must not be stricter than the publisher
    in reliability, durability, deadline, liveliness kind and liveliness lease.
    """
    if (
        offered.reliability is ReliabilityPolicy.BEST_EFFORT
        and requested.reliability is ReliabilityPolicy.RELIABLE
    ):
        return QoSPolicyKind.RELIABILITY, "reliability: publisher offers BEST_EFFORT, subscription requests RELIABLE"
    if (
        offered.durability is DurabilityPolicy.VOLATILE
        and requested.durability is DurabilityPolicy.TRANSIENT_LOCAL
    ):
        return QoSPolicyKind.DURABILITY, "durability: publisher offers VOLATILE, subscription requests TRANSIENT_LOCAL"
    requested_deadline = finite_ns(requested.deadline)
    if requested_deadline is not None:
        offered_deadline = finite_ns(offered.deadline)
        if offered_deadline is None or offered_deadline > requested_deadline:
            return QoSPolicyKind.DEADLINE, "deadline: publisher offers a longer deadline than the subscription requests"
    if offered.liveliness < requested.liveliness:
        return QoSPolicyKind.LIVELINESS, (
            f"liveliness: publisher offers {offered.liveliness.name}, subscription requests {requested.liveliness.name}"
        )
    requested_lease = finite_ns(requested.liveliness_lease_duration)
    if requested_lease is not None:
        offered_lease = finite_ns(offered.liveliness_lease_duration)
        if offered_lease is None or offered_lease > requested_lease:
            return QoSPolicyKind.LIVELINESS, (
                "liveliness: publisher offers a longer liveliness lease than the subscription requests"
            )
    return None


def incompatibility(offered: QoSProfile, requested: QoSProfile) -> str | None:
    """Why a publisher offering ``offered`` cannot serve a subscription requesting ``requested``
    (see :func:`incompatible_policy`); None when they connect."""
    found = incompatible_policy(offered, requested)
    return None if found is None else found[1]
