"""Lock-step replay: a bag's inputs fed to nodes on sim time, what they publish captured.

The impure half of ``aiorobot bag check`` (the comparison is :mod:`._diff`). The nodes run in
a local ``Runtime(use_sim_time=True)`` whose ``/clock`` only the replay publishes, and time
moves as the simulator's lock-step moves it: to each earlier timer deadline any node waits for
(``Clock.next_deadline_ns``), then to the next input time, where ``/clock`` is published, every
input recorded at that time is published in bag order, and the runtime settles before time
moves again. What the nodes compute therefore does not depend on the machine's speed, and two
replays give the same bytes.

Which topics are which comes from the nodes themselves: an *output* is a topic they publish
that the bag holds (minus :data:`INFRASTRUCTURE_TOPICS`), an *input* a topic they subscribe to
that the bag holds and that is not an output (a node that both publishes and listens to
``/tf`` hears its own transforms, as in the recorded run). ``/clock`` is never played: the
replay owns time.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ._metadata import BagError
from ._reader import BagReader

__all__ = ["INFRASTRUCTURE_TOPICS", "ReplayResult", "replay"]

#: Topics every node publishes, not what it computes: not compared unless asked for by name.
INFRASTRUCTURE_TOPICS = frozenset({"/rosout", "/parameter_events"})


@dataclass(frozen=True, slots=True)
class ReplayResult:
    """What a replay fed and captured.

    ``outputs``: topic -> ``[(time_ns, cdr), ...]`` as the nodes published them; ``inputs``: the
    topics played; ``not_in_bag``: topics the nodes subscribe to that the bag lacks;
    ``not_recorded``: topics the nodes publish that the bag lacks (so nothing to compare with);
    ``played``: input messages published; ``steps``: times ``/clock`` moved; ``sim_ns``: the
    recording time replayed.
    """

    outputs: dict[str, list[tuple[int, bytes]]]
    inputs: tuple[str, ...]
    not_in_bag: tuple[str, ...]
    played: int
    steps: int
    sim_ns: int
    types: dict[str, Any] = field(default_factory=dict)
    not_recorded: tuple[str, ...] = ()


async def replay(
    path: str,
    factories: Sequence[Callable[[], Any]],
    *,
    outputs: Sequence[str] | None = None,
    settle_rounds: int = 3,
) -> ReplayResult:
    """Build the nodes (each factory called once), feed them the bag, capture their outputs.

    ``outputs``: the topics to capture (default: every topic the nodes publish that the bag
    holds). Raises :class:`BagError` when the nodes subscribe to nothing the bag holds, or an
    ``outputs`` topic is neither published by the nodes nor in the bag.
    """
    from aiorobot import ClockPublisher, Runtime
    from aiorobot.msgs import deserialize, serialize
    from aiorobot.lowlevel import Tap, add_tap

    with BagReader(path) as reader:
        known = {t.name: t for t in reader.topics}
        # built before the runtime: a node's imports and kernel loading do not stall its loop
        built = [factory() for factory in factories]
        async with Runtime(use_sim_time=True, transport="local", handle_signals=False) as rt:
            clock = ClockPublisher(name="bag_check_clock")
            rt.add_node(clock)
            now_ns = reader.start_ns
            clock.publish_time(now_ns)  # before the nodes: their timers start where the recording starts
            await rt.settle()
            nodes = [rt.add_node(node) for node in built]
            await rt.settle()
            published = {p.topic_name: p for n in nodes for p in n.publishers}
            subscribed = {s.topic_name for n in nodes for s in n.subscriptions}
            wanted = _outputs(path, known, published, outputs)
            inputs = tuple(sorted(t for t in subscribed if t in known and t not in wanted and t != "/clock"))
            if not inputs:
                raise BagError(
                    f"{path}: the nodes subscribe to {', '.join(sorted(subscribed)) or 'nothing'}; "
                    f"the bag holds none of these (it holds {', '.join(sorted(known))})"
                )
            captured: dict[str, list[tuple[int, bytes]]] = {t: [] for t in wanted}
            types = {t: reader.message_type(t) for t in wanted}
            for topic in wanted:
                pub = published[topic]

                def keep(msg: Any, out: list[tuple[int, bytes]] = captured[topic]) -> None:
                    out.append((rt.clock.now().nanoseconds, serialize(msg)))

                add_tap(rt, Tap(pub.msg_type, topic, pub.qos, keep, owner="<bag check>"))
            feeder = rt.add_node(_feeder_node())
            pubs, in_types = {}, {}
            for topic in inputs:
                in_types[topic] = reader.message_type(topic)
                if in_types[topic] is None:
                    raise BagError(f"{path}: input {topic}: {reader.type_problem(topic)}")
                pubs[topic] = feeder.create_publisher(in_types[topic], topic, known[topic].qos)
            await rt.settle()
            played = steps = 0
            batch: list[tuple[str, bytes]] = []
            batch_ns = now_ns

            async def step_to(target_ns: int) -> None:
                """Fire every timer due before ``target_ns`` on its deadline, then move to ``target_ns``."""
                nonlocal now_ns, steps
                while (due := rt.clock.next_deadline_ns()) is not None and now_ns < due < target_ns:
                    clock.publish_time(due)
                    now_ns = due
                    steps += 1
                    await rt.settle(rounds=settle_rounds)
                clock.publish_time(target_ns)
                now_ns = target_ns
                steps += 1

            async def flush() -> None:
                nonlocal played
                if not batch:
                    return
                await step_to(batch_ns)
                for topic, data in batch:
                    pubs[topic].publish(deserialize(data, in_types[topic]))
                played += len(batch)
                batch.clear()
                await rt.settle(rounds=settle_rounds)

            for topic, t_ns, data in reader.messages(inputs):
                if t_ns != batch_ns:
                    await flush()
                    batch_ns = t_ns
                batch.append((topic, data))
            await flush()
            end_ns = max(reader.end_ns, now_ns)
            if end_ns > now_ns:  # the timers' outputs after the last input, up to the recording's end
                await step_to(end_ns)
                await rt.settle(rounds=settle_rounds)
    not_in_bag = tuple(sorted(t for t in subscribed if t not in known and t != "/clock"))
    not_recorded = tuple(sorted(t for t in published if t not in known and t not in INFRASTRUCTURE_TOPICS))
    return ReplayResult(captured, inputs, not_in_bag, played, steps, now_ns - reader.start_ns, types, not_recorded)


def _outputs(path: str, known: dict[str, Any], published: dict[str, Any], outputs: Sequence[str] | None) -> list[str]:
    if outputs is None:
        return sorted(t for t in published if t in known and t not in INFRASTRUCTURE_TOPICS)
    for topic in outputs:
        if topic not in published:
            raise BagError(f"output {topic}: the nodes do not publish it (they publish {', '.join(sorted(published))})")
        if topic not in known:
            raise BagError(f"{path}: output {topic} is not in the bag, so there is nothing to compare it with")
    return list(dict.fromkeys(outputs))


def _feeder_node() -> Any:
    from aiorobot import Node

    return Node("bag_check_player", start_parameter_services=False)
