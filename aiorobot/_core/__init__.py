"""The core: the run loop and the node family, which every other layer builds on.

``Runtime`` and its loops (main, priority, watchdog, waker), ``Node`` and its mixins, the
in-process bus, publishers and subscriptions, services, actions, timers, clocks, time, QoS,
names, callback groups, parameter types, logging and the transport seam. Everything here is
private; the public names are re-exported once by ``aiorobot/__init__.py``.

The core imports only itself, the standard library, ``aiorobot.msgs`` and
``aiorobot.parameters`` (``Runtime(config=...)`` reads a graph file through the loader that
``aiorobot.launch`` installs); it finds transports by name in the registry of
:mod:`aiorobot._core._transport` and never names an application or a transport
implementation (docs/architecture.md; tests/test_layers.py keeps this true).
"""
