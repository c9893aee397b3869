"""The behaviour tree engine against BehaviorTree.CPP's and Nav2's control semantics, on small trees
whose leaves answer from a script (no runtime: the tree is plain Python on the loop that ticks it)."""

from __future__ import annotations

import asyncio

import pytest

from aiorobot.nav._bt import AsyncAction, NodeRegistry, Status, TreeError, TreeNode, load_tree
from aiorobot.nav._bt_nav2 import DEFAULT_TREE, nav2_registry

S, F, R = Status.SUCCESS, Status.FAILURE, Status.RUNNING


class Scripted(TreeNode):
    """Answers the statuses in its ``script`` port ("S,R,F": one a tick, the last repeating); logs ticks and halts."""

    log: list[str] = []

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.script = [Status[{"S": "SUCCESS", "F": "FAILURE", "R": "RUNNING"}[c]] for c in self.ports["script"].split(",")]
        self.ticks = 0

    def _tick(self) -> Status:
        Scripted.log.append(f"tick {self.name}")
        out = self.script[min(self.ticks, len(self.script) - 1)]
        self.ticks += 1
        return out

    def _halt(self) -> None:
        Scripted.log.append(f"halt {self.name}")


class Blackboarded(TreeNode):
    def _tick(self) -> Status:
        self.set_output("out", self.get_input("value", float) * 2)
        return Status.SUCCESS


class Sleeper(AsyncAction):
    started = 0
    cancelled = 0

    async def run(self) -> bool:
        Sleeper.started += 1
        try:
            await asyncio.sleep(self.get_input("sec", float))
        except asyncio.CancelledError:
            Sleeper.cancelled += 1
            raise
        return self.get_input("ok", bool, True)


REG = NodeRegistry(Scripted=Scripted, Blackboarded=Blackboarded, Sleeper=Sleeper)


def _tree(body: str, now=lambda: 0.0):
    Scripted.log = []
    return load_tree(f'<root BTCPP_format="4"><BehaviorTree ID="T">{body}</BehaviorTree></root>', REG, now=now)


def _ticks(tree, n: int) -> list[Status]:
    return [tree.tick() for _ in range(n)]


def test_sequence_resumes_at_the_running_child_and_reactive_sequence_starts_over() -> None:
    t = _tree('<Sequence><Scripted name="a" script="S"/><Scripted name="b" script="R,S"/></Sequence>')
    assert _ticks(t, 2) == [R, S]
    assert Scripted.log == ["tick a", "tick b", "tick b"]  # a is not ticked again while b runs
    t = _tree('<ReactiveSequence><Scripted name="a" script="S,S,F"/><Scripted name="b" script="R"/></ReactiveSequence>')
    assert _ticks(t, 3) == [R, R, F]
    assert Scripted.log == ["tick a", "tick b", "tick a", "tick b", "tick a", "halt b"]  # a failing halts the running b


def test_fallback_tries_the_next_child_and_reactive_fallback_halts_a_running_later_one() -> None:
    t = _tree('<Fallback><Scripted name="a" script="F"/><Scripted name="b" script="S"/></Fallback>')
    assert t.tick() is S
    t = _tree('<ReactiveFallback><Scripted name="goal_updated" script="F,S"/><Scripted name="recover" script="R"/></ReactiveFallback>')
    assert _ticks(t, 2) == [R, S]
    assert Scripted.log[-2:] == ["tick goal_updated", "halt recover"]


def test_pipeline_sequence_reticks_the_children_before_the_running_one() -> None:
    t = _tree('<PipelineSequence><Scripted name="plan" script="S,R,S"/><Scripted name="follow" script="R,R,R,S"/></PipelineSequence>')
    assert _ticks(t, 4) == [R, R, R, S]
    # the planner runs again (R) while the follower keeps running: both are ticked every time
    assert Scripted.log == ["tick plan", "tick follow"] * 4  # then both done: nothing running to halt


def test_round_robin_moves_on_each_time_and_fails_when_all_fail() -> None:
    t = _tree('<RoundRobin><Scripted name="a" script="S"/><Scripted name="b" script="F"/><Scripted name="c" script="S"/></RoundRobin>')
    assert _ticks(t, 3) == [S, S, S]
    assert [e for e in Scripted.log if e.startswith("tick")] == ["tick a", "tick b", "tick c", "tick a"]
    t = _tree('<RoundRobin><Scripted name="a" script="F"/><Scripted name="b" script="F"/></RoundRobin>')
    assert t.tick() is F


