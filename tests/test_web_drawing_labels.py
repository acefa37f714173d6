"""The plans page's two pictures keep their labels apart: the data flow's arrow names (FetchMyPen's
``graspPose`` and ``objectPosition`` lay on one another where both arrows enter #10) and the service
resource graph's titles (PutCupBelowOfTapOfWaterDispenser's suptitle over its subplot's title).

The flow's label boxes are estimated here as a browser draws them (10 px DejaVu Sans: at most 6 px a
character of these names, 9 px above the baseline and 2 below); the graph's are measured by matplotlib.
"""

from __future__ import annotations

import itertools
import re
import xml.etree.ElementTree as ET

import matplotlib.pyplot as plt
import pytest
from flask.testing import FlaskClient

from cbrs.actions.composer import Composer
from cbrs.actions.draw import figure
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, diagram

SVG = "{http://www.w3.org/2000/svg}"
Rect = tuple[float, float, float, float]


def overlapping(rects: list[Rect]) -> list[tuple[Rect, Rect]]:
    return [
        (a, b)
        for a, b in itertools.combinations(rects, 2)
        if a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
    ]


def arrow_labels(svg: ET.Element) -> list[Rect]:
    found = []
    for text in svg.iter(SVG + "text"):
        if text.get("font-size") == "10":
            x, y, width = float(text.get("x", 0)), float(text.get("y", 0)), len("".join(text.itertext())) * 6.0
            found.append((x - width / 2, y - 9, x + width / 2, y + 2))
    return found


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_the_data_flow_s_arrow_names_lie_apart_and_off_the_boxes(client: FlaskClient) -> None:
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    found = re.search(r'<svg class="diagram".*?</svg>', page, re.S)
    assert found is not None
    svg = ET.fromstring(found.group(0))
    labels = arrow_labels(svg)
    assert len(labels) == 21  # one per input bound, none dropped to make room
    assert overlapping(labels) == []
    boxes = [
        (
            float(r.get("x", 0)),
            float(r.get("y", 0)),
            float(r.get("x", 0)) + float(r.get("width", 0)),
            float(r.get("y", 0)) + float(r.get("height", 0)),
        )
        for r in svg.iter(SVG + "rect")
    ]
    assert [(label, box) for label in labels for box in boxes if overlapping([label, box])] == []


def test_arrows_converging_on_one_box_get_their_names_one_above_the_other() -> None:
    rows = [[diagram.Box("a", "a", "a"), diagram.Box("b", "b", "b")], [diagram.Box("c", "c", "c")]]
    edges = [diagram.Edge("a", "c", "objectPosition"), diagram.Edge("b", "c", "graspPose")]
    svg = ET.fromstring(str(diagram.layered(rows, edges, "t", "d")))
    assert overlapping(arrow_labels(svg)) == []


def test_the_service_resource_graph_s_texts_lie_apart(bundled_kb: KnowledgeBase) -> None:
    drawn = figure(Composer(bundled_kb).compose("PutCupBelowOfTapOfWaterDispenser"))
    try:
        drawn.canvas.draw()
        renderer = drawn.canvas.get_renderer()  # type: ignore[attr-defined]
        texts = [t for axis in drawn.axes for t in (axis.title, *axis.texts) if t.get_text()]
        texts += [t for legend in drawn.legends for t in legend.get_texts()]
        texts += list(drawn.texts)  # the suptitle
        rects = []
        for text in texts:
            shape = text.get_bbox_patch() or text
            extent = shape.get_window_extent(renderer)
            rects.append((extent.x0, extent.y0, extent.x1, extent.y1))
        assert len(rects) > 10 and overlapping(rects) == []
    finally:
        plt.close(drawn)


def test_the_service_resource_graph_gives_no_room_to_levels_with_nothing_drawn(bundled_kb: KnowledgeBase) -> None:
    """RobotSelfPosition's vertices are on 2 of the search's 10 levels; the drawing spread them over all
    10, so that most of it was empty, and columns as wide as their names made such a drawing wider still."""
    drawn = figure(Composer(bundled_kb).compose("RobotSelfPosition"))
    try:
        (axis,) = drawn.axes
        columns = sorted({text.get_position()[0] for text in axis.texts})
        assert columns == list(range(len(columns))) and len(columns) <= 3
        assert axis.get_xlim() == pytest.approx((-0.7, len(columns) - 1 + 0.7))
    finally:
        plt.close(drawn)
