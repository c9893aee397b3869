"""``rclpy`` on aiorobot (installed by ``aiorobot exec``): init, spin, shutdown and friends.

See docs/rclpy-compat.md for what is supported, what differs and what is missing.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from .._context import Context, default_context
from .._missing import module_getattr

__all__ = [
    "create_node",
    "get_default_context",
    "get_global_executor",
    "init",
    "ok",
    "shutdown",
    "spin",
    "spin_once",
    "spin_until_future_complete",
    "try_shutdown",
    "utilities",
]

_global_executor: Any = None


class InitContextManager:
    """What ``rclpy.init`` returns: ``with rclpy.init():`` shuts down (``try_shutdown``) on exit."""

    def __init__(self, context: Context) -> None:
        self.context = context

    def __enter__(self) -> InitContextManager:
        return self

    def __exit__(self, *exc: object) -> None:
        self.context.try_shutdown()


def init(
    *, args: Sequence[str] | None = None, context: Context | None = None, domain_id: int | None = None,
    signal_handler_options: Any = None,
) -> InitContextManager:
    """Initialise the context: parse ``--ros-args`` from ``args`` (default ``sys.argv``)."""
    ctx = context or default_context()
    ctx.init(None if args is None else list(args), domain_id=domain_id)
    return InitContextManager(ctx)


def ok(*, context: Context | None = None) -> bool:
    return (context or default_context()).ok()


def shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    global _global_executor
    (context or default_context()).shutdown()
    if context is None and _global_executor is not None:
        _global_executor.shutdown()
        _global_executor = None


def try_shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    global _global_executor
    (context or default_context()).try_shutdown()
    if context is None and _global_executor is not None:
        _global_executor.shutdown()
        _global_executor = None


def get_default_context(*, shutting_down: bool = False) -> Context:
    return default_context()


def get_global_executor() -> Any:
    global _global_executor
    if _global_executor is None:
        from .executors import SingleThreadedExecutor

        _global_executor = SingleThreadedExecutor()
    return _global_executor


def create_node(node_name: str, **kwargs: Any) -> Any:
    from .node import Node

    return Node(node_name, **kwargs)


def spin(node: Any, executor: Any = None) -> None:
    """Run callbacks until the context shuts down (``ExternalShutdownException`` then) or Ctrl-C."""
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        with executor.context.spinning():
            while executor.context.ok():
                executor.spin_once()
    finally:
        executor.remove_node(node)


def spin_once(node: Any, *, executor: Any = None, timeout_sec: float | None = None) -> None:
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        executor.spin_once(timeout_sec=timeout_sec)
    finally:
        executor.remove_node(node)


def spin_until_future_complete(node: Any, future: Any, executor: Any = None, timeout_sec: float | None = None) -> None:
    executor = get_global_executor() if executor is None else executor
    try:
        executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec)
    finally:
        executor.remove_node(node)


def __getattr__(name: str) -> Any:
    import importlib

    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    return _missing(name)


_SUBMODULES = frozenset(
    {
        "action", "callback_groups", "client", "clock", "duration", "exceptions", "executors",
        "logging", "node", "parameter", "publisher", "qos", "service", "subscription", "task", "time",
        "timer", "utilities", "signals", "context", "lifecycle", "serialization",
        "parameter_client", "impl", "service_introspection", "experimental",
    }
)
_missing = module_getattr(
    __name__, "rclpy", {"get_rmw_implementation_identifier", "wait_for_message", "create_guard_condition"}
)
