"""``aiorobot graph --html``'s page: a layered drawing of a graph, self-contained."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from aiorobot import EndpointInfo, Graph, NodeInfo, QoSProfile, TopicInfo
from aiorobot._core._bus import Incompatibility
from aiorobot.cli._graph_html import graph_html, layout

SVG = "{http://www.w3.org/2000/svg}"


def make_graph() -> Graph:
    chain = [("/camera", "/image", "/detector"), ("/detector", "/detections", "/planner"),
             ("/planner", "/cmd_vel", "/base"), ("/base", "/odom", "/planner")]  # /odom closes a cycle
    nodes = sorted({n for pub, _, sub in chain for n in (pub, sub)})
    qos = QoSProfile(depth=10)
    topics = [
        TopicInfo(t, ("std_msgs/msg/String",), (EndpointInfo(p, t, "std_msgs/msg/String", "publisher", qos),),
                  (EndpointInfo(s, t, "std_msgs/msg/String", "subscription", qos),))
        for p, t, s in chain
    ]
    topics.append(TopicInfo("/rosout", ("rcl_interfaces/msg/Log",),
                            tuple(EndpointInfo(n, "/rosout", "rcl_interfaces/msg/Log", "publisher", qos) for n in nodes), ()))
    bad = Incompatibility("/cmd_vel", "p", "s", "best effort offered, reliable requested", "/planner", "/base")
    return Graph(tuple(NodeInfo(n[1:], "/", n, "main") for n in nodes), tuple(topics), (bad,))


def test_layers_follow_the_data_flow_and_columns_do_not_overlap() -> None:
    vertices, edges, width, height = layout(make_graph())
    x = {v.label: v.x for v in vertices.values()}
    assert x["/camera"] < x["/image"] < x["/detector"] < x["/detections"] < x["/planner"] < x["/cmd_vel"] < x["/base"]
    assert "topic:/rosout" not in vertices and len(edges) == 8
    by_column: dict[float, list] = {}
    for v in vertices.values():
        by_column.setdefault(round(v.x - v.width / 2), []).append(v)
        assert 0 <= v.x - v.width / 2 and v.x + v.width / 2 <= width and 0 <= v.y <= height
    for column in by_column.values():
        ys = sorted(v.y for v in column)
        assert all(b - a >= 36 for a, b in zip(ys, ys[1:]))


def test_page_is_one_self_contained_document_with_an_svg() -> None:
    page = graph_html(make_graph(), title="robot")
    assert page.startswith("<!DOCTYPE html>") and "<script" not in page
    assert re.findall(r"(?:src|href)=", page) == []  # nothing to fetch
    svg = ET.fromstring(page[page.index("<svg"): page.index("</svg>") + 6])
    groups = svg.findall(f"{SVG}g")
    nodes = [g.get("data-name") for g in groups if g.get("class") == "node"]
    topics = [g.get("data-name") for g in groups if g.get("class") == "topic"]
    assert nodes == ["/base", "/camera", "/detector", "/planner"]
    assert topics == ["/cmd_vel", "/detections", "/image", "/odom"]
    edges = {(p.get("data-from"), p.get("data-to")) for p in svg.findall(f"{SVG}path") if p.get("class") == "edge"}
    assert ("/planner", "/cmd_vel") in edges and ("/odom", "/planner") in edges and len(edges) == 8
    red = [g.get("data-name") for g in groups if g.find(f"{SVG}rect") is not None and g.find(f"{SVG}rect").get("stroke") == "#c00"]
    assert red == ["/cmd_vel"]
    assert "/rosout" in graph_html(make_graph(), include_debug=True)
