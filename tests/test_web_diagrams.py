"""The pictures drawn on the server as inline SVG: a class among its superclasses, subclasses and parts on
its page, and a plan's data flow on the plans page. Every box is a link that resolves; text is escaped;
the JSON twins carry the same facts as lists, without the markup."""

from __future__ import annotations

import itertools
import re
import xml.etree.ElementTree as ET
from html import unescape

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, diagram, taxonomy
from cbrs.web.plans import _flow

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def picture(page: str) -> ET.Element:
    found = re.search(r'<svg class="diagram".*?</svg>', page, re.S)
    assert found is not None, "no picture on the page"
    return ET.fromstring(found.group(0))  # well-formed XML, or this fails


def boxes(svg: ET.Element) -> dict[str, str]:
    """Each linked box's text (its lines joined by a space) -> its href."""
    return {
        " ".join("".join(t.itertext()) for t in a.iter(SVG + "tspan") if t.get("x")): a.get("href", "")
        for a in svg.iter(SVG + "a")
    }


def test_the_class_page_draws_the_class_among_its_ancestors_subclasses_and_parts(client: FlaskClient) -> None:
    page = client.get("/taxonomy/class", query_string={"iri": "home:Position"}).text
    svg = picture(page)
    # a group, not role="img", which would hide the links inside from screen readers
    assert svg.get("role") == "group" and svg.find(SVG + "title") is not None
    description = svg.find(SVG + "desc")
    assert description is not None and "direct subclasses" in (description.text or "")
    assert all(a.find(SVG + "title") is not None for a in svg.iter(SVG + "a"))  # each link has a name
    drawn = boxes(svg)
    assert {"owl:Thing", "home:SpatialData", "home:Position"} <= set(drawn)  # the path up, and itself
    assert {"home:RobotPosition", "home:Position2D"} <= set(drawn)  # its subclasses
    assert {"home:XCoordinate", "home:YCoordinate", "home:Theta"} <= set(drawn)  # its parts
    dashed = [line for line in svg.iter(SVG + "polyline") if line.get("stroke-dasharray")]
    assert len(dashed) == 3  # one dashed arrow per part
    assert_no_arrow_runs_under_a_box(svg)
    assert drawn["home:Position2D"] == "/taxonomy/class?iri=home:Position2D"
    for href in set(drawn.values()):
        assert client.get(unescape(href)).status_code == 200, href


def rectangles(svg: ET.Element) -> list[tuple[float, float, float, float]]:
    return [
        (float(r.get("x", 0)), float(r.get("y", 0)), float(r.get("width", 0)), float(r.get("height", 0)))
        for r in svg.iter(SVG + "rect")
    ]


def crosses(a: tuple[float, float], b: tuple[float, float], box: tuple[float, float, float, float]) -> bool:
    """Whether the segment a-b passes through the inside of the box (its edges are where arrows end)."""
    x, y, w, h = box
    inset = 1.0
    left, right, top, bottom = x + inset, x + w - inset, y + inset, y + h - inset
    t0, t1 = 0.0, 1.0
    dx, dy = b[0] - a[0], b[1] - a[1]
    for p, q in ((-dx, a[0] - left), (dx, right - a[0]), (-dy, a[1] - top), (dy, bottom - a[1])):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return False
    return True


def assert_no_arrow_runs_under_a_box(svg: ET.Element) -> None:
    boxes_drawn = rectangles(svg)
    for line in svg.iter(SVG + "polyline"):
        points = [tuple(map(float, p.split(","))) for p in line.get("points", "").split()]
        for a, b in itertools.pairwise(points):
            assert not any(crosses(a, b, box) for box in boxes_drawn), (a, b)  # type: ignore[arg-type]


def test_the_twin_has_no_picture(client: FlaskClient) -> None:
    body = client.get("/taxonomy/class.json", query_string={"iri": "home:Position"}).get_json()
    assert "picture" not in body and body["subclasses"]


