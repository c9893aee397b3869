"""Online 2D lidar SLAM, the pure core: scans + odometry in, a pose graph and an occupancy map out.

:class:`Slam` follows slam_toolbox's (Karto's) pipeline and parameter names:

1. A scan becomes a graph node once odometry says the robot moved ``minimum_travel_distance``
   or turned ``minimum_travel_heading`` since the last node (the first scan always does).
2. The node's pose is the correlative match (``_slam_matcher``) of its scan against the running
   buffer (the last ``scan_buffer_size`` nodes within ``scan_buffer_maximum_scan_distance``),
   searched around the odometry prediction; it is linked to the previous node by a scan-match
   edge (covariance from the match) and an odometry edge (covariance growing with the motion).
   A match whose response is below ``recovery_search_response`` is searched again over the loop
   window (odometry slipped); one below ``link_match_minimum_response_fine`` is not used: the node
   keeps the odometry prediction.
3. Loop closure (``do_loop_closing``): nodes older than the running buffer within
   ``loop_search_maximum_distance`` are candidates; with at least ``loop_match_minimum_chain_size``
   of them, the scan is matched against their scans over the wide ``loop_search_space_dimension``
   window. The closure is accepted only when the response reaches ``loop_match_minimum_response_fine``,
   the match is unambiguous (no pose farther than ``loop_match_ambiguity_radius`` fits within
   ``loop_match_maximum_ambiguity`` of it: a corridor's repeated bays fail this) and its
   position variance is at most ``loop_match_maximum_variance``; then the graph is optimised
   (``_slam_graph``, robust kernel on closures).
4. The map is the log-odds occupancy grid (``_mapping``'s kernel) of every node's scan at its
   graph pose, redrawn from scratch after an optimisation moved the nodes.

Bad input is counted, never fatal: NaN beams are dropped (``beams_invalid``), as are +-inf ones
(REP 117's no return / too close: ``beams_out_of_range``); a scan
with fewer than ``minimum_returns`` usable beams (empty, all beyond range) is skipped
(``scans_empty``); odometry that jumps (more than ``maximum_odometry_jump`` m or rad between two
scans, or backwards in time) is not integrated (``odometry_jumps``): the next scan continues
from the new odometry as if the robot had not moved.

``mode = "localization"`` matches scans against a loaded graph without changing it.
"""

from __future__ import annotations

import io
import json
import math
import time
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._maps import OccupancyMap
from ._slam_graph import PoseGraph, compose, relative, wrap
from ._slam_matcher import Match, match, scan_points, transform_points

__all__ = ["MODES", "Slam", "SlamParameters", "SlamStatistics", "SlamUpdate"]

MODES = ("mapping", "localization")
#: the pose graph file's format tag (a .posegraph file is an .npz archive with these arrays)
_FORMAT = "aiorobot-slam-posegraph-1"


@dataclass(frozen=True, slots=True)
class SlamParameters:
    """slam_toolbox's parameters (names and meaning) where they apply; the defaults suit a 12 m lidar."""

    mode: str = "mapping"
    resolution: float = 0.05
    max_laser_range: float = 12.0
    minimum_travel_distance: float = 0.5
    minimum_travel_heading: float = 0.5
    scan_buffer_size: int = 20
    scan_buffer_maximum_scan_distance: float = 10.0
    link_match_minimum_response_fine: float = 0.1
    #: ours: a match responding below this is searched again over the loop-closure window
    recovery_search_response: float = 0.5
    correlation_search_space_dimension: float = 0.5
    correlation_search_space_resolution: float = 0.025
    correlation_search_space_smear_deviation: float = 0.03
    coarse_search_angle_offset: float = 0.349
    do_loop_closing: bool = True
    loop_search_maximum_distance: float = 3.0
    loop_match_minimum_chain_size: int = 10
    loop_match_minimum_response_fine: float = 0.6
    loop_search_space_dimension: float = 3.0
    loop_search_space_resolution: float = 0.05
    loop_search_space_smear_deviation: float = 0.05
    loop_search_angle_offset: float = 0.2
    #: ours: the acceptance test's ambiguity ratio, radius (m) and largest position variance (m^2)
    loop_match_maximum_ambiguity: float = 0.85
    loop_match_ambiguity_radius: float = 0.5
    loop_match_maximum_variance: float = 0.01
    #: ours: odometry steps larger than this (m, or rad) between two scans are jumps, not motion
    maximum_odometry_jump: float = 1.0
    minimum_returns: int = 20

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"mode: expected one of {', '.join(map(repr, MODES))}, found {self.mode!r}")
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{f.name}: expected a finite number >= 0, found {v!r}")
        for name in ("resolution", "max_laser_range", "correlation_search_space_smear_deviation",
                     "loop_search_space_smear_deviation"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}: expected a number > 0, found {getattr(self, name)!r}")
        if self.scan_buffer_size < 1:
            raise ValueError(f"scan_buffer_size: expected an int >= 1, found {self.scan_buffer_size!r}")


