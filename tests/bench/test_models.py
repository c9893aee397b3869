"""The executor models and their parts behave as the rclpy executors they stand for.

Behaviour only: which callbacks ran, in which order, never how fast.
"""

from __future__ import annotations

import threading

import pytest

from aiorobot.bench._model_single import next_deadline, run_single
from aiorobot.bench._model_threads import MultiThreadedExecutorModel, MutuallyExclusiveGroup, run_threads
from aiorobot.bench._seedconfig import SeedConfig
from aiorobot.bench._workload import cpu_work, sleep_work, work_function

TINY = SeedConfig(periods=3, warmup=1, control_period_sec=0.002, perception_period_sec=0.005, work_sec=0.004)


def test_next_deadline_advances_one_period_when_on_time() -> None:
    assert next_deadline(1.0, 0.5, now=1.1) == 1.5


def test_next_deadline_skips_missed_periods_as_rcl_does() -> None:
    assert next_deadline(1.0, 0.5, now=2.2) == pytest.approx(2.5)  # 1.5 and 2.0 are skipped
    assert next_deadline(1.0, 0.5, now=1.5) == 1.5  # exactly due: not skipped


def test_mutually_exclusive_group_admits_one_callback_at_a_time() -> None:
    group = MutuallyExclusiveGroup()
    assert group.beginning_execution()
    assert not group.can_execute()
    assert not group.beginning_execution()
    group.ending_execution()
    assert group.can_execute()


def test_threads_model_never_overlaps_callbacks_of_one_group() -> None:
    executor = MultiThreadedExecutorModel(num_threads=4)
    group = MutuallyExclusiveGroup()
    running = 0
    overlaps = 0
    calls = 0
    lock = threading.Lock()

    def callback() -> None:
        nonlocal running, overlaps, calls
        with lock:
            running += 1
            overlaps += running > 1
            calls += 1
            done = calls >= 10
        sleep_work(0.002)  # longer than both periods: the pool would overlap them without the group
        with lock:
            running -= 1
        if done:
            executor.request_stop()

    executor.create_timer(0.001, callback, group)
    executor.create_timer(0.001, callback, group)
    executor.spin()
    assert calls >= 10
    assert overlaps == 0


@pytest.mark.parametrize("runner", [run_single, run_threads], ids=["single", "threads"])
@pytest.mark.parametrize("kind", ["sleep", "cpu"])
def test_models_record_every_control_callback_asked_for(runner, kind: str) -> None:
    stamps = runner(kind, TINY)
    assert len(stamps) >= TINY.stamps_needed
    assert stamps == sorted(stamps)


def test_work_function_maps_each_kind_and_rejects_others() -> None:
    assert work_function("sleep") is sleep_work
    assert work_function("cpu") is cpu_work
    with pytest.raises(ValueError, match=r"one of \('sleep', 'cpu'\), received 'gpu'"):
        work_function("gpu")


def test_seed_config_rejects_zero_periods() -> None:
    with pytest.raises(ValueError, match="periods must be >= 1, received 0"):
        SeedConfig(periods=0)
