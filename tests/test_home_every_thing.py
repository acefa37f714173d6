"""Every physical thing of the map is on the home's pages (cbrs.home_things, cbrs.home_plan, /home, /search,
cbrs home): the lab's reading lamp (docs/examples/lab10_reading_lamp.ttl, a home:Lamp with an extent) was on
no page and the search found nothing of it. Also a thing with a position and no extent, a thing of a lab's
own class straight under home:PhysicalObject, and the bundled home's page unchanged but for its tap lever
and spout. And the plans page heads a lab's task by its shown name. No simulation: in-memory stores, one
app per module."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.app import App
from cbrs.cli_home import home
from cbrs.home_plan import draw_home, survey
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

SVG = "{http://www.w3.org/2000/svg}"
LAB10, LAB = "https://example.org/lab10#", "https://example.org/lab-every#"
WORLD = "https://w3id.org/cbrs/world#"

LAB_THINGS = f"""@prefix home: <{PREFIXES["home"]}> .
@prefix lab: <{LAB}> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
lab:Thermostat a owl:Class ; rdfs:subClassOf home:Sensor ; rdfs:label "thermostat"@en .
lab:FloorGizmo a owl:Class ; rdfs:subClassOf home:PhysicalObject .
lab:Thermostat1 a lab:Thermostat , owl:NamedIndividual ; home:x 3.0 ; home:y 8.5 ; home:z 1.5 .
lab:Gizmo1 a lab:FloorGizmo , owl:NamedIndividual ; rdfs:label "the lab's gizmo"@en ;
    home:minX 1.0 ; home:maxX 1.4 ; home:minY 7.0 ; home:maxY 7.2 ; home:minZ 0.0 ; home:maxZ 0.3 .
"""


@pytest.fixture(scope="module")
def lab_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    """The bundled home with the lab's lamp, a thermostat placed by a point and a gizmo of the lab's own
    class, each loaded into the ontology and the map as a lab does."""
    things = tmp_path_factory.mktemp("every") / "lab_things.ttl"
    things.write_text(LAB_THINGS, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for path in (EXAMPLES / "lab10_reading_lamp.ttl", things):
        for graph in ("ontology", "map"):
            kb.load([path], graph=graph)
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def client(lab_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(lab_kb)).test_client()


@pytest.fixture(scope="module")
def home_json(client: FlaskClient) -> dict[str, Any]:
    body: dict[str, Any] = client.get("/home.json").get_json()
    return body


@pytest.fixture(scope="module")
def svg(client: FlaskClient) -> ET.Element:
    return ET.fromstring(client.get("/home.svg").get_data(as_text=True))


def _thing(body: dict[str, Any], iri: str) -> dict[str, Any]:
    found = [t for t in body["things"] if t["iri"] == iri]
    assert len(found) == 1, [t["name"] for t in body["things"]]
    return found[0]


def _link(svg: ET.Element, iri: str) -> ET.Element:
    """The picture's link to ``iri`` (one), with its tooltip."""
    found = [a for a in svg.iter(SVG + "a") if unquote((a.get("href") or "").partition("iri=")[2]) == iri]
    assert len(found) == 1, iri
    return found[0]


def _metres_to_px(svg: ET.Element) -> tuple[float, float, float]:
    """The picture's scale (px a metre) and where x = 0 and y = 0 fall, from the Bedroom's rectangle
    (x 0 to 6, y 5 to 9 in the bundled map)."""
    rect = _link(svg, WORLD + "Bedroom").find(SVG + "rect")
    assert rect is not None
    scale = float(rect.get("width", 0)) / 6.0
    left, top = float(rect.get("x", 0)), float(rect.get("y", 0))
    return scale, left, top + 9.0 * scale


def _search(client: FlaskClient, text: str) -> dict[str, Any]:
    body: dict[str, Any] = client.get("/search.json", query_string={"q": text}).get_json()
    return body


def test_the_labs_lamp_is_listed_with_the_appliances_drawn_by_its_extent_and_found(
    client: FlaskClient, home_json: dict[str, Any], svg: ET.Element
) -> None:
    lamp = _thing(home_json, LAB10 + "ReadingLamp1")
    assert lamp["kind"] == "appliance" and lamp["room"] == "LivingRoom"  # a home:Lamp, below home:Appliance
    assert lamp["where"] == "x 0.4 to 0.7, y 0.4 to 0.7, top at 1.5 m" and lamp["shown"] == "lab10:ReadingLamp1"
    kinds = [t["kind"] for t in home_json["things"]]
    appliances = [t["name"] for t in home_json["things"] if t["kind"] == "appliance"]
    assert appliances == ["WaterDispenser01", "ReadingLamp1"]  # the dispenser's kind comes from its class too
    first = kinds.index("appliance")
    assert kinds[first : first + 2] == ["appliance", "appliance"]  # grouped: the lamp beside the dispenser
    assert home_json["counts"]["appliances"] == 2 and "2 appliances" in home_json["counted"]

    drawn = _link(svg, LAB10 + "ReadingLamp1")
    title = drawn.findtext(SVG + "title") or ""
    assert title.startswith("ReadingLamp1 (reading lamp by the sofa): appliance, x 0.4 to 0.7")
    rect = drawn.find(SVG + "rect")
    assert rect is not None
    scale, x0, y0 = _metres_to_px(svg)
    assert float(rect.get("x", 0)) == pytest.approx(x0 + 0.4 * scale, abs=0.1)
    assert float(rect.get("y", 0)) == pytest.approx(y0 - 0.7 * scale, abs=0.1)
    assert float(rect.get("width", 0)) == pytest.approx(0.3 * scale, abs=0.1)
    assert drawn.findtext(SVG + "text") == "ReadingLamp1"

    by_name = _search(client, "ReadingLamp1")
    assert by_name["things"]["count"] == 1 and by_name["total"] >= 1
    by_label = _search(client, "reading lamp")
    assert by_label["terms"]["count"] == 1  # the class lab10:ReadingLamp, as before
    (match,) = by_label["things"]["matches"]
    assert match["name"] == "lab10:ReadingLamp1" and match["kind"] == "appliance" and match["room"] == "LivingRoom"


