"""The pure sync policies, without a runtime.

The approximate-time scenarios are those of ROS 2 message_filters'
``test/test_approximate_time_policy.cpp`` (the reference algorithm's expected
outputs); items here are the stamps themselves, in seconds as nanoseconds.
"""

import itertools

import numpy as np
import pytest

from aiorobot.message_filters import ApproximateTimePolicy, ExactTimePolicy

S = 1_000_000_000  # one second in nanoseconds


def run_policy(policy, inputs):
    """Feed ``(stamp_sec, input_index)`` pairs; return the output sets as stamps in seconds."""
    out = []
    for stamp_sec, index in inputs:
        stamp = round(stamp_sec * S)
        for group in policy.add(index, stamp, stamp):
            out.append(tuple(s / S for s in group))
    return out


# -- ExactTimePolicy ---------------------------------------------------------------


def test_exact_outputs_sets_with_equal_stamps_in_input_order():
    policy = ExactTimePolicy(2, 10)
    out = run_policy(policy, [(1, 0), (1, 1), (2, 1), (2, 0)])
    assert out == [(1, 1), (2, 2)]


def test_exact_drops_older_incomplete_sets_once_a_newer_set_completes():
    policy = ExactTimePolicy(2, 10)
    out = run_policy(policy, [(1, 0), (2, 0), (3, 0), (3, 1), (2, 1)])
    assert out == [(3, 3)]
    assert policy.dropped_sets == 2  # stamps 1 and 2 of input 0


def test_exact_queue_size_drops_the_oldest_pending_sets():
    policy = ExactTimePolicy(2, 2)
    out = run_policy(policy, [(1, 0), (2, 0), (3, 0), (1, 1), (2, 1)])
    # 1 of input 0 goes when 3 arrives; the late 1 of input 1 is then the oldest and goes too.
    assert out == [(2, 2)]
    assert policy.dropped_sets == 2 and policy.pending == 1


def test_exact_three_inputs_wait_for_all_three():
    policy = ExactTimePolicy(3, 10)
    assert run_policy(policy, [(5, 0), (5, 2)]) == []
    assert run_policy(policy, [(5, 1)]) == [(5, 5, 5)]


def test_exact_each_item_is_used_once():
    policy = ExactTimePolicy(2, 10)
    assert run_policy(policy, [(1, 0), (1, 1), (1, 1)]) == [(1, 1)]


def test_exact_rejects_fewer_than_two_inputs():
    with pytest.raises(ValueError, match=r"^a synchronizer needs two or more inputs, got 1$"):
        ExactTimePolicy(1, 10)


# -- ApproximateTimePolicy: the upstream scenarios -------------------------------


def test_approximate_exact_match():
    # A: a..b..c   B: A..B..C
    inputs = [(0, 0), (0, 1), (3, 0), (3, 1), (6, 0), (6, 1)]
    assert run_policy(ApproximateTimePolicy(2, 10), inputs) == [(0, 0), (3, 3), (6, 6)]


def test_approximate_perfect_match():
    # A: a..b..c.   B: .A..B..C   -> the last pair waits for a newer message
    inputs = [(0, 0), (1, 1), (3, 0), (4, 1), (6, 0), (7, 1)]
    assert run_policy(ApproximateTimePolicy(2, 10), inputs) == [(0, 1), (3, 4)]


def test_approximate_imperfect_match():
    # A: a.xb..c.   B: .A...B.C
    inputs = [(0, 0), (1, 1), (2, 0), (3, 0), (5, 1), (6, 0), (7, 1)]
    assert run_policy(ApproximateTimePolicy(2, 10), inputs) == [(0, 1), (6, 5)]


def test_approximate_acceleration():
    inputs = [(0, 0), (7, 1), (12, 0), (15, 1), (17, 0), (18, 1)]
    assert run_policy(ApproximateTimePolicy(2, 10), inputs) == [(12, 7), (17, 18)]


DROPPED_INPUTS = [(0, 0), (1, 1), (3, 1), (4, 0), (7, 1), (8, 0), (10, 0), (11, 1), (13, 0), (14, 1)]


def test_approximate_queue_size_one_drops_messages():
    assert run_policy(ApproximateTimePolicy(2, 1), DROPPED_INPUTS) == [(4, 3), (10, 11)]


def test_approximate_queue_size_two_is_just_enough():
    assert run_policy(ApproximateTimePolicy(2, 2), DROPPED_INPUTS) == [(0, 1), (4, 3), (8, 7), (10, 11)]


def test_approximate_long_queue():
    inputs = [(t, 0) for t in range(9)] + [(3, 1), (9, 0), (10, 0), (11, 0), (12, 0), (10, 1), (13, 0)]
    assert run_policy(ApproximateTimePolicy(2, 5), inputs) == [(10, 10)]


def test_approximate_double_publish():
    inputs = [(0, 0), (1, 1), (3, 1), (3, 0)]
    assert run_policy(ApproximateTimePolicy(2, 10), inputs) == [(0, 1), (3, 3)]


