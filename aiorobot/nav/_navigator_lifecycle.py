"""BasicNavigator's ``lifecycleStartup`` / ``lifecycleShutdown``, as a part of :class:`~._navigator.Navigator`.

As Nav2's: every service of type nav2_msgs/srv/ManageLifecycleNodes in the graph (each lifecycle
manager's ``~/manage_nodes``) is asked to STARTUP (or SHUTDOWN) in turn, waiting for each service and
for its answer.

Where they differ from BasicNavigator's: see :meth:`LifecycleCommands.lifecycle_startup`.
"""

from __future__ import annotations

from typing import Any

__all__ = ["LifecycleCommands"]

_MANAGE = "nav2_msgs/srv/ManageLifecycleNodes"


class LifecycleCommands:
    """``lifecycle_startup`` / ``lifecycle_shutdown`` for a Node subclass (Navigator)."""

    get_logger: Any
    get_service_names_and_types: Any
    create_client: Any
    destroy_client: Any

    async def lifecycle_startup(self, timeout_sec: float | None = None) -> bool:
        """STARTUP every lifecycle manager (configure then activate its nodes); True if all succeeded.

        ``timeout_sec`` bounds each manager's answer (None: wait, as BasicNavigator does).

        rclpy difference: a coroutine returning whether every manager succeeded (BasicNavigator's
        returns None); no manager in the graph is logged and returns False; the initial pose is not
        re-sent while a manager starts up (aiorobot's AMCL is not a lifecycle node to wait for).
        """
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        self.get_logger().info("Starting up lifecycle nodes based on lifecycle_manager.")
        ok = await self._manage_all(ManageLifecycleNodes.Request.STARTUP, "Starting up", timeout_sec)
        if ok:
            self.get_logger().info("Nav2 is ready for use!")
        return ok

    async def lifecycle_shutdown(self, timeout_sec: float | None = None) -> bool:
        """SHUTDOWN every lifecycle manager (deactivate, clean up, shut down its nodes); True if all succeeded."""
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        self.get_logger().info("Shutting down lifecycle nodes based on lifecycle_manager.")
        return await self._manage_all(ManageLifecycleNodes.Request.SHUTDOWN, "Shutting down", timeout_sec)

    async def _manage_all(self, command: int, verb: str, timeout_sec: float | None) -> bool:
        from aiorobot.msgs.nav2_msgs import ManageLifecycleNodes

        managers = [name for name, types in self.get_service_names_and_types() if types and types[0] == _MANAGE]
        if not managers:
            self.get_logger().warning(f"{verb}: no lifecycle manager in the graph (no {_MANAGE} service)")
            return False
        ok = True
        for srv_name in managers:
            self.get_logger().info(f"{verb} {srv_name}")
            client = self.create_client(ManageLifecycleNodes, srv_name)
            try:
                while not await client.wait_for_service(timeout_sec=1.0):
                    self.get_logger().info(f"{srv_name} service not available, waiting...")
                response = await client.call(ManageLifecycleNodes.Request(command=command), timeout_sec=timeout_sec)
            finally:
                self.destroy_client(client)
            if not response.success:
                self.get_logger().error(f"{verb}: {srv_name} reported failure (see its log for the node and why)")
                ok = False
        return ok

    # BasicNavigator's names
    lifecycleStartup = lifecycle_startup  # noqa: N815
    lifecycleShutdown = lifecycle_shutdown  # noqa: N815
