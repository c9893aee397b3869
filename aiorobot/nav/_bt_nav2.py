"""Nav2's behaviour-tree nodes, bound to the navigation server, and the server's default tree.

The leaves keep Nav2's element names and ports (nav2_behavior_tree's plugins) and run the server's
own planner, controller loop and behaviours (:mod:`._behaviors`) instead of calling other servers:

- actions: ``ComputePathToPose`` (goal, path, error_code_id, error_msg), ``FollowPath`` (path,
  error_code_id, error_msg; a new ``path`` on the blackboard is taken up while it runs),
  ``Spin`` (spin_dist, time_allowance), ``BackUp`` (backup_dist, backup_speed, time_allowance),
  ``DriveOnHeading`` (dist_to_travel, speed, time_allowance), ``Wait`` (wait_duration) and
  ``ClearEntireCostmap`` (service_name; the server has one costmap: any name clears it);
- conditions: ``GoalUpdated``, ``GlobalUpdatedGoal`` (the blackboard's ``goal`` changed since the
  node last ran), ``WouldAPlannerRecoveryHelp`` / ``WouldAControllerRecoveryHelp`` (error_code is
  one that a recovery may cure, Nav2's lists);
- the selectors ``ControllerSelector``, ``PlannerSelector``, ``GoalCheckerSelector``,
  ``ProgressCheckerSelector``, ``PathHandlerSelector`` write their default to their output port
  (one controller, one planner: nothing to select).

Spin, BackUp, Wait and DriveOnHeading count as recoveries (Nav2's ``number_recoveries``).

:data:`DEFAULT_TREE` restates Nav2's ``navigate_to_pose_w_replanning_and_recovery.xml``: replan at
1 Hz beside the path follower (each with one clear-costmap retry), and when navigation fails, up to
``number_of_retries`` rounds of the recovery actions in turn (clear both costmaps, spin 1.57 rad,
wait 5 s, back up 0.30 m at 0.15 m/s) unless the goal changed; a planner error no recovery helps
with (goal or start off the map, goal occupied) ends it at once.
"""

from __future__ import annotations

from typing import Any

from ._bt import AsyncAction, Condition, NodeRegistry, Status, TreeNode
from ._geometry import xyyaw

__all__ = ["DEFAULT_TREE", "nav2_registry"]

DEFAULT_TREE = """\
<root BTCPP_format="4" main_tree_to_execute="NavigateToPoseWReplanningAndRecovery">
  <!-- aiorobot's restatement of Nav2's default NavigateToPose tree -->
  <BehaviorTree ID="NavigateToPoseWReplanningAndRecovery">
    <RecoveryNode number_of_retries="{number_of_retries}" name="NavigateRecovery">
      <PipelineSequence name="NavigateWithReplanning">
        <RateController hz="{replan_hz}">
          <RecoveryNode number_of_retries="1" name="ComputePathToPose">
            <ComputePathToPose goal="{goal}" path="{path}" error_code_id="{compute_path_error_code}"
                               error_msg="{compute_path_error_msg}"/>
            <Sequence>
              <WouldAPlannerRecoveryHelp error_code="{compute_path_error_code}"/>
              <ClearEntireCostmap name="ClearGlobalCostmap-Context" service_name="global_costmap/clear_entirely_global_costmap"/>
            </Sequence>
          </RecoveryNode>
        </RateController>
        <RecoveryNode number_of_retries="1" name="FollowPath">
          <FollowPath path="{path}" error_code_id="{follow_path_error_code}" error_msg="{follow_path_error_msg}"/>
          <Sequence>
            <WouldAControllerRecoveryHelp error_code="{follow_path_error_code}"/>
            <ClearEntireCostmap name="ClearLocalCostmap-Context" service_name="local_costmap/clear_entirely_local_costmap"/>
          </Sequence>
        </RecoveryNode>
      </PipelineSequence>
      <Sequence>
        <Fallback>
          <WouldAControllerRecoveryHelp error_code="{follow_path_error_code}"/>
          <WouldAPlannerRecoveryHelp error_code="{compute_path_error_code}"/>
        </Fallback>
        <ReactiveFallback name="RecoveryFallback">
          <GoalUpdated/>
          <RoundRobin name="RecoveryActions">
            <Sequence name="ClearingActions">
              <ClearEntireCostmap name="ClearLocalCostmap-Subtree" service_name="local_costmap/clear_entirely_local_costmap"/>
              <ClearEntireCostmap name="ClearGlobalCostmap-Subtree" service_name="global_costmap/clear_entirely_global_costmap"/>
            </Sequence>
            <Spin spin_dist="1.57"/>
            <Wait wait_duration="5.0"/>
            <BackUp backup_dist="0.30" backup_speed="0.15"/>
          </RoundRobin>
        </ReactiveFallback>
      </Sequence>
    </RecoveryNode>
  </BehaviorTree>
</root>
"""

def planner_recoverable() -> set[int]:
    """ComputePathToPose / ComputePathThroughPoses codes a recovery may cure (WouldAPlannerRecoveryHelp's list)."""
    from aiorobot.msgs.nav2_msgs import ComputePathThroughPoses, ComputePathToPose

    return {int(getattr(action.Result, name)) for action in (ComputePathToPose, ComputePathThroughPoses)
            for name in ("UNKNOWN", "NO_VALID_PATH", "TIMEOUT")}


def controller_recoverable() -> set[int]:
    """FollowPath codes a recovery may cure (WouldAControllerRecoveryHelp's list)."""
    from aiorobot.msgs.nav2_msgs import FollowPath

    return {int(getattr(FollowPath.Result, name)) for name in ("UNKNOWN", "PATIENCE_EXCEEDED", "FAILED_TO_MAKE_PROGRESS",
                                                                "NO_VALID_CONTROL")}