def test_subclasses_past_the_row_are_one_box_that_opens_the_tree(
    client: FlaskClient, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(taxonomy, "MAX_PICTURE_ROW", 2)
    body = client.get("/taxonomy/class.json", query_string={"iri": "home:Position"}).get_json()
    drawn = boxes(picture(client.get("/taxonomy/class", query_string={"iri": "home:Position"}).text))
    rest = len(body["subclasses"]) - 2
    assert drawn[f"{rest} more"] == "/taxonomy?root=home:Position"
    assert len([name for name in drawn if name in {s["name"] for s in body["subclasses"]}]) == 2


def test_the_plan_page_draws_the_data_flow(client: FlaskClient) -> None:
    body = client.get("/plans.json", query_string={"task": "FetchMyPen"}).get_json()
    assert "flow" not in body
    steps = body["composition"]["steps"]
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    svg = picture(page)
    drawn = boxes(svg)
    assert sorted(drawn.values()) == sorted(f"#step-{s['index']}" for s in steps)
    for href in drawn.values():
        assert f'id="{href[1:]}"' in page  # each box opens its row of the table
    # one arrow per input, precondition and goal
    bindings = sum(len(s["inputs"]) + len(s["preconditions"]) for s in steps) + len(body["composition"]["goals"])
    assert len(list(svg.iter(SVG + "polyline"))) == bindings
    assert_no_arrow_runs_under_a_box(svg)
    heads = [line.get("points", "").split()[-1] for line in svg.iter(SVG + "polyline")]
    assert len(set(heads)) == len(heads)  # arrows into one box spread over its side, not onto one point
    # a step is drawn below every step it takes something from
    y = {a.get("href"): float(next(a.iter(SVG + "rect")).get("y", "0")) for a in svg.iter(SVG + "a")}
    for step in steps:
        for binding in step["inputs"] + step["preconditions"]:
            if "step" in binding["from"]:
                assert y[f"#step-{binding['from']['step']}"] < y[f"#step-{step['index']}"]


def test_a_composition_without_steps_draws_nothing() -> None:
    assert _flow({"task": "urn:x", "steps": [], "goals": [], "unsatisfied": [{"text": "x"}]}) is None


def test_an_arrow_that_spans_rows_bends_past_the_boxes_between() -> None:
    rows = [[diagram.Box("top", "top", "t")], [diagram.Box(f"m{i}", f"middle {i}", "t") for i in range(3)]]
    rows.append([diagram.Box("bottom", "bottom", "t")])
    edges = [diagram.Edge("top", f"m{i}") for i in range(3)] + [diagram.Edge(f"m{i}", "bottom") for i in range(3)]
    edges.append(diagram.Edge("top", "bottom", "straight down"))
    svg = ET.fromstring(str(diagram.layered(rows, edges, "t", "d")))
    long = [p for p in svg.iter(SVG + "polyline") if p.find(SVG + "title").text == "straight down"]  # type: ignore[union-attr]
    assert len(long) == 1 and len(long[0].get("points", "").split()) == 4  # out, through the slot, in
    assert len(rectangles(svg)) == 5  # the waypoint is not drawn
    assert_no_arrow_runs_under_a_box(svg)


def test_text_and_links_are_escaped() -> None:
    rows = [[diagram.Box("a", 'x<script>"&', 'title "<b>"', '/p?a=1&b="2"')], [diagram.Box("b", "lab.owl#Thing", "t")]]
    svg = diagram.layered(rows, [diagram.Edge("b", "a", "<in>")], "t<", "d&")
    tree = ET.fromstring(str(svg))  # well-formed despite the markup characters
    assert "<script>" not in svg and "x&lt;script&gt;" in svg
    assert next(tree.iter(SVG + "a")).get("href") == '/p?a=1&b="2"'
    light = [t for t in tree.iter(SVG + "tspan") if t.get("fill-opacity")]
    assert ["".join(t.itertext()) for t in light] == ["lab.owl#"]  # the file part drawn lighter


def test_a_subtree_page_draws_its_root(client: FlaskClient) -> None:
    drawn = boxes(picture(client.get("/taxonomy", query_string={"root": "home:Position"}).text))
    assert {"home:SpatialData", "home:Position", "home:RobotPosition"} <= set(drawn)
    assert "picture" not in client.get("/taxonomy.json", query_string={"root": "home:Position"}).get_json()
    assert '<svg class="diagram"' not in client.get("/taxonomy").text


def test_a_property_s_picture_speaks_of_subproperties(client: FlaskClient) -> None:
    svg = picture(client.get("/taxonomy/class", query_string={"iri": "home:hasXCoordinate"}).text)
    description = svg.find(SVG + "desc")
    assert description is not None and "direct subproperties" in (description.text or "")
