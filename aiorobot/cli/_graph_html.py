"""The graph as a self-contained HTML page with an inline SVG, laid out like rqt_graph.

Nodes are ellipses, topics boxes, edges run publisher -> topic -> subscriber, left to
right. The layout is a small layered (Sugiyama-style) drawing: cycles are broken by a
depth-first search, every vertex sits on the layer of its longest path from a source,
and a few barycenter sweeps order each layer to cut crossings. No Graphviz, no
JavaScript, no external resources: the file opens anywhere, offline.

As rqt_graph's default "hide debug", ``/rosout`` and ``/parameter_events`` (which every
node touches) are left out unless ``include_debug``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from html import escape
from typing import Any

__all__ = ["DEBUG_TOPICS", "graph_html", "layout"]

DEBUG_TOPICS = frozenset({"/rosout", "/parameter_events"})

_CHAR_PX = 7.2  # monospace 12 px
_HEIGHT = 36.0
_LAYER_GAP = 90.0
_ROW_GAP = 22.0
_MARGIN = 20.0


@dataclass
class Vertex:
    key: str  # "node:/ns/name" or "topic:/name"
    label: str
    kind: str  # "node" | "topic"
    tooltip: str
    warn: bool = False
    layer: int = 0
    x: float = 0.0  # centre
    y: float = 0.0
    width: float = 0.0
    ins: list[str] = field(default_factory=list)
    outs: list[str] = field(default_factory=list)


def layout(graph: Any, *, include_debug: bool = False) -> tuple[dict[str, Vertex], list[tuple[str, str]], float, float]:
    """Vertices with positions, edges as (from key, to key), and the drawing's width and height."""
    bad = {i.topic for i in graph.incompatible_qos}
    vertices: dict[str, Vertex] = {}
    edges: list[tuple[str, str]] = []
    for n in sorted(graph.nodes, key=lambda n: n.fully_qualified_name):
        key = f"node:{n.fully_qualified_name}"
        vertices[key] = Vertex(key, n.fully_qualified_name, "node", f"node {n.fully_qualified_name}")
    for t in graph.topics:
        if t.name in DEBUG_TOPICS and not include_debug:
            continue
        key = f"topic:{t.name}"
        tip = f"topic {t.name} [{', '.join(t.types)}]"
        if t.name in bad:
            tip += "\n" + "\n".join(f"{i.kind}: {i.publisher_node} -> {i.subscription_node} ({i.reason})"
                                    for i in graph.incompatible_qos if i.topic == t.name)
        vertices[key] = Vertex(key, t.name, "topic", tip, warn=t.name in bad)
        for p in t.publishers:
            edges.append((f"node:{p.node}", key))
        for s in t.subscriptions:
            edges.append((key, f"node:{s.node}"))
    edges = [e for e in dict.fromkeys(edges) if e[0] in vertices and e[1] in vertices]
    for a, b in edges:
        vertices[a].outs.append(b)
        vertices[b].ins.append(a)
    _assign_layers(vertices, edges)
    return (vertices, edges, *_place(vertices))


def _assign_layers(vertices: dict[str, Vertex], edges: list[tuple[str, str]]) -> None:
    # Break cycles: drop the edges a DFS finds pointing back to a vertex on its stack.
    state: dict[str, int] = {}
    back: set[tuple[str, str]] = set()
    for root in sorted(vertices, key=lambda k: (len(vertices[k].ins) > 0, k)):
        if root in state:
            continue
        stack = [(root, iter(vertices[root].outs))]
        state[root] = 1
        while stack:
            v, it = stack[-1]
            nxt = next(it, None)
            if nxt is None:
                state[v] = 2
                stack.pop()
            elif state.get(nxt) == 1:
                back.add((v, nxt))
            elif nxt not in state:
                state[nxt] = 1
                stack.append((nxt, iter(vertices[nxt].outs)))
    indegree = {k: 0 for k in vertices}
    for a, b in edges:
        if (a, b) not in back:
            indegree[b] += 1
    ready = sorted(k for k, d in indegree.items() if d == 0)
    while ready:
        v = ready.pop()
        for b in vertices[v].outs:
            if (v, b) not in back:
                vertices[b].layer = max(vertices[b].layer, vertices[v].layer + 1)
                indegree[b] -= 1
                if indegree[b] == 0:
                    ready.append(b)


