"""A recorder killed with SIGKILL leaves a bag whose completed chunks `reindex` recovers."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from aiorobot.bag import BagError, BagReader, reindex

CHILD = textwrap.dedent(
    """
    import sys
    import numpy as np
    import aiorobot
    from aiorobot import Node, Runtime
    from aiorobot.bag import Recorder
    from aiorobot.msgs.std_msgs import UInt8MultiArray, UInt32

    class Source(Node):
        def __init__(self):
            super().__init__("source")
            self.rng = np.random.default_rng(1)
            self.i = 0
            self.seq = self.create_publisher(UInt32, "/seq", 1000)
            self.blob = self.create_publisher(UInt8MultiArray, "/blob", 1000)
            self.create_timer(0.001, self.tick)

        def tick(self):
            for _ in range(20):
                self.seq.publish(UInt32(data=self.i))
                self.blob.publish(UInt8MultiArray(data=self.rng.integers(0, 256, 512, dtype=np.uint8)))
                self.i += 1

    async def main():
        async with Runtime(handle_signals=False) as rt:
            rt.add_node(Recorder(path=sys.argv[1], max_cache_size=16 * 1024))
            rt.add_node(Source())
            await rt.spin()

    aiorobot.run(main())
    """
)


def test_sigkill_during_recording_leaves_a_readable_prefix_after_reindex(tmp_path: Path) -> None:
    bag = tmp_path / "killed"
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(bag)], stderr=subprocess.PIPE)
    try:
        mcap = bag / "killed_0.mcap"
        deadline = time.monotonic() + 45
        while not (mcap.exists() and mcap.stat().st_size > 200_000):  # several 16 KiB chunks on disk
            assert child.poll() is None, child.stderr.read().decode() if child.stderr else ""
            assert time.monotonic() < deadline, "the recorder wrote nothing within 45 s"
            time.sleep(0.05)
        os.kill(child.pid, signal.SIGKILL)
        child.wait(10)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
        if child.stderr:
            child.stderr.close()
    with pytest.raises(BagError, match=r"aiorobot bag reindex"):
        BagReader(bag)
    result = reindex(bag)
    assert result.damaged == 1 and result.messages > 0
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    values = []
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        conns = [c for c in reader.connections if c.topic == "/seq"]
        for conn, _, raw in reader.messages(connections=conns):
            values.append(reader.deserialize(raw, conn.msgtype).data)
    assert len(values) > 100
    assert values == list(range(len(values)))  # a prefix, in order, nothing in between missing
    with BagReader(bag) as reader:
        assert reader.message_count == result.messages
