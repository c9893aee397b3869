"""``rclpy.lifecycle.managed_entity``: what a lifecycle node drives through its transitions."""

from __future__ import annotations

from collections.abc import Callable
from functools import wraps
from typing import TYPE_CHECKING, Any

from ....lifecycle import TransitionCallbackReturn

if TYPE_CHECKING:
    from .node import LifecycleState

__all__ = ["ManagedEntity", "SimpleManagedEntity", "TransitionCallbackReturn"]


class ManagedEntity:
    """An entity with the six transition callbacks; each returns SUCCESS unless overridden."""

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle configure transition request."""
        return TransitionCallbackReturn.SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle cleanup transition request."""
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle shutdown transition request."""
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle activate transition request."""
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle deactivate transition request."""
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle error transition request."""
        return TransitionCallbackReturn.SUCCESS


class SimpleManagedEntity(ManagedEntity):
    """A managed entity that only sets a flag when activated / deactivated."""

    def __init__(self) -> None:
        self._enabled = False

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._enabled = True
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._enabled = False
        return TransitionCallbackReturn.SUCCESS

    @property
    def is_activated(self) -> bool:
        return self._enabled

    @staticmethod
    def when_enabled(
        wrapped: Callable[..., None] | None = None, *, when_not_enabled: Callable[..., None] | None = None
    ) -> Any:
        """Decorate a method so it runs only while activated (else ``when_not_enabled()``, if given)."""

        def decorator(wrapped: Callable[..., None]) -> Callable[..., None]:
            @wraps(wrapped)
            def only_when_enabled_wrapper(self: SimpleManagedEntity, *args: Any, **kwargs: Any) -> None:
                if not self._enabled:
                    if when_not_enabled is not None:
                        when_not_enabled()
                    return
                wrapped(self, *args, **kwargs)

            return only_when_enabled_wrapper

        if wrapped is None:
            return decorator
        return decorator(wrapped)
