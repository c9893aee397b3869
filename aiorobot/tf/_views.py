"""Text views of a transform tree: tf2's YAML and a Graphviz graph."""

from __future__ import annotations

from dataclasses import dataclass

from ._cache import display_time

__all__ = ["FrameInfo", "frames_as_dot", "frames_as_yaml"]


@dataclass(frozen=True, slots=True)
class FrameInfo:
    """What a buffer knows about one frame's link to its parent."""

    frame: str
    parent: str
    authority: str
    rate_hz: float
    latest_ns: int
    oldest_ns: int
    static: bool


def frames_as_yaml(infos: list[FrameInfo], now_ns: int = 0) -> str:
    """tf2's ``allFramesAsYAML`` text (``transform_delay`` only when ``now_ns`` is given)."""
    if not infos:
        return "[]"
    out = []
    for f in infos:
        out.append(f"{f.frame}: \n")
        out.append(f"  parent: '{f.parent}'\n")
        out.append(f"  broadcaster: '{f.authority}'\n")
        out.append(f"  rate: {f.rate_hz:.3f}\n")
        out.append(f"  most_recent_transform: {display_time(f.latest_ns)}\n")
        out.append(f"  oldest_transform: {display_time(f.oldest_ns)}\n")
        if now_ns:
            out.append(f"  transform_delay: {(now_ns - f.latest_ns) / 1e9:.3f}\n")
        out.append(f"  buffer_length: {(f.latest_ns - f.oldest_ns) / 1e9:.3f}\n")
    return "".join(out)


def frames_as_dot(infos: list[FrameInfo], frames: list[str], now_ns: int = 0) -> str:
    """A Graphviz digraph: every frame a node, every link an edge parent -> child
    labelled with its authority and, for dynamic links, rate, latest stamp and span."""
    lines = ["digraph G {"]
    if not infos:
        lines.append('"no tf data received";')
    for name in frames:
        lines.append(f'"{_escape(name)}";')
    for f in infos:
        if f.static:
            timing = "static"
        else:
            timing = f"Average rate: {f.rate_hz:.3f} Hz\\nMost recent transform: {display_time(f.latest_ns)}"
            if now_ns:
                timing += f" ({(now_ns - f.latest_ns) / 1e9:.3f} sec old)"
            timing += f"\\nBuffer length: {(f.latest_ns - f.oldest_ns) / 1e9:.3f} sec"
        lines.append(
            f'"{_escape(f.parent)}" -> "{_escape(f.frame)}" '
            f'[label="Broadcaster: {_escape(f.authority)}\\n{timing}"];'
        )
    lines.append("}")
    return "\n".join(lines) + "\n"


def _escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')