class _ServerLeaf(TreeNode):
    server: Any = None  # bound per registry


class _ServerAction(AsyncAction):
    server: Any = None

    def _fail(self, code: int, message: str) -> bool:
        self.set_output("error_code_id", int(code))
        self.set_output("error_msg", message)
        return False

    def _ok(self) -> bool:
        self.set_output("error_code_id", 0)
        self.set_output("error_msg", "")
        return True


class ComputePathToPose(_ServerAction):
    async def run(self) -> bool:
        from ._navigation_server import _Abort

        s = self.server
        goal = self.get_input("goal")
        try:
            await s._wait_for_map()
            p = s._plan(s._robot_pose(), xyyaw(goal))
        except _Abort as err:
            return self._fail(err.code, str(err))
        self.set_output("path", p.poses)
        return self._ok()


class FollowPath(_ServerAction):
    async def run(self) -> bool:
        from aiorobot.msgs.nav2_msgs import FollowPath as FollowPathAction

        outcome, message = await self.server.behaviors.follow(lambda: self.get_input("path"))
        if outcome == "SUCCEEDED":
            return self._ok()
        return self._fail(getattr(FollowPathAction.Result, outcome, FollowPathAction.Result.UNKNOWN), message)


class _Recovery(_ServerAction):
    """A behaviour run as a recovery: counted in the server's ``recoveries``."""

    action_name = ""

    async def run(self) -> bool:
        from aiorobot.msgs import nav2_msgs

        s = self.server
        s.recoveries += 1
        s.get_logger().info(f"recovery {s.recoveries}: {self.name}")
        outcome, message = await self.behave()
        if outcome == "SUCCEEDED":
            return self._ok()
        action = getattr(nav2_msgs, self.action_name, None)
        return self._fail(getattr(action.Result, outcome, 0) if action is not None else 0, message)

    async def behave(self) -> tuple[str, str]:
        raise NotImplementedError


class Spin(_Recovery):
    action_name = "Spin"

    def behave(self) -> Any:
        return self.server.behaviors.spin(self.get_input("spin_dist", float, 1.57),
                                          self.get_input("time_allowance", float, 10.0))


class BackUp(_Recovery):
    action_name = "BackUp"

    def behave(self) -> Any:
        return self.server.behaviors.drive(-abs(self.get_input("backup_dist", float, 0.15)),
                                           -abs(self.get_input("backup_speed", float, 0.025)),
                                           self.get_input("time_allowance", float, 10.0))


class DriveOnHeading(_Recovery):
    action_name = "DriveOnHeading"

    def behave(self) -> Any:
        return self.server.behaviors.drive(self.get_input("dist_to_travel", float, 0.15), self.get_input("speed", float, 0.025),
                                           self.get_input("time_allowance", float, 10.0))


class Wait(_Recovery):
    async def behave(self) -> tuple[str, str]:
        s = self.server
        s._stop_base()
        await s.get_clock().sleep_for(self.get_input("wait_duration", float, 1.0))
        return "SUCCEEDED", ""


class ClearEntireCostmap(_ServerLeaf):
    def _tick(self) -> Status:
        cm = self.server.costmap
        if cm is not None:
            cm.clear_obstacles()
            cm.update()
        return Status.SUCCESS


class GoalUpdated(Condition):
    """SUCCESS when the blackboard's ``goal`` (or ``goals``) differs from what it saw when it last ran."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.seen: Any = None

    def _tick(self) -> Status:
        current = (self.blackboard.get("goal"), self.blackboard.get("goals"))
        if self.status is Status.IDLE:  # BT::isStatusActive: first tick of a run only remembers
            self.seen = current
            return Status.FAILURE
        if current != self.seen:
            self.seen = current
            return Status.SUCCESS
        return Status.FAILURE


class WouldAPlannerRecoveryHelp(Condition):
    def check(self) -> bool:
        return int(self.get_input("error_code", int, 0)) in planner_recoverable()


class WouldAControllerRecoveryHelp(Condition):
    def check(self) -> bool:
        return int(self.get_input("error_code", int, 0)) in controller_recoverable()


def _selector(default_port: str, output_port: str) -> type[TreeNode]:
    class Selector(TreeNode):
        def _tick(self) -> Status:
            self.set_output(output_port, self.get_input(default_port, str, ""))
            return Status.SUCCESS

    return Selector


def nav2_registry(server: Any) -> NodeRegistry:
    """Nav2's node library (see the module doc) bound to ``server`` (a NavigationServer)."""
    leaves: dict[str, type[TreeNode]] = {
        "ComputePathToPose": ComputePathToPose, "FollowPath": FollowPath, "Spin": Spin, "BackUp": BackUp,
        "DriveOnHeading": DriveOnHeading, "Wait": Wait, "ClearEntireCostmap": ClearEntireCostmap,
    }
    registry = NodeRegistry()
    for name, cls in leaves.items():
        registry[name] = type(name, (cls,), {"server": server})
    registry.update({
        "GoalUpdated": GoalUpdated, "GlobalUpdatedGoal": GoalUpdated,
        "WouldAPlannerRecoveryHelp": WouldAPlannerRecoveryHelp,
        "WouldAControllerRecoveryHelp": WouldAControllerRecoveryHelp,
        "ControllerSelector": _selector("default_controller", "selected_controller"),
        "PlannerSelector": _selector("default_planner", "selected_planner"),
        "GoalCheckerSelector": _selector("default_goal_checker", "selected_goal_checker"),
        "ProgressCheckerSelector": _selector("default_progress_checker", "selected_progress_checker"),
        "PathHandlerSelector": _selector("default_path_handler", "selected_path_handler"),
    })
    return registry
