"""A small asyncio-native behaviour tree that reads BehaviorTree.CPP's XML (the format Nav2's trees use).

A tree is ticked (:meth:`Tree.tick`) from a coroutine, every ``bt_loop_duration`` in Nav2; each tick
walks it from the root and returns ``RUNNING``, ``SUCCESS`` or ``FAILURE``. A leaf that takes time
(:class:`AsyncAction`) starts a task on its first tick and answers ``RUNNING`` until the task ends;
halting it (a reactive parent moving on, a sequence failing, the tree stopping) cancels the task. No
threads: everything runs on the loop that ticks.

Ports and the blackboard are BehaviorTree.CPP's: an attribute ``path="{path}"`` reads and writes the
blackboard entry ``path``; any other value is a literal, converted to the type the node asks for.

Controls and decorators, with BehaviorTree.CPP v4's and Nav2's semantics:

- ``Sequence`` (resumes at the running child), ``ReactiveSequence`` (re-ticks from the first),
  ``Fallback``, ``ReactiveFallback``;
- Nav2's ``PipelineSequence`` (re-ticks the children before the running one, so a replanning branch
  runs beside the path follower), ``RoundRobin`` (the next child each time; a success returns at
  once), ``RecoveryNode`` (two children: on the first's failure run the second and retry, up to
  ``number_of_retries``);
- ``RateController`` (``hz``: ticks its child at most that often, and each tick while it runs),
  ``Inverter``, ``ForceSuccess``, ``ForceFailure``, ``RetryUntilSuccessful`` (``num_attempts``),
  ``Repeat`` (``num_cycles``).

Leaves come from a registry (:class:`NodeRegistry`): Nav2's library bound to the navigation server is
in :mod:`._bt_nav2`. An unknown element, a missing port or a malformed file is a :class:`TreeError`
naming the file, the element and what was expected. Not supported: subtrees, scripting, ``_skipIf``
style preconditions, the SKIPPED status, and BehaviorTree.CPP's type-safe port declarations
(ports convert on read).
"""

from __future__ import annotations

import asyncio
import difflib
import enum
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Coroutine
from typing import Any

__all__ = ["AsyncAction", "Blackboard", "Condition", "NodeRegistry", "Status", "Tree", "TreeError", "TreeNode", "load_tree"]


class Status(enum.Enum):
    IDLE = "IDLE"
    RUNNING = "RUNNING"
    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"


class TreeError(ValueError):
    """A tree that cannot be built: the file (or ``<string>``), the element and what was expected."""


class Blackboard(dict):  # type: ignore[type-arg]
    """The entries that ports named ``{key}`` read and write."""


class TreeNode:
    """A node: ``ports`` are its XML attributes (``name`` aside), ``children`` its child elements."""

    def __init__(self, name: str, ports: dict[str, str], blackboard: Blackboard, children: list[TreeNode] | None = None) -> None:
        self.name = name
        self.ports = ports
        self.blackboard = blackboard
        self.children = children or []
        self.status = Status.IDLE

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} {self.status.name}>"

    def tick(self) -> Status:
        self.status = self._tick()
        return self.status

    def halt(self) -> None:
        """Stop the node if it runs (its :meth:`_halt`, its per-run state, its running children), then
        make it IDLE: BehaviorTree.CPP's haltNode + resetStatus. A node that is not running only
        becomes IDLE and keeps its state (a RoundRobin remembers whose turn is next)."""
        if self.status is Status.RUNNING:
            self._halt()
            self._finish()
        self.status = Status.IDLE

    def _finish(self) -> None:
        """A control ending a run: halt the running children, reset the others' status, forget per-run state."""
        for child in self.children:
            child.halt()
        self._reset()

    def _tick(self) -> Status:
        raise NotImplementedError

    def _halt(self) -> None:
        """Stop work in progress (a running leaf's task)."""

    def _reset(self) -> None:
        """Forget per-run state (a control's current child, a retry count)."""

    def get_input(self, key: str, kind: Callable[[Any], Any] = str, default: Any = ...) -> Any:
        """The port ``key``: a blackboard entry for ``{entry}``, else the literal converted by ``kind``."""
        raw = self.ports.get(key)
        if raw is None:
            if default is ...:
                raise TreeError(f"{type(self).__name__} {self.name!r}: expected the port {key!r}, found none")
            return default
        if raw.startswith("{") and raw.endswith("}"):
            entry = raw[1:-1]
            if entry not in self.blackboard:
                if default is ...:
                    raise TreeError(f"{type(self).__name__} {self.name!r}: port {key!r} reads blackboard entry "
                                    f"{entry!r}, which nothing has written")
                return default
            return self.blackboard[entry]
        if kind is bool:
            return raw.strip().lower() in ("true", "1")
        return kind(raw)

    def set_output(self, key: str, value: Any) -> None:
        """Write ``value`` to the blackboard entry the port ``key`` names (nothing when the port is absent)."""
        raw = self.ports.get(key)
        if raw is None:
            return
        if not (raw.startswith("{") and raw.endswith("}")):
            raise TreeError(f"{type(self).__name__} {self.name!r}: output port {key!r} must name a blackboard "
                            f"entry as '{{entry}}', found {raw!r}")
        self.blackboard[raw[1:-1]] = value


