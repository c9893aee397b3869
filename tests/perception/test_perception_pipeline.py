"""Pipelines in worker processes: results as messages, back-pressure, bad input, killed workers, no /dev/shm leak."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

from aiorobot import Node, Runtime
from aiorobot.msgs.sensor_msgs import Image
from aiorobot.msgs.std_msgs import String
from aiorobot.perception import Pipeline
from _perception_helpers import wait_until

import _perception_kernels as kernels


def in_dev_shm(name: str | None) -> bool:
    """Whether this segment exists (other processes on the machine have their own; only ours matter)."""
    assert name is not None
    return name in os.listdir("/dev/shm")


def image(value: int = 7, width: int = 640, height: int = 480, frame_id: str = "camera_optical_frame") -> Image:
    msg = Image(height=height, width=width, encoding="rgb8", step=width * 3,
                data=np.full(height * width * 3, value, np.uint8))
    msg.header.frame_id = frame_id
    return msg


class Camera(Node):
    def __init__(self) -> None:
        super().__init__("camera")
        self.pub = self.create_publisher(Image, "/image", 10)
        self.results: list[str] = []
        self.create_subscription(String, "/out", lambda m: self.results.append(m.data), 100)


async def test_results_come_back_as_messages_from_the_workers_and_shm_is_clean_after():
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.mean_and_pid, publish=("/out", String), workers=2)
        await pipeline.start()
        assert in_dev_shm(pipeline.ring_name)
        pids = pipeline.worker_pids()
        assert len(pids) == 2 and os.getpid() not in pids
        for value in (10, 20, 30):
            camera.pub.publish(image(value))
            await wait_until(lambda: len(camera.results) == value // 10)
        pid, mean, *rest = camera.results[0].split(" ")
        assert int(pid) in pids and mean == "10.000" and " ".join(rest) == "(480, 640, 3) camera_optical_frame"
        stats = pipeline.statistics()
        assert (stats.received, stats.processed, stats.published, stats.in_flight) == (3, 3, 3, 0)
        assert set(stats.latency) >= {"handoff", "to_worker", "kernel", "from_worker", "total"}
        assert stats.latency["total"].count == 3 and stats.latency["total"].p50_ms > 0
    assert not in_dev_shm(pipeline.ring_name)


async def test_a_worker_killed_mid_frame_frees_its_slot_and_is_restarted():
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.hang_on_marker, publish=("/out", String), workers=1)
        await pipeline.start()
        slots = pipeline.free_slots
        camera.pub.publish(image(255))  # the worker blocks on this frame
        await wait_until(lambda: pipeline.statistics().in_flight == 1)
        (victim,) = pipeline.worker_pids()
        os.kill(victim, signal.SIGKILL)
        await wait_until(lambda: pipeline.statistics().worker_restarts == 1)
        assert pipeline.free_slots == slots
        assert pipeline.worker_pids() != [victim]
        camera.pub.publish(image(5))  # the restarted worker serves the next frame
        await wait_until(lambda: camera.results == ["5"])
        stats = pipeline.statistics()
        assert (stats.failed, stats.worker_restarts, stats.processed) == (1, 1, 1)
    assert not in_dev_shm(pipeline.ring_name)


async def test_runtime_shutdown_with_a_worker_stuck_mid_frame_leaves_nothing_in_dev_shm():
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.hang_on_marker, publish=("/out", String))
        camera.pub.publish(image(255))  # starts the pipeline lazily; the worker never finishes
        await wait_until(lambda: pipeline.statistics().in_flight == 1)
        pids = pipeline.worker_pids()
    assert not in_dev_shm(pipeline.ring_name)
    for pid in pids:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


async def test_bad_frames_are_dropped_counted_and_warned_about_once(caplog):
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.strict, publish=("/out", String))
        await pipeline.start()
        bad = [image(2)] * 4
        bad[0].step = 100  # step shorter than a row
        bad[1] = Image(height=0, width=0, encoding="rgb8", step=0)  # empty
        bad[2] = image(2)
        bad[2].encoding = "yuv422_wat"
        bad[3] = image(2)
        bad[3].height = 479  # size disagrees with data
        for msg in bad:
            camera.pub.publish(msg)
        await wait_until(lambda: pipeline.statistics().dropped_bad_input == 4)
        for n, value in enumerate((3, 13, 99, 0, 4)):  # kernel: bad input, raises, dies, nothing, a result
            camera.pub.publish(image(value))
            await wait_until(lambda: pipeline.statistics().received == 5 + n and pipeline.statistics().in_flight == 0)
        await wait_until(lambda: camera.results == ["4"])
        stats = pipeline.statistics()
        assert stats.dropped_bad_input == 5
        assert stats.failed == 2 and stats.worker_restarts == 1
        assert stats.processed == 2 and stats.published == 1
    drops = [r.getMessage() for r in caplog.records if "dropped a frame" in r.getMessage()]
    assert drops == ["pipeline /image: dropped a frame: image step 100 is shorter than width*channels = "
                     "640*3 = 1920 for encoding 'rgb8' (1 dropped so far)"]  # throttled
    assert any("exited with code 3" in r.getMessage() for r in caplog.records)
    assert any("unlucky frame" in r.getMessage() for r in caplog.records)


async def test_a_result_of_the_wrong_type_is_counted_as_failed(caplog):
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.wrong_type, publish=("/out", String))
        camera.pub.publish(image(1))
        await wait_until(lambda: pipeline.statistics().failed == 1)
        assert pipeline.statistics().published == 0


@pytest.mark.parametrize("policy, expected", [("latest", ["0", "4"]), ("drop_oldest", ["0", "3", "4"])])
async def test_back_pressure_policies(tmp_path, policy, expected):
    gate = tmp_path / "open"
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        camera = rt.add_node(Camera())
        pipeline = Pipeline(node, "/image", Image, kernels.gated, publish=("/out", String), workers=1, queue=2,
                            policy=policy, context=lambda: str(gate))
        await pipeline.start()
        for value in range(5):  # frame 0 holds the worker; 1..4 arrive while it is busy
            camera.pub.publish(image(value, 64, 48))
            await wait_until(lambda: pipeline.statistics().received == value + 1)
        gate.touch()
        await wait_until(lambda: len(camera.results) == len(expected))
        await wait_until(lambda: pipeline.statistics().in_flight == 0)
        assert camera.results == expected
        assert pipeline.statistics().dropped_queue == 5 - len(expected)


@pytest.mark.parametrize("kw, message", [
    (dict(workers=0), r"^workers: expected an integer >= 1, got 0$"),
    (dict(queue=0), r"^queue: expected an integer >= 1, got 0$"),
    (dict(policy="newest"), r"^policy: expected one of 'latest', 'drop_oldest', got 'newest'$"),
])
async def test_bad_settings_are_refused(kw, message):
    with pytest.raises(ValueError, match=message):
        Pipeline(Node("vision"), "/image", Image, kernels.first_pixel, **kw)


async def test_a_worker_that_cannot_start_is_not_restarted_in_a_loop(caplog):
    async with Runtime() as rt:
        node = rt.add_node(Node("vision"))
        pipeline = Pipeline(node, "/image", Image, kernels.Unimportable(), publish=("/out", String))
        await pipeline.start()
        await wait_until(lambda: any("not restarting it" in r.getMessage() for r in caplog.records))
        assert pipeline.statistics().worker_restarts == 2 and pipeline.worker_pids() == []
    assert not in_dev_shm(pipeline.ring_name)