def test_a_thing_with_a_position_and_no_extent_is_a_mark_at_its_position(
    client: FlaskClient, home_json: dict[str, Any], svg: ET.Element
) -> None:
    thermostat = _thing(home_json, LAB + "Thermostat1")
    assert thermostat["kind"] == "device"  # lab:Thermostat < home:Sensor < home:Device < home:Artifact
    assert thermostat["where"] == "at (3, 8.5, 1.5)" and thermostat["room"] == "Bedroom"
    mark = _link(svg, LAB + "Thermostat1").find(SVG + "polygon")
    assert mark is not None
    corners = [tuple(map(float, p.split(","))) for p in (mark.get("points") or "").split()]
    scale, x0, y0 = _metres_to_px(svg)
    assert sum(c[0] for c in corners) / 4 == pytest.approx(x0 + 3.0 * scale, abs=0.2)
    assert sum(c[1] for c in corners) / 4 == pytest.approx(y0 - 8.5 * scale, abs=0.2)
    assert _search(client, "thermostat1")["things"]["matches"][0]["kind"] == "device"


def test_a_thing_of_the_labs_own_class_under_physical_object_is_its_own_kind(
    client: FlaskClient, home_json: dict[str, Any], svg: ET.Element
) -> None:
    gizmo = _thing(home_json, LAB + "Gizmo1")
    assert gizmo["kind"] == "floor gizmo"  # the class has no label: its local name in words
    assert gizmo["room"] == "Bedroom" and gizmo["classes"] == ["lab-every:FloorGizmo"]  # as the pages name it
    assert (_link(svg, LAB + "Gizmo1").findtext(SVG + "title") or "").startswith(
        "Gizmo1 (the lab's gizmo): floor gizmo"
    )
    assert [m["local"] for m in _search(client, "gizmo")["things"]["matches"]] == ["Gizmo1"]
    assert home_json["counts"]["floor gizmos"] == 1 and "1 floor gizmo" in home_json["counted"]


def test_cbrs_home_counts_them_and_draws_them(lab_kb: KnowledgeBase, tmp_path: Path) -> None:
    drawing = tmp_path / "home.svg"
    done = CliRunner().invoke(home, ["--draw", str(drawing)], obj=App(":memory:", lab_kb))
    first = done.output.splitlines()[0]
    assert "1 device" in first and "2 appliances" in first and "1 floor gizmo" in first, done.output
    assert "lab-every%23Gizmo1" in drawing.read_text("utf-8") and "lab10%23ReadingLamp1" in drawing.read_text("utf-8")


def test_the_bundled_home_gains_only_its_tap_lever_and_spout(bundled_kb: KnowledgeBase) -> None:
    """What the bundled page listed stays as it was, in its order; the lever and spout of the water
    dispenser are added, unlabelled outlines whose tooltips say whose part they are. Its regions (below the
    tap, the table's top) and docking pose are places, not physical things, and stay out."""
    found = survey(bundled_kb)
    picture = found.picture()
    added = {WORLD + "Tap01", WORLD + "Spout01"}
    assert found.semantic_map is not None
    before = draw_home(found.semantic_map, found.believed).entries  # without the kinds: the page as it was
    assert [e for e in picture.entries if e.iri not in added] == list(before)
    kinds = list(dict.fromkeys(e.kind for e in picture.entries))
    assert kinds.index("appliance component") == kinds.index("appliance") + 1
    assert {e.iri for e in picture.entries if e.kind == "appliance component"} == added
    for entry in picture.entries:
        if entry.iri in added:
            assert entry.where.endswith("part of WaterDispenser01") and entry.room == "Kitchen"
    listed = {e.iri for e in picture.entries}
    assert not listed & {WORLD + "BelowOfTap", WORLD + "KitchenTableTop"}
    assert [e.kind for e in picture.entries if e.iri == WORLD + "KitchenTableDock"] == ["docking pose"]  # once
    root = ET.fromstring(picture.svg)
    lever = _link(root, WORLD + "Tap01")
    assert lever.find(SVG + "text") is None and lever.find(SVG + "rect").get("fill") == "none"  # type: ignore[union-attr]
    assert found.counts()["appliance components"] == 2 and found.counts()["appliances"] == 1


def test_the_plans_page_heads_a_labs_task_by_its_shown_name() -> None:
    """``/plans?task=`` with the IRI of a lab's task (what its list's option sends): the heading and the
    title said "Plan for https://example.org/lab5#FetchPenForVisitor"."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab5_visitor_in_kitchen.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab5_fetch_pen_for_visitor.ttl"], graph="requirements")
    page = (
        create_app(SparqlService(kb))
        .test_client()
        .get("/plans", query_string={"task": "https://example.org/lab5#FetchPenForVisitor"})
    )
    html = page.get_data(as_text=True)
    kb.close()
    assert re.search(r"<title>Plan for lab5:FetchPenForVisitor · cbrs</title>", html)
    assert "<h1>Plan for lab5:FetchPenForVisitor</h1>" in html
    assert "Plan for https://" not in html