class Condition(TreeNode):
    """A leaf answering at once: :meth:`check` True -> SUCCESS, False -> FAILURE."""

    def _tick(self) -> Status:
        return Status.SUCCESS if self.check() else Status.FAILURE

    def check(self) -> bool:
        raise NotImplementedError


class AsyncAction(TreeNode):
    """A leaf that takes time: :meth:`run` (a coroutine returning True for success) runs as a task."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._task: asyncio.Task[bool] | None = None

    def _tick(self) -> Status:
        if self._task is None:
            self._task = asyncio.ensure_future(self.run())
        if not self._task.done():
            return Status.RUNNING
        task, self._task = self._task, None
        return Status.SUCCESS if task.result() else Status.FAILURE  # an exception in run() propagates

    def _halt(self) -> None:
        if self._task is not None:
            self._task.cancel()
            self._task = None

    def run(self) -> Coroutine[Any, Any, bool]:
        raise NotImplementedError


# -- controls -------------------------------------------------------------------------------


class Sequence(TreeNode):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.current = 0

    def _tick(self) -> Status:
        while self.current < len(self.children):
            status = self.children[self.current].tick()
            if status is Status.RUNNING:
                return status
            if status is Status.FAILURE:
                self._finish()
                return Status.FAILURE
            self.current += 1
        self._finish()
        return Status.SUCCESS

    def _reset(self) -> None:
        self.current = 0


class Fallback(Sequence):
    def _tick(self) -> Status:
        while self.current < len(self.children):
            status = self.children[self.current].tick()
            if status is Status.RUNNING:
                return status
            if status is Status.SUCCESS:
                self._finish()
                return Status.SUCCESS
            self.current += 1
        self._finish()
        return Status.FAILURE


class ReactiveSequence(TreeNode):
    """Every tick from the first child: a failure ends it, a running child halts those after it."""

    stop_on = Status.FAILURE

    def _tick(self) -> Status:
        for i, child in enumerate(self.children):
            status = child.tick()
            if status is Status.RUNNING:
                for later in self.children[i + 1 :]:
                    later.halt()
                return status
            if status is self.stop_on:
                self._finish()
                return status
        self._finish()
        return Status.SUCCESS if self.stop_on is Status.FAILURE else Status.FAILURE


class ReactiveFallback(ReactiveSequence):
    stop_on = Status.SUCCESS


class PipelineSequence(TreeNode):
    """Nav2's: the children before the furthest running one are re-ticked each time."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.last = 0

    def _tick(self) -> Status:
        for i, child in enumerate(self.children):
            status = child.tick()
            if status is Status.FAILURE:
                self._finish()
                return status
            if status is Status.RUNNING and i >= self.last:
                self.last = i
                return status
        self._finish()
        return Status.SUCCESS

    def _reset(self) -> None:
        self.last = 0


