"""The frame ring on its own: slots, in-place reads from another process, unlink on close."""

from __future__ import annotations

import multiprocessing
import os

import numpy as np
import pytest

from aiorobot.perception import FrameRing, RingAttachment


def in_dev_shm(name: str) -> bool:
    return name in os.listdir("/dev/shm")


def test_slots_are_handed_out_once_and_come_back():
    with FrameRing(3, 1024) as ring:
        taken = [ring.acquire() for _ in range(3)]
        assert sorted(taken) == [0, 1, 2] and ring.acquire() is None
        ring.release(taken[1])
        assert ring.acquire() == taken[1]
        with pytest.raises(ValueError, match=r"^slot 7 of <FrameRing psm_\w+ slots=3 slot_bytes=1024 busy=3> is not in use$"):
            ring.release(7)


def test_a_reader_sees_the_written_frame_in_place_and_close_unlinks():
    ring = FrameRing(2, 640 * 480 * 3)
    assert in_dev_shm(ring.name)
    frame = np.random.default_rng(1).integers(0, 255, (480, 640, 3), dtype=np.uint8)
    slot = ring.acquire()
    shape, dtype = ring.write(slot, frame)
    reader = RingAttachment(ring.name, ring.slot_bytes)
    view = reader.view(slot, shape, dtype)
    assert np.array_equal(view, frame) and not view.flags.writeable
    ring.write(slot, frame[::-1])  # same memory: the reader sees the new frame without a copy
    assert np.array_equal(view, frame[::-1])
    del view
    reader.close()
    ring.close()
    ring.close()
    assert not in_dev_shm(ring.name)
    with pytest.raises(RuntimeError, match="is closed"):
        ring.acquire()


def test_a_frame_larger_than_a_slot_is_refused():
    with FrameRing(1, 100) as ring:
        with pytest.raises(ValueError, match=r"^a frame of 101 bytes does not fit <FrameRing"):
            ring.write(ring.acquire(), np.zeros(101, np.uint8))


def _read_sum(name, slot_bytes, slot, shape, dtype, queue):
    reader = RingAttachment(name, slot_bytes)
    view = reader.view(slot, shape, dtype)
    queue.put(int(view.sum(dtype=np.int64)))
    del view
    reader.close()


def test_another_process_reads_the_slot():
    ctx = multiprocessing.get_context("forkserver")
    with FrameRing(2, 4096) as ring:
        slot = ring.acquire()
        shape, dtype = ring.write(slot, np.arange(1000, dtype=np.int32))
        queue = ctx.Queue()
        process = ctx.Process(target=_read_sum, args=(ring.name, ring.slot_bytes, slot, shape, dtype, queue))
        process.start()
        assert queue.get(timeout=30) == sum(range(1000))
        process.join()
        queue.close()
        queue.join_thread()


@pytest.mark.parametrize("slots, slot_bytes", [(0, 10), (1, 0)])
def test_ring_sizes_are_checked(slots, slot_bytes):
    with pytest.raises(ValueError, match=rf"^a FrameRing needs slots >= 1 and slot_bytes >= 1, got slots={slots}, "
                                         rf"slot_bytes={slot_bytes}$"):
        FrameRing(slots, slot_bytes)
