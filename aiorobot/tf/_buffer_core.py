"""The transform buffer core: tf2's ``BufferCore``, query for query.

Frames form a tree (each frame has one parent at a time). A lookup walks up
from the source and from the target frame to their common ancestor, composing
the links on the way, exactly as ``tf2::BufferCore::walkToTopParent`` does, so
the answers, the errors and their messages carry over from tf2.

Every public method takes and returns ROS messages and :class:`aiorobot.Time`;
state is guarded by a ``threading.Lock`` because the buffer may be fed from one
event loop thread and read from another.
"""

from __future__ import annotations

import logging
import math
import threading
from typing import Any

from ._cache import Sample, StaticCache, TimeCache, display_time
from ._exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)
from ._plans import trace_plan, walk_plan
from ._views import FrameInfo, frames_as_dot, frames_as_yaml
from ._math import IDENTITY_QUAT, Quat, Vec, _canonical, _qinv, _qmul, _qrot
from ._msgs import make_transform_stamped, time_ns, time_from_ns

__all__ = ["BufferCore", "MAX_GRAPH_DEPTH", "DEFAULT_CACHE_TIME_SEC"]

MAX_GRAPH_DEPTH = 1000
DEFAULT_CACHE_TIME_SEC = 10.0
QUATERNION_NORMALIZATION_TOLERANCE = 10e-3
_NO_PARENT = "NO_PARENT"
_ZERO: Vec = (0.0, 0.0, 0.0)

_log = logging.getLogger("aiorobot.tf")


def _strip_slash(frame_id: str) -> str:
    return frame_id[1:] if frame_id.startswith("/") else frame_id