def _place(vertices: dict[str, Vertex]) -> tuple[float, float]:
    layers: dict[int, list[Vertex]] = {}
    for v in vertices.values():
        v.width = max(len(v.label) * _CHAR_PX + (34 if v.kind == "node" else 20), 60.0)
        layers.setdefault(v.layer, []).append(v)
    order = {k: [v.key for v in sorted(layers[k], key=lambda v: v.key)] for k in sorted(layers)}

    def sweep(layer: int, neighbours: str) -> None:
        index = {key: i for lk in order.values() for i, key in enumerate(lk)}

        def barycenter(key: str) -> float:
            near = getattr(vertices[key], neighbours)
            return sum(index[n] for n in near) / len(near) if near else index[key]

        order[layer].sort(key=barycenter)

    for _ in range(4):
        for k in sorted(order)[1:]:
            sweep(k, "ins")
        for k in sorted(order, reverse=True)[1:]:
            sweep(k, "outs")
    x = _MARGIN
    height = 0.0
    for k in sorted(order):
        column = [vertices[key] for key in order[k]]
        width = max(v.width for v in column)
        for i, v in enumerate(column):
            v.x = x + width / 2
            v.y = _MARGIN + _HEIGHT / 2 + i * (_HEIGHT + _ROW_GAP)
        height = max(height, len(column) * (_HEIGHT + _ROW_GAP))
        x += width + _LAYER_GAP
    # centre each column vertically
    for k in sorted(order):
        column = [vertices[key] for key in order[k]]
        shift = (height - len(column) * (_HEIGHT + _ROW_GAP)) / 2
        for v in column:
            v.y += shift
    return x - _LAYER_GAP + _MARGIN, height + 2 * _MARGIN - _ROW_GAP


def graph_html(graph: Any, *, title: str = "aiorobot graph", include_debug: bool = False) -> str:
    """A complete HTML document drawing ``graph`` (an :class:`aiorobot.Graph`) as inline SVG."""
    vertices, edges, width, height = layout(graph, include_debug=include_debug)
    svg = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'viewBox="0 0 {width:.0f} {height:.0f}" font-family="monospace" font-size="12">',
        '<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="8" markerHeight="8" '
        'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="#555"/></marker></defs>',
    ]
    for a, b in edges:
        va, vb = vertices[a], vertices[b]
        x1, y1 = va.x + va.width / 2, va.y
        x2, y2 = vb.x - vb.width / 2, vb.y
        bend = max(abs(x2 - x1) / 2, 40.0)
        svg.append(
            f'<path class="edge" data-from="{escape(va.label)}" data-to="{escape(vb.label)}" '
            f'd="M{x1:.1f},{y1:.1f} C{x1 + bend:.1f},{y1:.1f} {x2 - bend:.1f},{y2:.1f} {x2:.1f},{y2:.1f}" '
            'fill="none" stroke="#555" stroke-width="1.3" marker-end="url(#arrow)"/>'
        )
    for v in sorted(vertices.values(), key=lambda v: v.key):
        stroke = "#c00" if v.warn else "#333"
        if v.kind == "node":
            shape = (f'<ellipse cx="{v.x:.1f}" cy="{v.y:.1f}" rx="{v.width / 2:.1f}" ry="{_HEIGHT / 2:.1f}" '
                     f'fill="#dbe9ff" stroke="{stroke}"/>')
        else:
            shape = (f'<rect x="{v.x - v.width / 2:.1f}" y="{v.y - _HEIGHT / 2:.1f}" width="{v.width:.1f}" '
                     f'height="{_HEIGHT:.1f}" fill="#fff6d5" stroke="{stroke}"/>')
        svg.append(
            f'<g class="{v.kind}" data-name="{escape(v.label)}"><title>{escape(v.tooltip)}</title>{shape}'
            f'<text x="{v.x:.1f}" y="{v.y + 4:.1f}" text-anchor="middle">{escape(v.label)}</text></g>'
        )
    svg.append("</svg>")
    counts = (f"{sum(v.kind == 'node' for v in vertices.values())} nodes, "
              f"{sum(v.kind == 'topic' for v in vertices.values())} topics")
    hidden = "" if include_debug else " (/rosout and /parameter_events hidden, as rqt_graph's &quot;hide debug&quot;)"
    return "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:1em} g.node:hover ellipse,g.topic:hover rect{stroke-width:3}"
        " svg{border:1px solid #ccc}</style>",
        "</head><body>",
        f"<h1>{escape(title)}</h1>",
        f"<p>{counts}{hidden}; ellipses are nodes, boxes topics, red boxes topics with incompatible QoS or types.</p>",
        *svg,
        "</body></html>",
        "",
    ])