class RoundRobin(TreeNode):
    """Nav2's: tick the current child; move on after it ends; a success returns at once."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.current = 0
        self.failed = 0

    def tick(self) -> Status:
        n = len(self.children)
        while self.failed < n:
            status = self.children[self.current].tick()
            if status is not Status.RUNNING:
                self.current = (self.current + 1) % n
            if status is Status.SUCCESS:
                self.failed = 0
                for child in self.children:
                    child.halt()
                self.status = status
                return status  # its own state kept: the next run starts at the next child
            if status is Status.RUNNING:
                self.status = status
                return status
            self.failed += 1
        self._finish()
        self.status = Status.FAILURE
        return Status.FAILURE

    def _reset(self) -> None:
        self.current = 0
        self.failed = 0


class RecoveryNode(TreeNode):
    """Nav2's: run the first child; on its failure run the second (the recovery) and retry, up to
    ``number_of_retries`` times; the recovery failing fails the node."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if len(self.children) != 2:
            raise TreeError(f"RecoveryNode {self.name!r}: expected exactly 2 children, found {len(self.children)}")
        self.current = 0
        self.retries = 0

    def _tick(self) -> Status:
        limit = self.get_input("number_of_retries", int, 1)
        while self.retries <= limit:
            status = self.children[self.current].tick()
            if status is Status.RUNNING:
                return status
            if self.current == 0:
                if status is Status.SUCCESS:
                    self._finish()
                    return status
                if self.retries >= limit:
                    self._finish()
                    return Status.FAILURE
                self.children[0].halt()
                self.current = 1
            else:
                if status is Status.FAILURE:
                    self._finish()
                    return status
                self.children[1].halt()
                self.retries += 1
                self.current = 0
        self._finish()
        return Status.FAILURE

    def _reset(self) -> None:
        self.current = 0
        self.retries = 0

    @property
    def retry_count(self) -> int:
        return self.retries


# -- decorators ------------------------------------------------------------------------------


class _Decorator(TreeNode):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if len(self.children) != 1:
            raise TreeError(f"{type(self).__name__} {self.name!r}: expected exactly 1 child, found {len(self.children)}")

    @property
    def child(self) -> TreeNode:
        return self.children[0]


class Inverter(_Decorator):
    def _tick(self) -> Status:
        status = self.child.tick()
        return {Status.SUCCESS: Status.FAILURE, Status.FAILURE: Status.SUCCESS}.get(status, status)


class ForceSuccess(_Decorator):
    def _tick(self) -> Status:
        status = self.child.tick()
        return Status.RUNNING if status is Status.RUNNING else Status.SUCCESS


class ForceFailure(_Decorator):
    def _tick(self) -> Status:
        status = self.child.tick()
        return Status.RUNNING if status is Status.RUNNING else Status.FAILURE


class RetryUntilSuccessful(_Decorator):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.attempts = 0

    def _tick(self) -> Status:
        limit = self.get_input("num_attempts", int)
        while self.attempts < limit or limit < 0:
            status = self.child.tick()
            if status is not Status.FAILURE:
                if status is Status.SUCCESS:
                    self._finish()
                return status
            self.attempts += 1
            self.child.halt()
        self._finish()
        return Status.FAILURE

    def _reset(self) -> None:
        self.attempts = 0


class Repeat(RetryUntilSuccessful):
    def _tick(self) -> Status:
        limit = self.get_input("num_cycles", int)
        while self.attempts < limit or limit < 0:
            status = self.child.tick()
            if status is not Status.SUCCESS:
                if status is Status.FAILURE:
                    self._finish()
                return status
            self.attempts += 1
            self.child.halt()
        self._finish()
        return Status.SUCCESS


