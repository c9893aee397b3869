"""Recording and replay: rosbag2 directories with MCAP storage (``aiorobot bag``).

- :class:`Recorder` — a node that records topics of the running graph, losing nothing;
- :class:`Player` — a node that plays a bag back, paced, optionally publishing ``/clock``;
- :class:`BagWriter` / :class:`BagReader` — the files themselves (rosbags reads what we write);
- :func:`reindex` — rebuilds a bag whose recorder was killed (``aiorobot bag reindex``).
"""

from __future__ import annotations

from ._metadata import BagError, TopicInfo
from ._player import Player, PlayerStatistics
from ._reader import BagReader
from ._recorder import Recorder, RecorderStatistics
from ._reindex import reindex
from ._writer import BagWriter

__all__ = [
    "BagError",
    "BagReader",
    "BagWriter",
    "Player",
    "PlayerStatistics",
    "Recorder",
    "RecorderStatistics",
    "TopicInfo",
    "reindex",
]