class BufferCore:
    """A tf2 transform buffer without waiting or message conversions on top.

    Parameters
    ----------
    cache_time_sec
        How much history each dynamic frame keeps, in seconds (tf2's default is 10).
    """

    def __init__(self, cache_time_sec: float = DEFAULT_CACHE_TIME_SEC) -> None:
        if not (isinstance(cache_time_sec, (int, float)) and cache_time_sec > 0):
            raise ValueError(f"expected cache_time_sec > 0, got {cache_time_sec!r}")
        self._cache_ns = round(float(cache_time_sec) * 1e9)
        self._lock = threading.Lock()
        # frame id 0 is "no parent", as in tf2
        self._ids: dict[str, int] = {_NO_PARENT: 0}
        self._names: list[str] = [_NO_PARENT]
        self._caches: list[TimeCache | StaticCache | None] = [None]
        self._authority: dict[int, str] = {}
        # per (target_frame, source_frame): [target_id, source_id, plan or None (not traced yet) or False]
        self._plans: dict[tuple[str, str], list[Any]] = {}

    @property
    def cache_time_sec(self) -> float:
        return self._cache_ns / 1e9

    def __repr__(self) -> str:
        with self._lock:
            n = sum(1 for c in self._caches if c is not None)
        return f"<{type(self).__name__} frames={len(self._names) - 1} links={n} cache_time_sec={self.cache_time_sec:g}>"

    # ------------------------------------------------------------------ inserting

    def set_transform(self, transform: Any, authority: str, *, static: bool = False) -> bool:
        """Insert a ``geometry_msgs/TransformStamped`` (``child_frame_id`` to ``header.frame_id``).

        Returns True when stored, False when refused for being older than the
        cache length (logged as a warning, as tf2's ``TF_OLD_DATA``).

        Raises
        ------
        InvalidArgumentException
            On an empty frame id, a frame as its own parent, NaN or infinite
            values, or a quaternion whose squared norm is more than 0.01 from 1.
        """
        try:
            frame_id = transform.header.frame_id
            child_frame_id = transform.child_frame_id
            stamp = transform.header.stamp
            tr = transform.transform.translation
            ro = transform.transform.rotation
            t = (float(tr.x), float(tr.y), float(tr.z))
            q = (float(ro.x), float(ro.y), float(ro.z), float(ro.w))
        except (AttributeError, TypeError, ValueError) as exc:
            raise InvalidArgumentException(
                "expected a geometry_msgs/msg/TransformStamped (header.frame_id, header.stamp, "
                f"child_frame_id, transform.translation, transform.rotation), got "
                f"{type(transform).__name__}: {exc}"
            ) from None
        stored = self._set_transform_raw(frame_id, child_frame_id, time_ns(stamp), t, q, authority, static)
        self._on_insert()
        return stored

    def _set_transform_raw(
        self,
        frame_id: str,
        child_frame_id: str,
        stamp_ns: int,
        t: Vec,
        q: Quat,
        authority: str,
        static: bool,
    ) -> bool:
        parent = _strip_slash(str(frame_id))
        child = _strip_slash(str(child_frame_id))
        problems = []
        if child == parent:
            problems.append(
                f'TF_SELF_TRANSFORM: frame_id and child_frame_id are both "{child}"; '
                "a frame cannot be its own parent"
            )
        if not child:
            problems.append("TF_NO_CHILD_FRAME_ID: child_frame_id is empty; set it to the frame being moved")
        if not parent:
            problems.append(
                f'TF_NO_FRAME_ID: header.frame_id of child "{child}" is empty; set it to the parent frame'
            )
        if not all(math.isfinite(v) for v in (*t, *q)):
            problems.append(
                f'TF_NAN_INPUT: the transform of child "{child}" has NaN or infinite values: '
                f"translation ({t[0]} {t[1]} {t[2]}) rotation ({q[0]} {q[1]} {q[2]} {q[3]})"
            )
        else:
            norm2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]
            if not abs(norm2 - 1.0) < QUATERNION_NORMALIZATION_TOLERANCE:
                problems.append(
                    f'TF_DENORMALIZED_QUATERNION: the rotation of child "{child}" '
                    f"({q[0]} {q[1]} {q[2]} {q[3]}) has squared norm {norm2:g}; expected 1 "
                    f"within {QUATERNION_NORMALIZATION_TOLERANCE}"
                )
        if problems:
            raise InvalidArgumentException(
                f'Ignoring transform from authority "{authority}": ' + "; ".join(problems)
            )
        # stored as tf2 stores it: through a rotation matrix, so normalised and canonical
        qc = _canonical(q)
        with self._lock:
            child_id = self._lookup_or_insert(child)
            parent_id = self._lookup_or_insert(parent)
            cache = self._caches[child_id]
            if cache is None or cache.is_static != static:
                cache = StaticCache() if static else TimeCache(self._cache_ns)
                self._caches[child_id] = cache
                self._plans.clear()  # the tree's shape changed
            elif cache.latest_time_and_parent()[1] != parent_id:
                self._plans.clear()  # a new parent (re-parenting)
            sample: Sample = (parent_id, t[0], t[1], t[2], qc[0], qc[1], qc[2], qc[3])
            if not cache.insert(stamp_ns, sample):
                latest = cache.latest_stamp()
                _log.warning(
                    "TF_OLD_DATA ignoring data from the past for frame %s at time %s according to "
                    "authority %s: it is older than the latest data (%s) minus the cache length "
                    "(%g s). Possible reasons are listed at http://wiki.ros.org/tf/Errors%%20explained",
                    child,
                    display_time(stamp_ns),
                    authority,
                    display_time(latest),
                    self.cache_time_sec,
                )
                return False
            self._authority[child_id] = authority
        return True

    def _on_insert(self) -> None:
        """Hook for subclasses: called after every insert, outside the lock."""

    def _lookup_or_insert(self, name: str) -> int:
        fid = self._ids.get(name)
        if fid is None:
            fid = len(self._names)
            self._ids[name] = fid
            self._names.append(name)
            self._caches.append(None)
        return fid

    def clear(self) -> None:
        """Forget every dynamic transform; static transforms stay (as in tf2)."""
        with self._lock:
            self._plans.clear()
            for cache in self._caches:
                if cache is not None:
                    cache.clear()

    # ------------------------------------------------------------------ validation

    def _validate(self, frame_id: Any, where: str) -> int:
        """Frame number of ``frame_id``, or raise as tf2's ``validateFrameId`` (lock held)."""
        check_frame_id_syntax(frame_id, where)
        fid = self._ids.get(frame_id, 0)
        if fid == 0:
            known = ", ".join(self._names[1:21]) + (", ..." if len(self._names) > 21 else "")
            raise LookupException(
                f'"{frame_id}" passed to {where} does not exist. Known frames: [{known}]'
            )
        return fid

    def _check_frame(self, frame_id: Any, where: str) -> tuple[int, str]:
        """As `_validate` but never raising: (0, reason) on failure (lock held)."""
        try:
            return self._validate(frame_id, where), ""
        except TransformException as exc:
            return 0, str(exc)

    # ------------------------------------------------------------------ walking the tree

    def _loop_error(self) -> LookupException:
        return LookupException(
            "The tf tree is invalid because it contains a loop or a path deeper than "
            f"{MAX_GRAPH_DEPTH} links.\n{self._frames_as_string()}"
        )

    def _connectivity_error(self, source_id: int, target_id: int) -> ConnectivityException:
        return ConnectivityException(
            f"Could not find a connection between '{self._names[target_id]}' and "
            f"'{self._names[source_id]}' because they are not part of the same tree. "
            "Tf has two or more unconnected trees."
        )

    def _latest_common_time(self, target_id: int, source_id: int) -> int:
        """tf2's ``getLatestCommonTime`` (lock held); statics do not limit it; raises."""
        caches = self._caches
        if source_id == target_id:
            cache = caches[source_id]
            return cache.latest_stamp() if cache is not None else 0
        never = 1 << 62
        # walk up from the source, remembering each link's latest time and parent
        source_chain: list[tuple[int, int]] = []
        source_parents: set[int] = set()
        frame = source_id
        depth = 0
        common = never
        while frame != 0:
            cache = caches[frame]
            if cache is None:
                break
            latest, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if latest != 0 and latest < common:
                common = latest
            source_chain.append((latest, parent))
            source_parents.add(parent)
            frame = parent
            if frame == target_id:  # the target is an ancestor of the source
                return 0 if common == never else common
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()
        # walk up from the target until we meet the source's chain
        frame = target_id
        depth = 0
        common = never
        common_parent = 0
        while True:
            cache = caches[frame]
            if cache is None:
                break
            latest, parent = cache.latest_time_and_parent()
            if parent == 0:
                break
            if latest != 0 and latest < common:
                common = latest
            if parent in source_parents:
                common_parent = parent
                break
            frame = parent
            if frame == source_id:  # the source is an ancestor of the target
                return 0 if common == never else common
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()
        if common_parent == 0:
            raise self._connectivity_error(source_id, target_id)
        for latest, parent in source_chain:
            if latest != 0 and latest < common:
                common = latest
            if parent == common_parent:
                break
        return 0 if common == never else common

    def _walk(
        self, target_id: int, source_id: int, t: int, accumulate: bool
    ) -> tuple[int, Vec, Quat]:
        """tf2's ``walkToTopParent`` (lock held): returns (time, translation, rotation).

        The transform maps source coordinates to target coordinates (source2target).
        With ``accumulate=False`` only parents are followed (``canTransform``) and
        the returned transform is the identity.
        """
        if source_id == target_id:
            return t, _ZERO, IDENTITY_QUAT
        if t == 0:
            t = self._latest_common_time(target_id, source_id)
        caches = self._caches
        names = self._names

        # walk to the root from the source, accumulating source2top
        s_vec: Vec = _ZERO
        s_q: Quat = IDENTITY_QUAT
        frame = source_id
        top_parent = frame
        depth = 0
        extrapolation_error = ""
        extrapolation_possible = False
        while frame != 0:
            cache = caches[frame]
            if cache is None:  # the root of the tree has no cache
                top_parent = frame
                break
            if accumulate:
                st, error = cache.get_data(t)
                parent = st[0] if st is not None else 0
            else:
                parent, error = cache.get_parent(t)
            if parent == 0:
                # there may still be a path from the target to this frame
                top_parent = frame
                extrapolation_possible = True
                extrapolation_error = error or self._no_data(frame)
                break
            if frame == target_id:  # the target is an ancestor of the source
                return t, s_vec, s_q
            if accumulate:
                q = (st[4], st[5], st[6], st[7])  # type: ignore[index]
                r = _qrot(q, s_vec)
                s_vec = (r[0] + st[1], r[1] + st[2], r[2] + st[3])  # type: ignore[index]
                s_q = _qmul(q, s_q)
            top_parent = frame
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()

        # walk from the target to that top parent, accumulating target2top
        t_vec: Vec = _ZERO
        t_q: Quat = IDENTITY_QUAT
        frame = target_id
        depth = 0
        while frame != top_parent:
            cache = caches[frame]
            if cache is None:
                break
            if accumulate:
                st, error = cache.get_data(t)
                parent = st[0] if st is not None else 0
            else:
                parent, error = cache.get_parent(t)
            if parent == 0:
                raise ExtrapolationException(
                    f"{error or self._no_data(frame)}, when looking up transform from frame "
                    f"[{names[source_id]}] to frame [{names[target_id]}]"
                )
            if frame == source_id:  # the source is an ancestor of the target
                qi = _qinv(t_q)
                return t, _qrot(qi, (-t_vec[0], -t_vec[1], -t_vec[2])), qi
            if accumulate:
                q = (st[4], st[5], st[6], st[7])  # type: ignore[index]
                r = _qrot(q, t_vec)
                t_vec = (r[0] + st[1], r[1] + st[2], r[2] + st[3])  # type: ignore[index]
                t_q = _qmul(q, t_q)
            frame = parent
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()

        if frame != top_parent:
            if extrapolation_possible:
                raise ExtrapolationException(
                    f"{extrapolation_error}, when looking up transform from frame "
                    f"[{names[source_id]}] to frame [{names[target_id]}]"
                )
            raise self._connectivity_error(source_id, target_id)

        # full path: target2source^-1 ... compose top2target with source2top
        qi = _qinv(t_q)
        iv = _qrot(qi, (-t_vec[0], -t_vec[1], -t_vec[2]))
        r = _qrot(qi, s_vec)
        return t, (r[0] + iv[0], r[1] + iv[1], r[2] + iv[2]), _qmul(qi, s_q)

    def _no_data(self, frame: int) -> str:
        return f"No transform data for frame [{self._names[frame]}] (its history is empty)"

    # ------------------------------------------------------------------ lookups

    def _lookup_raw(self, target_frame: str, source_frame: str, t: int, where: str) -> tuple[int, Vec, Quat]:
        """(stamp_ns, translation, canonical rotation) of source2target at ``t`` (takes the lock)."""
        if target_frame == source_frame:
            if t == 0:
                with self._lock:
                    fid = self._ids.get(target_frame, 0)
                    cache = self._caches[fid]
                    t = cache.latest_stamp() if cache is not None else 0
            return t, _ZERO, IDENTITY_QUAT
        with self._lock:
            entry = self._plans.get((target_frame, source_frame))
            if entry is None:
                target_id = self._validate(target_frame, f"{where} argument target_frame")
                source_id = self._validate(source_frame, f"{where} argument source_frame")
                entry = self._plans[(target_frame, source_frame)] = [target_id, source_id, None]
            target_id, source_id, plan = entry
            if t == 0:
                t = self._latest_common_time(target_id, source_id)
            replayed = walk_plan(plan, t) if plan else None
            if replayed is not None:
                t_out = t
                vec, q = replayed
            else:
                t_out, vec, q = self._walk(target_id, source_id, t, True)
                if plan is None:
                    entry[2] = trace_plan(self._caches, target_id, source_id, t_out, MAX_GRAPH_DEPTH) or False
        # tf2 hands the result through a rotation matrix: same sign convention
        return t_out, vec, _canonical(q)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """The transform taking data from ``source_frame`` into ``target_frame`` at ``time``.

        ``time = Time()`` (zero) means the latest time common to the whole chain;
        the result is stamped with the time used. Returns a
        ``geometry_msgs/TransformStamped`` with ``header.frame_id = target_frame``
        and ``child_frame_id = source_frame``.

        Raises
        ------
        LookupException, ConnectivityException, ExtrapolationException, InvalidArgumentException
        """
        t_out, vec, q = self._lookup_raw(target_frame, source_frame, time_ns(time), "lookup_transform")
        return make_transform_stamped(target_frame, source_frame, t_out, vec, q)

    def _lookup_full_raw(
        self, target_frame: str, target_t: int, source_frame: str, source_t: int, fixed_frame: str
    ) -> tuple[int, Vec, Quat]:
        where = "lookup_transform_full"
        with self._lock:
            self._validate(target_frame, f"{where} argument target_frame")
            self._validate(source_frame, f"{where} argument source_frame")
            self._validate(fixed_frame, f"{where} argument fixed_frame")
        _, v1, q1 = self._lookup_raw(fixed_frame, source_frame, source_t, where)
        t_out, v2, q2 = self._lookup_raw(target_frame, fixed_frame, target_t, where)
        r = _qrot(q2, v1)
        return t_out, (r[0] + v2[0], r[1] + v2[1], r[2] + v2[2]), _canonical(_qmul(q2, q1))

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
    ) -> Any:
        """Time travel: ``source_frame`` at ``source_time`` into ``target_frame`` at ``target_time``.

        ``fixed_frame`` is a frame assumed not to move between the two times
        (typically ``odom`` or ``map``). The result is stamped with the time used
        for the target.
        """
        t_out, vec, q = self._lookup_full_raw(
            target_frame, time_ns(target_time), source_frame, time_ns(source_time), fixed_frame
        )
        return make_transform_stamped(target_frame, source_frame, t_out, vec, q)

    def _can_transform_ids(self, target_id: int, source_id: int, t: int) -> tuple[bool, str]:
        """tf2's ``canTransformInternal`` (lock held)."""
        if target_id == 0 or source_id == 0:
            return False, "Source or target frame is not yet defined"
        if target_id == source_id:
            return True, ""
        try:
            self._walk(target_id, source_id, t, False)
        except TransformException as exc:
            return False, str(exc)
        return True, ""

    def _can_transform_raw(self, target_frame: Any, source_frame: Any, t: int) -> tuple[bool, str]:
        if target_frame == source_frame:
            return True, ""
        with self._lock:
            target_id, error = self._check_frame(target_frame, "can_transform argument target_frame")
            if target_id == 0:
                return False, error
            source_id, error = self._check_frame(source_frame, "can_transform argument source_frame")
            if source_id == 0:
                return False, error
            return self._can_transform_ids(target_id, source_id, t)

    def can_transform(
        self, target_frame: str, source_frame: str, time: Any, *, return_debug_tuple: bool = False
    ) -> bool | tuple[bool, str]:
        """Whether `lookup_transform` would succeed now. Never raises for tf errors.

        With ``return_debug_tuple=True`` returns ``(ok, reason)`` (reason is ''
        on success), as tf2_ros does.
        """
        ok, reason = self._can_transform_raw(target_frame, source_frame, time_ns(time))
        return (ok, reason) if return_debug_tuple else ok

    def _can_transform_full_raw(
        self, target_frame: Any, target_t: int, source_frame: Any, source_t: int, fixed_frame: Any
    ) -> tuple[bool, str]:
        where = "can_transform_full"
        with self._lock:
            ids = []
            for name, arg in ((target_frame, "target_frame"), (source_frame, "source_frame"), (fixed_frame, "fixed_frame")):
                fid, error = self._check_frame(name, f"{where} argument {arg}")
                if fid == 0:
                    return False, error
                ids.append(fid)
            target_id, source_id, fixed_id = ids
            ok, reason = self._can_transform_ids(target_id, fixed_id, target_t)
            if not ok:
                return ok, reason
            return self._can_transform_ids(fixed_id, source_id, source_t)

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        *,
        return_debug_tuple: bool = False,
    ) -> bool | tuple[bool, str]:
        """Whether `lookup_transform_full` would succeed now. Never raises for tf errors."""
        ok, reason = self._can_transform_full_raw(
            target_frame, time_ns(target_time), source_frame, time_ns(source_time), fixed_frame
        )
        return (ok, reason) if return_debug_tuple else ok

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        """The latest time at which every link between the two frames has data.

        Static links do not limit it; an all-static chain gives ``Time()`` (zero).
        """
        with self._lock:
            target_id = self._validate(target_frame, "get_latest_common_time argument target_frame")
            source_id = self._validate(source_frame, "get_latest_common_time argument source_frame")
            return time_from_ns(self._latest_common_time(target_id, source_id))

    # ------------------------------------------------------------------ introspection

    def get_all_frame_names(self) -> list[str]:
        """Every frame id the buffer has heard of, as child or as parent."""
        with self._lock:
            return self._names[1:]

    def frame_exists(self, frame_id: str) -> bool:
        with self._lock:
            return frame_id in self._ids and frame_id != _NO_PARENT

    def _parent_of(self, cache: TimeCache | StaticCache) -> int:
        sample, _ = cache.get_data(0)
        return sample[0] if sample is not None else 0

    def _frames_as_string(self) -> str:
        lines = []
        for fid in range(1, len(self._names)):
            cache = self._caches[fid]
            if cache is None:
                continue
            lines.append(f"Frame {self._names[fid]} exists with parent {self._names[self._parent_of(cache)]}.\n")
        return "".join(lines)

    def all_frames_as_string(self) -> str:
        """One line per frame: ``Frame X exists with parent Y.`` (tf2's format)."""
        with self._lock:
            return self._frames_as_string()

    def frame_infos(self) -> list[FrameInfo]:
        """One :class:`FrameInfo` per frame that has data: parent, authority, rate, stamps."""
        with self._lock:
            infos = []
            for fid in range(1, len(self._names)):
                cache = self._caches[fid]
                if cache is None or len(cache) == 0:
                    continue
                latest = cache.latest_stamp()
                oldest = cache.oldest_stamp()
                infos.append(
                    FrameInfo(
                        frame=self._names[fid],
                        parent=self._names[self._parent_of(cache)],
                        authority=self._authority.get(fid, "no recorded authority"),
                        # tf2's figure: samples over the span, the span at least 100 us
                        rate_hz=len(cache) * 1e9 / max(latest - oldest, 100_000),
                        latest_ns=latest,
                        oldest_ns=oldest,
                        static=cache.is_static,
                    )
                )
            return infos

    def all_frames_as_yaml(self, current_time: Any = None) -> str:
        """tf2's YAML view: per frame its parent, broadcaster, rate and data span."""
        now = time_ns(current_time) if current_time is not None else 0
        return frames_as_yaml(self.frame_infos(), now)

    def to_dot(self, current_time: Any = None) -> str:
        """Graphviz text of the tree: one edge per link, labelled with the publishing
        authority, the average rate and the latest stamp (``static`` for static links)."""
        now = time_ns(current_time) if current_time is not None else 0
        return frames_as_dot(self.frame_infos(), self.get_all_frame_names(), now)


def check_frame_id_syntax(frame_id: Any, where: str) -> None:
    """Raise InvalidArgumentException for a non-string, empty or '/'-prefixed frame id."""
    if not isinstance(frame_id, str):
        raise InvalidArgumentException(
            f"Invalid argument {frame_id!r} passed to {where} - expected a frame id string, "
            f"got {type(frame_id).__name__}"
        )
    if not frame_id:
        raise InvalidArgumentException(
            f'Invalid argument "{frame_id}" passed to {where} - in tf2 frame_ids cannot be empty'
        )
    if frame_id.startswith("/"):
        raise InvalidArgumentException(
            f'Invalid argument "{frame_id}" passed to {where} - in tf2 frame_ids cannot start '
            f"with a '/'; use \"{frame_id.lstrip('/')}\""
        )