def test_approximate_four_inputs():
    inputs = [
        (0, 0), (1, 1), (2, 2), (3, 3), (5, 0), (5, 3), (6, 1), (6, 2),
        (8, 0), (9, 1), (10, 2), (11, 3), (10, 0), (13, 0), (14, 1),
    ]  # fmt: skip
    out = run_policy(ApproximateTimePolicy(4, 10), inputs)
    assert out == [(0, 1, 2, 3), (5, 6, 6, 5), (10, 9, 10, 11)]


def test_approximate_early_publish():
    inputs = [(0, 0), (1, 1), (2, 2), (3, 3), (7, 0)]
    assert run_policy(ApproximateTimePolicy(4, 10), inputs) == [(0, 1, 2, 3)]


def test_approximate_rate_bound_lets_sets_out_earlier():
    inputs = [(0, 0), (1, 1), (3, 0), (4, 1), (6, 0), (7, 1)]
    bounded = ApproximateTimePolicy(2, 10, inter_message_lower_bounds_ns=[int(1.5 * S), 0])
    assert run_policy(bounded, inputs) == [(0, 1), (3, 4)]
    tighter = ApproximateTimePolicy(2, 10)
    tighter.set_inter_message_lower_bound(0, 2 * S)
    assert run_policy(tighter, inputs) == [(0, 1), (3, 4), (6, 7)]


# -- ApproximateTimePolicy: slop, single use, overflow ------------------------------


def test_approximate_never_outputs_a_set_wider_than_the_slop():
    # B is always 0.4 s after A: nothing pairs within 0.3 s, everything within 0.5 s.
    inputs = [x for k in range(10) for x in ((k, 0), (k + 0.4, 1))]
    assert run_policy(ApproximateTimePolicy(2, 10, max_interval_ns=int(0.3 * S)), inputs) == []
    wide = run_policy(ApproximateTimePolicy(2, 10, max_interval_ns=int(0.5 * S)), inputs)
    assert wide == [(k, k + 0.4) for k in range(9)]


def test_approximate_queue_overflow_drops_the_oldest_item():
    policy = ApproximateTimePolicy(2, 3)
    assert run_policy(policy, [(t, 0) for t in range(5)]) == []
    assert policy.queued(0) == 3 and policy.dropped == 2
    # The survivors are 2, 3, 4: a B message at 0 can no longer pair with A at 0.
    assert run_policy(policy, [(0, 1), (2.1, 1)]) == [(2, 2.1)]


def jittered_streams(rng, n_inputs, count, period_sec, jitter_sec):
    """Each input publishes once per period with uniform stamp jitter; arrival interleaved by stamp."""
    events = []
    for index in range(n_inputs):
        for k in range(count):
            stamp = k * period_sec + rng.uniform(-jitter_sec, jitter_sec)
            events.append((stamp, index, k))
    events.sort()
    return events


@pytest.mark.parametrize("n_inputs", [2, 3])
def test_approximate_pairs_jittered_streams_by_period(n_inputs):
    rng = np.random.default_rng(7)
    events = jittered_streams(rng, n_inputs, count=200, period_sec=0.1, jitter_sec=0.01)
    policy = ApproximateTimePolicy(n_inputs, 10, max_interval_ns=int(0.05 * S))
    sets = []
    for stamp, index, k in events:
        sets.extend(policy.add(index, round(stamp * S), (k, stamp)))
    # Every set joins the messages of one period, each period once, in order; only
    # the last period may wait for a newer message to prove its set optimal.
    periods = [tuple(k for k, _ in s) for s in sets]
    assert all(len(set(p)) == 1 for p in periods)
    assert [p[0] for p in periods] == list(range(len(periods)))
    assert len(periods) >= 199


def test_approximate_uses_each_message_at_most_once_within_the_slop():
    rng = np.random.default_rng(11)
    policy = ApproximateTimePolicy(3, 5, max_interval_ns=int(0.02 * S))
    seen = set()
    uid = itertools.count()
    t = 0.0
    for _ in range(3000):
        t += float(rng.uniform(0, 0.01))
        index = int(rng.integers(3))  # random rates per input, a little out of order
        stamp = round((t + float(rng.uniform(-0.005, 0.005))) * S)
        for s in policy.add(index, stamp, (next(uid), index, stamp)):
            ids = [m[0] for m in s]
            assert not seen.intersection(ids)
            seen.update(ids)
            assert [m[1] for m in s] == [0, 1, 2]
            stamps = [m[2] for m in s]
            assert max(stamps) - min(stamps) <= int(0.2 * S)
            last_span_start = min(stamps)
    assert seen and last_span_start >= 0


def test_approximate_rejects_bad_arguments():
    with pytest.raises(ValueError, match=r"^queue_size: expected an int >= 1, got 0$"):
        ApproximateTimePolicy(2, 0)
    with pytest.raises(ValueError, match=r"two or more inputs"):
        ApproximateTimePolicy(1, 3)
    with pytest.raises(IndexError, match=r"^input index: expected 0\.\.1, got 2$"):
        ApproximateTimePolicy(2, 3).add(2, 0, None)