def test_recovery_node_retries_after_the_recovery_up_to_the_limit() -> None:
    t = _tree('<RecoveryNode number_of_retries="2"><Scripted name="nav" script="F"/><Scripted name="fix" script="S"/></RecoveryNode>')
    assert t.tick() is F
    assert [e for e in Scripted.log if e.startswith("tick")] == ["tick nav", "tick fix", "tick nav", "tick fix", "tick nav"]
    t = _tree('<RecoveryNode number_of_retries="5"><Scripted name="nav" script="F,S"/><Scripted name="fix" script="R,S"/></RecoveryNode>')
    assert _ticks(t, 2) == [R, S]  # the recovery running holds the node; then navigation succeeds
    t = _tree('<RecoveryNode><Scripted name="nav" script="F"/><Scripted name="fix" script="F"/></RecoveryNode>')
    assert t.tick() is F and Scripted.log.count("tick fix") == 1  # a failed recovery ends it


def test_rate_controller_ticks_its_child_at_most_hz_on_the_trees_clock() -> None:
    clock = [0.0]
    t = _tree('<RateController hz="1.0"><Scripted name="plan" script="S"/></RateController>', now=lambda: clock[0])
    for step in range(30):  # 3 s at 10 Hz
        clock[0] = step * 0.1
        assert t.tick() is S
    assert Scripted.log.count("tick plan") == 3


def test_ports_read_literals_and_blackboard_entries_and_write_outputs() -> None:
    t = _tree('<Sequence><Blackboarded value="1.5" out="{x}"/><Blackboarded value="{x}" out="{y}"/></Sequence>')
    assert t.tick() is S and (t.blackboard["x"], t.blackboard["y"]) == (3.0, 6.0)
    t = _tree('<Blackboarded value="{missing}" out="{y}"/>')
    with pytest.raises(TreeError, match=r"port 'value' reads blackboard entry 'missing', which nothing has written"):
        t.tick()


async def test_an_async_action_runs_while_ticked_and_a_halt_cancels_it() -> None:
    Sleeper.started = Sleeper.cancelled = 0
    t = _tree('<Sleeper sec="0.01"/>')
    statuses = []
    while not statuses or statuses[-1] is R:
        statuses.append(t.tick())
        await asyncio.sleep(0.005)
    assert statuses[0] is R and statuses[-1] is S and Sleeper.started == 1
    t = _tree('<ReactiveSequence><Scripted name="ok" script="S,F"/><Sleeper sec="60"/></ReactiveSequence>')
    assert t.tick() is R
    await asyncio.sleep(0)
    assert t.tick() is F
    await asyncio.sleep(0)
    assert Sleeper.cancelled == 1


def test_bad_trees_are_one_clear_error() -> None:
    with pytest.raises(TreeError, match=r"^<string>: unknown node <Sequense> in tree 'T'; did you mean <Sequence>\?"):
        _tree("<Sequense/>")
    with pytest.raises(TreeError, match=r"RecoveryNode 'RecoveryNode': expected exactly 2 children, found 1"):
        _tree('<RecoveryNode><Scripted script="S"/></RecoveryNode>')
    with pytest.raises(TreeError, match=r"not valid XML"):
        load_tree("<root><BehaviorTree", REG, now=lambda: 0.0)
    with pytest.raises(TreeError, match=r"main_tree_to_execute 'B' is not among the trees \['A'\]"):
        load_tree('<root main_tree_to_execute="B"><BehaviorTree ID="A"><Scripted script="S"/></BehaviorTree></root>',
                  REG, now=lambda: 0.0)


def test_the_default_tree_builds_with_nav2s_node_library() -> None:
    tree = load_tree(DEFAULT_TREE, nav2_registry(server=None), now=lambda: 0.0)
    names = {type(n).__name__ for n in tree.nodes()}
    assert tree.id == "NavigateToPoseWReplanningAndRecovery"
    assert {"RecoveryNode", "PipelineSequence", "RateController", "ComputePathToPose", "FollowPath", "RoundRobin",
            "Spin", "Wait", "BackUp", "ClearEntireCostmap", "GoalUpdated"} <= names


def test_a_round_robin_under_a_reactive_fallback_takes_the_next_recovery_each_round() -> None:
    # Nav2's recovery subtree: each failed navigation attempt gets the next recovery action in turn
    t = _tree('<RecoveryNode number_of_retries="3"><Scripted name="nav" script="F"/>'
              '<ReactiveFallback><Scripted name="goal_updated" script="F"/>'
              '<RoundRobin><Scripted name="clear" script="S"/><Scripted name="spin" script="S"/>'
              '<Scripted name="wait" script="S"/></RoundRobin></ReactiveFallback></RecoveryNode>')
    assert t.tick() is F
    assert [e[5:] for e in Scripted.log if e.startswith("tick") and e != "tick goal_updated"] == [
        "nav", "clear", "nav", "spin", "nav", "wait", "nav"]