class RateController(_Decorator):
    """Nav2's: tick the child the first time, each tick while it runs, and again once 1/``hz`` has
    passed since it last succeeded; between those answer the last status. Time is the tree's clock."""

    def __init__(self, *args: Any, now: Callable[[], float], **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.now = now
        self.start = -math.inf

    def _tick(self) -> Status:
        period = 1.0 / self.get_input("hz", float, 10.0)
        if self.status is Status.IDLE:
            self.start = -math.inf
        if self.child.status is Status.RUNNING or self.now() - self.start >= period:
            status = self.child.tick()
            if status is Status.SUCCESS:
                self.start = self.now()
            return status
        return self.status


# -- building --------------------------------------------------------------------------------

#: BehaviorTree.CPP's and Nav2's controls and decorators, by XML element name
BUILTIN: dict[str, type[TreeNode]] = {
    "Sequence": Sequence, "Fallback": Fallback, "ReactiveSequence": ReactiveSequence,
    "ReactiveFallback": ReactiveFallback, "PipelineSequence": PipelineSequence, "RoundRobin": RoundRobin,
    "RecoveryNode": RecoveryNode, "Inverter": Inverter, "ForceSuccess": ForceSuccess, "ForceFailure": ForceFailure,
    "RetryUntilSuccessful": RetryUntilSuccessful, "Repeat": Repeat, "RateController": RateController,
}


class NodeRegistry(dict):  # type: ignore[type-arg]
    """Element name -> a factory ``(name, ports, blackboard, children) -> TreeNode`` (a TreeNode subclass fits)."""


class Tree:
    """A built tree: :meth:`tick` it, :meth:`halt` it; ``blackboard`` is shared by its nodes."""

    def __init__(self, root: TreeNode, blackboard: Blackboard, tree_id: str) -> None:
        self.root = root
        self.blackboard = blackboard
        self.id = tree_id

    def __repr__(self) -> str:
        return f"<Tree {self.id!r} {self.root.status.name}>"

    def tick(self) -> Status:
        return self.root.tick()

    def halt(self) -> None:
        self.root.halt()

    def nodes(self) -> list[TreeNode]:
        out, todo = [], [self.root]
        while todo:
            node = todo.pop(0)
            out.append(node)
            todo.extend(node.children)
        return out


def load_tree(xml: str, registry: NodeRegistry, *, now: Callable[[], float], blackboard: Blackboard | None = None,
              source: str = "<string>") -> Tree:
    """Build the main tree of a BehaviorTree.CPP XML document (v3 or v4 ``<root>``).

    ``registry`` names the leaves (and extra controls); ``now`` is the clock (s) that rate-limited
    decorators read. The main tree is ``main_tree_to_execute``, or the only ``<BehaviorTree>``.
    """
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as err:
        raise TreeError(f"{source}: not valid XML ({err})") from None
    if root.tag != "root":
        raise TreeError(f"{source}: expected a <root> element, found <{root.tag}>")
    trees = {t.get("ID", ""): t for t in root.findall("BehaviorTree")}
    if not trees:
        raise TreeError(f"{source}: expected at least one <BehaviorTree ID=...>, found none")
    main = root.get("main_tree_to_execute") or (next(iter(trees)) if len(trees) == 1 else "")
    if main not in trees:
        raise TreeError(f"{source}: main_tree_to_execute {main!r} is not among the trees {sorted(trees)}")
    body = list(trees[main])
    if len(body) != 1:
        raise TreeError(f"{source}: <BehaviorTree ID={main!r}> must hold exactly one root node, found {len(body)}")
    board = blackboard if blackboard is not None else Blackboard()
    known = {**BUILTIN, **registry}

    def build(element: ET.Element) -> TreeNode:
        kind = element.tag
        ports = {k: v for k, v in element.attrib.items() if k != "name"}
        if kind in ("Action", "Condition", "Control", "Decorator") and "ID" in ports:
            kind = ports.pop("ID")  # the explicit form <Action ID="Spin" .../>
        if kind not in known:
            near = difflib.get_close_matches(kind, list(known), n=1)
            raise TreeError(f"{source}: unknown node <{kind}> in tree {main!r}" + (f"; did you mean <{near[0]}>?" if near else "")
                            + f" (known: {', '.join(sorted(known))})")
        name = element.get("name", kind)
        children = [build(child) for child in element]
        factory = known[kind]
        try:
            if factory is RateController:
                return RateController(name, ports, board, children, now=now)
            return factory(name, ports, board, children)
        except TreeError as err:
            raise TreeError(f"{source}: {err}") from None

    return Tree(build(body[0]), board, main)
