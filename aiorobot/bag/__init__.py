"""Recording and replay: rosbag2 directories with MCAP storage (``aiorobot bag``).

- :class:`Recorder` — a node that records topics of the running graph, losing nothing (or, in
  snapshot mode, keeps the last seconds in a :class:`SnapshotBuffer` and writes them on demand);
- :class:`Player` — a node that plays a bag back, paced, optionally publishing ``/clock``;
- :class:`BagWriter` / :class:`BagReader` — the files themselves (rosbags reads what we write);
- :func:`reindex` — rebuilds a bag whose recorder was killed (``aiorobot bag reindex``);
- :func:`convert` — ``ros2 bag convert``: merge, split, filter, change storage, compress;
- :func:`sweep` — the same replay for several parameter variants in worker processes, with figures;
- :func:`check_bag` — replays a bag's inputs into nodes in lock-step on sim time and compares
  their outputs with the recording, field by field (``aiorobot bag check``, the ``bag_replay`` fixture).
"""

from __future__ import annotations

from ._check import CheckResult, check_bag
from ._convert import ConvertResult, OutputBag, convert, read_output_options
from ._diff import DiffReport, FieldDifference, TopicDiff, parse_tolerance
from ._metadata import BagError, TopicInfo
from ._player import Player, PlayerStatistics
from ._reader import BagReader
from ._recorder import Recorder, RecorderStatistics
from ._reindex import reindex
from ._sweep import TopicFigures, VariantResult, odometry_rmse, sweep, topic_figures, variants_from_params
from ._snapshot import SnapshotBuffer, SnapshotBufferStatistics
from ._replay import ReplayResult
from ._writer import BagWriter

__all__ = [
    "BagError",
    "BagReader",
    "BagWriter",
    "CheckResult",
    "ConvertResult",
    "DiffReport",
    "FieldDifference",
    "OutputBag",
    "Player",
    "PlayerStatistics",
    "Recorder",
    "RecorderStatistics",
    "ReplayResult",
    "SnapshotBuffer",
    "SnapshotBufferStatistics",
    "TopicDiff",
    "TopicFigures",
    "TopicInfo",
    "VariantResult",
    "check_bag",
    "convert",
    "odometry_rmse",
    "parse_tolerance",
    "read_output_options",
    "reindex",
    "sweep",
    "topic_figures",
    "variants_from_params",
]