@dataclass(frozen=True, slots=True)
class SlamStatistics:
    """Counts since construction (or loading) and the last timings."""

    scans: int
    nodes: int
    loop_closures: int
    loop_closures_rejected: int
    loop_closure_attempts: int
    matches_failed: int
    recovery_searches: int
    beams_invalid: int
    beams_out_of_range: int
    scans_empty: int
    odometry_jumps: int
    optimizations: int
    last_match_ms: float
    last_optimization_ms: float


@dataclass(frozen=True, slots=True)
class SlamUpdate:
    """What :meth:`Slam.add_scan` did with a scan: ``node`` (its index, or -1: no node), whether a
    loop closed, and the skip reason when it was not used (``""``, ``"empty"``, ``"odometry_jump"``)."""

    node: int = -1
    loop_closed: bool = False
    skipped: str = ""


class Slam:
    """Online graph SLAM on 2D scans. :meth:`add_scan` per scan; :attr:`pose` is map -> robot."""

    def __init__(self, params: SlamParameters | None = None, *, start_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        self.params = params or SlamParameters()
        self.graph = PoseGraph()
        self.node_points: list[NDArray[np.float64]] = []  #: each node's returns, robot frame
        self.node_odom: list[tuple[float, float, float]] = []  #: odometry pose at each node
        self.start_pose = tuple(float(v) for v in start_pose)
        #: map -> odom (x, y, yaw): where the odometry frame sits in the map
        self.map_to_odom: tuple[float, float, float] = self.start_pose  # type: ignore[assignment]
        self._anchor: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None  # (map pose, odom pose)
        self._last_odom: tuple[float, float, float] | None = None
        self._last_stamp: float | None = None
        self._prev_node: int | None = None  #: the last node this session added (None: none yet, or after load)
        self._odometry_link = True  #: whether odometry since _prev_node is continuous
        #: localization mode's recent scans (not graph nodes): matched against with the loaded nodes
        self._loc_poses: list[tuple[float, float, float]] = []
        self._loc_points: list[NDArray[np.float64]] = []
        self._mapper: Any = None  #: the log-odds grid and how many nodes it holds
        self._mapped_nodes = 0
        self._map_cache: tuple[int, OccupancyMap] | None = None
        self._map_version = 0
        self.closures: list[tuple[int, int]] = []
        self._counts = dict(scans=0, loop_closures=0, loop_closures_rejected=0, loop_closure_attempts=0,
                            matches_failed=0, recovery_searches=0, beams_invalid=0, beams_out_of_range=0, scans_empty=0, odometry_jumps=0, optimizations=0)
        self._last_match_ms = 0.0
        self._last_opt_ms = 0.0

    def __repr__(self) -> str:
        x, y, yaw = self.pose
        return (f"<Slam {self.params.mode} nodes={len(self.graph)} closures={self._counts['loop_closures']} "
                f"pose=({x:.2f}, {y:.2f}, {yaw:.2f})>")

    # -- state ---------------------------------------------------------------------------

    @property
    def pose(self) -> tuple[float, float, float]:
        """map -> robot at the last scan."""
        if self._last_odom is None:
            return self.start_pose  # type: ignore[return-value]
        return compose(self.map_to_odom, self._last_odom)

    def statistics(self) -> SlamStatistics:
        return SlamStatistics(nodes=len(self.graph), last_match_ms=self._last_match_ms,
                              last_optimization_ms=self._last_opt_ms, **self._counts)

    # -- input ---------------------------------------------------------------------------

    def add_scan(self, odom: tuple[float, float, float], ranges: NDArray[np.float64], angle_min: float,
                 angle_increment: float, range_min: float, range_max: float, *,
                 laser_pose: tuple[float, float, float] = (0.0, 0.0, 0.0), stamp_sec: float | None = None) -> SlamUpdate:
        """One scan taken at odometry pose ``odom`` (odom -> robot) with the laser at ``laser_pose`` on the robot."""
        p = self.params
        self._counts["scans"] += 1
        odom = (float(odom[0]), float(odom[1]), float(odom[2]))
        r = np.asarray(ranges, dtype=np.float64)
        self._counts["beams_invalid"] += int(np.count_nonzero(np.isnan(r)))
        self._counts["beams_out_of_range"] += int(np.count_nonzero(np.isinf(r)))
        if stamp_sec is not None and self._last_stamp is not None and stamp_sec < self._last_stamp:
            self._counts["odometry_jumps"] += 1
            return SlamUpdate(skipped="odometry_jump")
        if not all(math.isfinite(v) for v in odom):
            self._counts["odometry_jumps"] += 1
            return SlamUpdate(skipped="odometry_jump")
        if self._last_odom is not None:
            step = relative(self._last_odom, odom)
            if math.hypot(step[0], step[1]) > p.maximum_odometry_jump or abs(step[2]) > p.maximum_odometry_jump:
                # keep map -> robot where it was: the new odometry frame is re-anchored to it
                self._counts["odometry_jumps"] += 1
                here = compose(self.map_to_odom, self._last_odom)
                self.map_to_odom = compose(here, relative(odom, (0.0, 0.0, 0.0)))
                if self._anchor is not None:
                    self._anchor = (here, odom)
                self._odometry_link = False  # the next node's odometry edge would span the jump
                self._last_odom = odom
                self._last_stamp = stamp_sec
                return SlamUpdate(skipped="odometry_jump")
        points = scan_points(r, angle_min, angle_increment, range_min, min(range_max, p.max_laser_range), laser_pose)
        if len(points) < p.minimum_returns:
            self._counts["scans_empty"] += 1
            if self._last_odom is None:
                return SlamUpdate(skipped="empty")
            self._last_odom = odom
            self._last_stamp = stamp_sec
            return SlamUpdate(skipped="empty")
        self._last_odom = odom
        self._last_stamp = stamp_sec
        if self._anchor is not None:
            moved = relative(self._anchor[1], odom)
            if math.hypot(moved[0], moved[1]) < p.minimum_travel_distance and abs(moved[2]) < p.minimum_travel_heading:
                return SlamUpdate()
        if p.mode == "localization":
            return self._localize(odom, points)
        return self._add_node(odom, points)

    # -- mapping -------------------------------------------------------------------------

    def _predict(self, odom: tuple[float, float, float]) -> tuple[float, float, float]:
        if self._anchor is None:
            return compose(self.map_to_odom, odom)
        return compose(self._anchor[0], relative(self._anchor[1], odom))

    def _prior_covariance(self, odom: tuple[float, float, float]) -> NDArray[np.float64]:
        """Covariance (map frame) of the odometry prediction: grows with the motion since the anchor."""
        moved = relative(self._anchor[1], odom) if self._anchor is not None else (0.0, 0.0, 0.0)
        sd_t = 0.05 * math.hypot(moved[0], moved[1]) + 0.005
        sd_r = 0.05 * abs(moved[2]) + 0.005
        return np.diag([sd_t ** 2, sd_t ** 2, sd_r ** 2])

    def _match_near(self, reference: NDArray[np.float64], points: NDArray[np.float64], prior: tuple[float, float, float],
                    odom: tuple[float, float, float]) -> tuple[tuple[float, float, float], Match | None]:
        """Match against ``reference`` near the odometry prediction: (the pose both support, the match),
        or (the prediction, None) when the response is below ``link_match_minimum_response_fine``."""
        p = self.params
        t0 = time.perf_counter()
        m = match(reference, points, prior, resolution=p.correlation_search_space_resolution,
                  smear_deviation=p.correlation_search_space_smear_deviation,
                  linear_half=0.5 * p.correlation_search_space_dimension, angular_half=p.coarse_search_angle_offset)
        prior_cov = self._prior_covariance(odom)
        if m.response < p.recovery_search_response:
            # odometry put the scan where it does not fit (a slip, a glitch under load): search as widely
            # as a loop closure does, and trust what fits there over the odometry
            wide = match(reference, points, prior, resolution=p.loop_search_space_resolution,
                         smear_deviation=p.loop_search_space_smear_deviation,
                         linear_half=0.5 * p.loop_search_space_dimension, angular_half=p.coarse_search_angle_offset,
                         block=8)
            if wide.response > m.response:
                m = match(reference, points, wide.pose, resolution=p.correlation_search_space_resolution,
                          smear_deviation=p.correlation_search_space_smear_deviation,
                          linear_half=0.5 * p.correlation_search_space_dimension, angular_half=p.coarse_search_angle_offset)
                prior_cov = np.diag([1e2, 1e2, 1e2])
                self._counts["recovery_searches"] += 1
        self._last_match_ms = (time.perf_counter() - t0) * 1e3
        if m.response < p.link_match_minimum_response_fine:
            self._counts["matches_failed"] += 1
            return prior, None
        return _fuse(prior, prior_cov, m), m

    def _buffer(self, pose: tuple[float, float, float], exclude_from: int) -> list[int]:
        """The running buffer: the nodes before ``exclude_from`` back along the chain; after a load,
        when this session has no node yet, the loaded nodes nearest to ``pose``."""
        p = self.params
        out: list[int] = []
        if self._prev_node is None:
            d = np.hypot(self.graph.poses[:exclude_from, 0] - pose[0], self.graph.poses[:exclude_from, 1] - pose[1])
            order = np.argsort(d)[: p.scan_buffer_size]
            return [int(j) for j in order if d[j] <= p.scan_buffer_maximum_scan_distance]
        for i in range(exclude_from - 1, -1, -1):
            if len(out) >= p.scan_buffer_size:
                break
            q = self.graph.poses[i]
            if math.hypot(q[0] - pose[0], q[1] - pose[1]) <= p.scan_buffer_maximum_scan_distance:
                out.append(i)
        return out

    def _reference(self, nodes: list[int]) -> NDArray[np.float64]:
        return np.vstack([transform_points(self.graph.poses[i], self.node_points[i]) for i in nodes])

    def _add_node(self, odom: tuple[float, float, float], points: NDArray[np.float64]) -> SlamUpdate:
        p = self.params
        prior = self._predict(odom)
        n = len(self.graph)
        pose = prior
        m: Match | None = None
        buffer = self._buffer(prior, n) if n else []
        if buffer:
            pose, m = self._match_near(self._reference(buffer), points, prior, odom)
        i = self.graph.add_node(pose)
        self.node_points.append(points)
        self.node_odom.append(odom)
        prev = self._prev_node
        linked = False
        if prev is not None and self._odometry_link:
            step = relative(self.node_odom[prev], odom)
            d = math.hypot(step[0], step[1])
            sd_t, sd_r = 0.1 * d + 0.02, 0.1 * abs(step[2]) + 0.02
            self.graph.add_edge(prev, i, step, np.diag([sd_t ** 2, sd_t ** 2, sd_r ** 2]), "odometry")
            linked = True
        if prev is None and m is not None:  # continuing a loaded graph: link to the nearest loaded node
            prev = buffer[0]
        if prev is not None and m is not None:
            self.graph.add_edge(prev, i, relative(tuple(self.graph.poses[prev]), m.pose),  # type: ignore[arg-type]
                                _edge_covariance(tuple(self.graph.poses[prev]), m.edge_covariance), "scan_match")
            linked = True
        if not linked and n:  # no match after a load or an odometry jump: a loose link keeps the graph connected
            prev = prev if prev is not None else (buffer[0] if buffer else n - 1)
            self.graph.add_edge(prev, i, relative(tuple(self.graph.poses[prev]), pose), np.diag([1.0, 1.0, 0.3]),  # type: ignore[arg-type]
                                "odometry")
        self._prev_node = i
        self._odometry_link = True
        closed = False
        if p.do_loop_closing and n:
            closed = self._close_loop(i, points)
        self._anchor = (tuple(float(v) for v in self.graph.poses[i]), odom)  # type: ignore[assignment]
        self.map_to_odom = compose(self._anchor[0], relative(odom, (0.0, 0.0, 0.0)))
        self._map_version += 1
        return SlamUpdate(node=i, loop_closed=closed)

    def _close_loop(self, i: int, points: NDArray[np.float64]) -> bool:
        p = self.params
        pose = tuple(self.graph.poses[i])
        recent = set(self._buffer(pose, i)) | set(range(max(0, i - p.scan_buffer_size), i))  # type: ignore[arg-type]
        dist = np.hypot(self.graph.poses[:i, 0] - pose[0], self.graph.poses[:i, 1] - pose[1])
        candidates = [j for j in np.flatnonzero(dist <= p.loop_search_maximum_distance) if j not in recent]
        if len(candidates) < p.loop_match_minimum_chain_size:
            return False
        self._counts["loop_closure_attempts"] += 1
        t0 = time.perf_counter()
        m = match(self._reference(candidates), points, pose, resolution=p.loop_search_space_resolution,  # type: ignore[arg-type]
                  smear_deviation=p.loop_search_space_smear_deviation, linear_half=0.5 * p.loop_search_space_dimension,
                  angular_half=p.loop_search_angle_offset, block=8, ambiguity_radius=p.loop_match_ambiguity_radius)
        self._last_match_ms = (time.perf_counter() - t0) * 1e3
        accepted = (m.response >= p.loop_match_minimum_response_fine and m.ambiguity <= p.loop_match_maximum_ambiguity
                    and max(m.covariance[0, 0], m.covariance[1, 1]) <= p.loop_match_maximum_variance)
        if not accepted:
            self._counts["loop_closures_rejected"] += 1
            return False
        j = int(candidates[int(np.argmin(np.hypot(self.graph.poses[candidates, 0] - m.pose[0],
                                                   self.graph.poses[candidates, 1] - m.pose[1])))])
        cov = _edge_covariance(tuple(self.graph.poses[j]), m.edge_covariance) * 4.0  # type: ignore[arg-type]
        # the edge measures node i in node j's frame, j's pose taken as the graph has it now
        self.graph.add_edge(j, i, relative(tuple(self.graph.poses[j]), m.pose), cov, "loop_closure")  # type: ignore[arg-type]
        result = self.graph.optimize()
        self._mapper = None  # the nodes moved: the next map is drawn again
        self._last_opt_ms = result.wall_sec * 1e3
        self._counts["optimizations"] += 1
        self._counts["loop_closures"] += 1
        self.closures.append((j, i))
        return True

    # -- localization --------------------------------------------------------------------

    def _localize(self, odom: tuple[float, float, float], points: NDArray[np.float64]) -> SlamUpdate:
        p = self.params
        prior = self._predict(odom)
        near = np.flatnonzero(np.hypot(self.graph.poses[:, 0] - prior[0], self.graph.poses[:, 1] - prior[1])
                              <= p.loop_search_maximum_distance)
        refs = [transform_points(self.graph.poses[j], self.node_points[j]) for j in near]
        refs += [transform_points(q, pts) for q, pts in zip(self._loc_poses, self._loc_points)]
        pose = self._match_near(np.vstack(refs), points, prior, odom)[0] if refs else prior
        self._loc_poses = (self._loc_poses + [pose])[-3:]  # the last three: where the loaded map ends, they carry on
        self._loc_points = (self._loc_points + [points])[-3:]
        self._anchor = (pose, odom)
        self.map_to_odom = compose(pose, relative(odom, (0.0, 0.0, 0.0)))
        return SlamUpdate()

    # -- map -----------------------------------------------------------------------------

    @property
    def map_version(self) -> int:
        """Grows whenever the map may have changed (a node added, the graph moved)."""
        return self._map_version

    def occupancy_map(self, frame_id: str = "map") -> OccupancyMap:
        """The occupancy grid of every node's scan at its graph pose.

        New nodes are drawn into the grid as they come; after an optimisation moved the nodes, or
        when a node's scan reaches past the grid, the grid is drawn again from every node.
        """
        if self._map_cache is not None and self._map_cache[0] == self._map_version:
            return self._map_cache[1]
        res = self.params.resolution
        n = len(self.graph)
        if n == 0:
            return OccupancyMap(np.full((1, 1), -1, dtype=np.int8), res, (self.start_pose[0], self.start_pose[1], 0.0), frame_id)
        new = [transform_points(self.graph.poses[i], self.node_points[i]) for i in range(self._mapped_nodes, n)]
        if self._mapper is None or not all(self._fits(q) for q in new):
            self._redraw()
        else:
            for i, q in zip(range(self._mapped_nodes, n), new):
                _integrate(self._mapper, float(self.graph.poses[i, 0]), float(self.graph.poses[i, 1]), q)
            self._mapped_nodes = n
        grid = self._mapper.to_map(frame_id)
        self._map_cache = (self._map_version, grid)
        return grid

    def _fits(self, points: NDArray[np.float64]) -> bool:
        m = self._mapper
        h, w = m.logodds.shape
        lo = np.array(m.origin)
        return bool(np.all(points.min(axis=0) >= lo) and np.all(points.max(axis=0) < lo + (w * m.resolution, h * m.resolution)))

    def _redraw(self) -> None:
        """Draw every node into a fresh grid 5 m larger all round than what the scans reach (room to grow)."""
        from ._mapping import OccupancyMapper

        res = self.params.resolution
        world = [transform_points(self.graph.poses[i], self.node_points[i]) for i in range(len(self.graph))]
        allp = np.vstack(world + [self.graph.poses[:, :2]])
        lo = np.floor((allp.min(axis=0) - 5.0) / res) * res
        hi = allp.max(axis=0) + 5.0
        self._mapper = OccupancyMapper((float(hi[0] - lo[0]), float(hi[1] - lo[1])), res, (float(lo[0]), float(lo[1])))
        for i, pts in enumerate(world):
            _integrate(self._mapper, float(self.graph.poses[i, 0]), float(self.graph.poses[i, 1]), pts)
        self._mapped_nodes = len(self.graph)

    # -- serialisation (slam_toolbox's serialize_map / deserialize_map) ---------------------

    def save(self, path: str | Path) -> Path:
        """Write the pose graph, its scans and the parameters to ``path`` (``.posegraph`` added when missing)."""
        path = Path(path)
        if path.suffix != ".posegraph":
            path = path.with_name(path.name + ".posegraph")
        counts = np.array([len(q) for q in self.node_points], dtype=np.int64)
        arrays = dict(self.graph.arrays(), points=np.vstack(self.node_points) if self.node_points else np.zeros((0, 2)),
                      point_counts=counts, node_odom=np.asarray(self.node_odom, dtype=np.float64).reshape(-1, 3),
                      meta=np.array(json.dumps({"format": _FORMAT, "parameters": asdict(self.params),
                                                "closures": self.closures})))
        buf = io.BytesIO()
        np.savez_compressed(buf, **arrays)
        path.write_bytes(buf.getvalue())
        return path

    @classmethod
    def load(cls, path: str | Path, params: SlamParameters | None = None) -> Slam:
        """Read a graph written by :meth:`save`; ``params`` (default: the saved ones) may change the mode.

        Raises ``ValueError`` naming the file when it is not such a graph.
        """
        path = Path(path)
        if not path.exists() and path.with_name(path.name + ".posegraph").exists():
            path = path.with_name(path.name + ".posegraph")
        try:
            with np.load(path, allow_pickle=False) as z:
                data = {key: z[key] for key in z.files}
            meta = json.loads(str(data["meta"]))
        except (OSError, ValueError, KeyError) as err:
            raise ValueError(f"{path}: expected a pose graph written by aiorobot's SLAM ({_FORMAT}), cannot read it: {err}") from None
        if meta.get("format") != _FORMAT:
            raise ValueError(f"{path}: expected format {_FORMAT!r}, found {meta.get('format')!r}")
        saved = SlamParameters(**meta["parameters"])
        slam = cls(params or saved)
        slam.graph = PoseGraph.from_arrays(data)
        counts = data["point_counts"]
        if len(counts) != len(slam.graph) or int(counts.sum()) != len(data["points"]):
            raise ValueError(f"{path}: expected scans for {len(slam.graph)} nodes, found {len(counts)} ({int(counts.sum())} points)")
        slam.node_points = np.split(np.asarray(data["points"], dtype=np.float64), np.cumsum(counts)[:-1])
        slam.node_odom = [tuple(map(float, q)) for q in data["node_odom"]]  # type: ignore[misc]
        slam.closures = [tuple(c) for c in meta.get("closures", [])]  # type: ignore[misc]
        if len(slam.graph):
            slam.start_pose = tuple(float(v) for v in slam.graph.poses[0])
        return slam

    def continue_from(self, pose: tuple[float, float, float]) -> None:
        """After :meth:`load`: the robot (odometry restarting wherever it is) stands at map pose ``pose``;
        the next scan is matched there and linked into the loaded graph."""
        self._last_odom = None
        self._last_stamp = None
        self._anchor = None
        self._prev_node = None
        self.map_to_odom = (float(pose[0]), float(pose[1]), float(pose[2]))


def _integrate(mapper: Any, x: float, y: float, points: NDArray[np.float64]) -> None:
    from ._kernels import integrate_scan

    integrate_scan(mapper.logodds, x, y, np.ascontiguousarray(points), np.ones(len(points), dtype=np.bool_),
                   mapper.origin[0], mapper.origin[1], mapper.resolution, mapper.l_free, mapper.l_occ, mapper.l_min,
                   mapper.l_max)
    mapper.scans += 1


def _fuse(prior: tuple[float, float, float], prior_cov: NDArray[np.float64], m: Match) -> tuple[float, float, float]:
    """The pose both the odometry prediction and the match support (information-weighted mean): where the
    scan pins the pose (walls all round) the match wins; along a featureless corridor, odometry does."""
    a = np.linalg.inv(prior_cov)
    b = np.linalg.inv(m.covariance + np.diag([1e-8, 1e-8, 1e-9]))
    mp = np.asarray(m.pose)
    d = np.asarray(prior) - mp
    d[2] = wrap(d[2])
    x = mp + np.linalg.solve(a + b, a @ d)
    return float(x[0]), float(x[1]), float(wrap(x[2]))


def _edge_covariance(frame: tuple[float, float, float], cov_map: NDArray[np.float64]) -> NDArray[np.float64]:
    """A map-frame pose covariance expressed in ``frame``'s axes (the edge's measurement frame)."""
    c, s = math.cos(frame[2]), math.sin(frame[2])
    rot = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    return rot @ cov_map @ rot.T

