"""The home drawn from the store before anything runs (cbrs.home_plan, the browser's /home, cbrs home):
every thing of the map is a link with a tooltip, a thing the world graph places elsewhere is drawn at
both places, labels are escaped, and a map the simulation would refuse is explained, not a 500. No
simulation: the map is read from in-memory stores."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import quote

import pytest
from click.testing import CliRunner

from cbrs.actions.belief import BeliefState, Observation
from cbrs.app import App
from cbrs.cli import cli
from cbrs.cli_home import home
from cbrs.home_plan import draw_home, resource_link, survey
from cbrs.kb import KnowledgeBase
from cbrs.kb.camera_view import default_image_size, floor_view, image_up
from cbrs.kb.namespaces import RDFS
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

SVG = "{http://www.w3.org/2000/svg}"
WORLD = "https://w3id.org/cbrs/world#"
SVC = "https://w3id.org/cbrs/service#"
FLAT_FILE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "studio_flat" / "home.ttl"
FLAT = "https://example.org/studio-flat#"


BASE_OUTSIDE = (
    "PREFIX home: <https://w3id.org/cbrs/home#> PREFIX svc: <https://w3id.org/cbrs/service#> "
    "DELETE { GRAPH graph:map { svc:P3DX01 home:x ?x } } INSERT { GRAPH graph:map { svc:P3DX01 home:x 30.0 } } "
    "WHERE { GRAPH graph:map { svc:P3DX01 home:x ?x } }"
)


def links(svg: str) -> dict[str, list[ET.Element]]:
    """The picture's links by the IRI they open, each with its shapes; every link has a title."""
    found: dict[str, list[ET.Element]] = {}
    for a in ET.fromstring(svg).iter(SVG + "a"):
        href = a.get("href") or ""
        assert a.find(SVG + "title") is not None and (a.find(SVG + "title").text or "").strip(), href  # type: ignore[union-attr]
        iri = re.sub(r"%([0-9A-F]{2})", lambda m: chr(int(m.group(1), 16)), href.split("iri=", 1)[1])
        found.setdefault(iri, []).append(a)
    return found


def centre(shape: ET.Element) -> tuple[float, float]:
    """A drawn shape's middle in pixels (a polygon's corners' mean, a circle's centre)."""
    if shape.tag == SVG + "circle":
        return float(shape.get("cx", 0)), float(shape.get("cy", 0))
    points = [tuple(map(float, p.split(","))) for p in (shape.get("points") or "").split()]
    return sum(p[0] for p in points) / len(points), sum(p[1] for p in points) / len(points)


@pytest.fixture(scope="module")
def bundled_map(bundled_kb: KnowledgeBase) -> SemanticMap:
    found = survey(bundled_kb)
    assert found.verdict == "ok", found.problem
    assert found.semantic_map is not None
    return found.semantic_map


def test_every_thing_of_the_bundled_home_is_a_link_with_a_tooltip(bundled_map: SemanticMap) -> None:
    picture = draw_home(bundled_map)
    drawn = links(picture.svg)
    smap = bundled_map
    wanted = {
        "room": smap.rooms & smap.things.keys(),
        "furniture": set(smap.furniture),
        "object": set(smap.objects),
        "robot": set(smap.robots) | {SVC + "CytonDualArm01"},
        "arm": set(smap.arms),
        "person": set(smap.people),
        "camera": set(smap.cameras),
        "dock": {WORLD + "KitchenTableDock"},
    }
    for kind, iris in wanted.items():
        assert iris, kind
        for iri in iris:
            assert iri in drawn, f"{kind} {iri} is not drawn as a link"
            assert drawn[iri][0].get("href") == resource_link(iri)
    assert {SVC + "CeilingCamera01", SVC + "CeilingCamera02", SVC + "Kinect01"} <= drawn.keys()
    title = drawn[WORLD + "KitchenTable"][0].find(SVG + "title")
    assert title is not None and "top at 0.75 m" in (title.text or "")
    views = [a for a in drawn[SVC + "CeilingCamera01"] if a.get("class") == "home-camera-view"]
    assert len(views) == 1, "a ceiling camera's floor is drawn"
    assert {e.kind for e in picture.entries} >= {"room", "wall", "furniture", "object", "person", "camera", "arm"}


def test_a_ceiling_camera_sees_the_floor_its_field_of_view_and_height_give(bundled_map: SemanticMap) -> None:
    camera = bundled_map.cameras[SVC + "CeilingCamera01"]  # 4.5 m up, 90 degrees, a 4:3 image, top to the north
    corners = floor_view(camera)
    assert corners is not None
    xs, ys = sorted({round(x, 6) for x, _ in corners}), sorted({round(y, 6) for _, y in corners})
    assert xs == [4.5 - 6.0, 4.5 + 6.0] and ys == [2.5 - 4.5, 2.5 + 4.5]
    assert floor_view(dataclasses.replace(camera, far=4.0)) is None, "the floor beyond its range is not seen"


def test_the_floor_a_camera_sees_is_what_the_simulations_camera_model_images() -> None:
    """The corners :func:`floor_view` gives fall on the corners of the image the simulation's camera
    renders (its calibration, sim.cameras): the picture and the simulation share one camera model."""
    cameras = pytest.importorskip("cbrs.sim.cameras")
    from cbrs.sim.layout import CameraSpec

    smap = SemanticMap.read(KnowledgeBase.open(":memory:"))
    for camera in (
        smap.cameras[SVC + "CeilingCamera01"],
        dataclasses.replace(smap.cameras[SVC + "CeilingCamera02"], yaw=0.3),
    ):
        width, height = default_image_size(camera)
        target = tuple(p + d for p, d in zip(camera.position, camera.direction, strict=True))
        spec = CameraSpec("c", camera.position, target, image_up(camera), width, height, camera.fov)  # type: ignore[arg-type]
        corners = floor_view(camera)
        assert corners is not None
        pixels = cameras.project(
            cameras.Intrinsics.from_fov(width, height, camera.fov),
            cameras.camera_to_world(spec),
            [[x, y, 0.0] for x, y in corners],
        )
        expected = [(0, 0), (width, 0), (width, height), (0, height)]  # top left first, clockwise
        for (u, v), (eu, ev) in zip(pixels.tolist(), expected, strict=True):
            assert math.hypot(u - eu, v - (ev - 1)) < 1e-6, (camera.name, pixels)  # the renderer samples v + 1


def test_a_thing_the_world_graph_places_elsewhere_is_drawn_at_both_places() -> None:
    kb = KnowledgeBase.open(":memory:")
    pen, start = WORLD + "Pen", (8.07, 3.30)
    BeliefState(kb).write(Observation(positions={pen: (2.3, 3.4, 0.5), WORLD + "Cup": (7.46, 3.32, 0.8)}))
    found = survey(kb)
    assert found.semantic_map is not None
    picture = draw_home(found.semantic_map, found.believed)
    shapes = [el for el in links(picture.svg)[pen][0] if el.tag in (SVG + "polygon", SVG + "circle")]
    assert len(shapes) == 2, "the pen at its start and where it is believed to be"
    (x0, y0), (x1, y1) = centre(shapes[0]), centre(shapes[1])
    dx, dy = 2.3 - start[0], 3.4 - start[1]
    scale = (x1 - x0) / dx
    assert scale > 0 and abs((y1 - y0) - (-dy * scale)) < 0.5, "y is up: north is the top of the picture"
    arrows = [el for el in links(picture.svg)[pen][0] if el.get("class") == "home-belief"]
    assert len(arrows) == 1
    cup = [el for el in links(picture.svg)[WORLD + "Cup"][0] if el.tag == SVG + "circle"]
    assert len(cup) == 1, "a centimetre from its start is no move"
    entry = next(e for e in picture.entries if e.iri == pen)
    assert entry.believed == (2.3, 3.4)


def test_labels_with_markup_characters_are_escaped(bundled_map: SemanticMap) -> None:
    label = 'Tom & Jerry\'s <kitchen> "east"'
    facts = dict(bundled_map.facts)
    facts[WORLD + "Kitchen"] = {**facts[WORLD + "Kitchen"], RDFS + "label": [label]}
    svg = draw_home(dataclasses.replace(bundled_map, facts=facts)).svg
    assert "<kitchen>" not in svg
    title = links(svg)[WORLD + "Kitchen"][0].find(SVG + "title")
    assert title is not None and label in (title.text or "")


def test_the_page_shows_the_picture_and_the_things(bundled_kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(bundled_kb)).test_client()
    body = client.get("/home.json").get_json()
    assert body["verdict"] == "ok" and body["problem"] is None
    assert body["counts"]["rooms"] == 3 and body["counts"]["people"] == 1
    assert {t["name"] for t in body["things"]} >= {"Kitchen", "KitchenTable", "Cup", "Pen", "Person", "P3DX01"}
    page = client.get("/home")
    assert page.status_code == 200
    html = page.get_data(as_text=True)
    assert '<svg xmlns="http://www.w3.org/2000/svg" class="home-plan"' in html
    assert 'href="/home"' in html, "the navigation links the page"
    svg = client.get("/home.svg")
    assert svg.mimetype == "image/svg+xml" and WORLD + "Cup" in links(svg.get_data(as_text=True))


def test_the_page_says_why_the_simulation_would_refuse_the_home_and_what_cannot_be_read() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(BASE_OUTSIDE, check_map=False)  # a home of no base is taken (tests/test_no_base.py); this is not
    client = create_app(SparqlService(kb)).test_client()
    body = client.get("/home.json").get_json()  # 200: the home's problem is what the page shows
    assert body["verdict"] == "refused" and body["problem"]["kind"] == "HomeError"
    assert "starts at (30.00, 1.50), in no room of the map" in body["problem"]["message"]
    assert body["picture"] is not None, "what the map holds is drawn all the same"
    page = client.get("/home")
    assert page.status_code == 200 and "in no room of the map" in page.get_data(as_text=True)

    kb.update(
        f'INSERT DATA {{ GRAPH graph:map {{ <{WORLD}Pen> <https://w3id.org/cbrs/home#yaw> "north" }} }}',
        check_map=False,
    )
    body = client.get("/home.json").get_json()
    assert body["verdict"] == "unreadable" and body["picture"] is None
    assert "home:yaw 'north', not a number" in body["problem"]["message"]
    page = client.get("/home")
    assert page.status_code == 200 and "home:yaw &#39;north&#39;, not a number" in page.get_data(as_text=True)
    assert client.get("/home.svg").status_code == 404


def test_cbrs_home_summarises_the_home_and_draws_it(tmp_path: Path) -> None:
    drawing = tmp_path / "home.svg"
    done = CliRunner().invoke(cli, ["--store", ":memory:", "home", "--draw", str(drawing)])
    assert done.exit_code == 0, done.output
    assert "3 rooms, 10 walls, 1 piece of furniture, 2 objects, 1 mobile robot, 1 stationary robot" in done.output
    assert "1 person, 3 cameras, 1 docking pose" in done.output
    assert "check: the simulation can build this home" in done.output
    said = json.loads(CliRunner().invoke(cli, ["--store", ":memory:", "home", "--json"]).output)
    assert said["verdict"] == "ok" and said["counts"]["cameras"] == 3 and said["problem"] is None
    drawn = links(drawing.read_text(encoding="utf-8"))
    assert drawn[WORLD + "Cup"][0].get("href") == "http://127.0.0.1:8080/resource?iri=" + quote(WORLD + "Cup", safe="")


def test_the_studio_flat_replacing_the_home_draws_too() -> None:
    """The flat loaded as ``cbrs load --graph map --replace`` loads it (the same call, in memory: the
    command's own test is tests/test_home_of_your_own.py), then the page and its picture."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([FLAT_FILE], "map", replace=True)
    body = create_app(SparqlService(kb)).test_client().get("/home.json").get_json()
    assert body["verdict"] == "ok" and body["counts"]["rooms"] == 2
    assert {t["name"] for t in body["things"] if t["kind"] == "room"} == {"Kitchenette", "Studio"}
    found = survey(kb)
    assert found.semantic_map is not None
    drawn = links(draw_home(found.semantic_map).svg)
    for name in ("Studio", "Kitchenette", "Sofa", "Worktop", "Dispenser", "Mug", "Biro", "Novel", "Resident"):
        assert FLAT + name in drawn, name
    assert WORLD + "Cup" not in drawn, "the bundled home is gone"


def test_cbrs_home_exits_1_with_the_check_s_message_and_draws_what_is_there(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(BASE_OUTSIDE, check_map=False)  # a home of no base is taken (tests/test_no_base.py); this is not
    drawing = tmp_path / "home.svg"
    done = CliRunner().invoke(home, ["--draw", str(drawing)], obj=App(":memory:", kb))  # this store, as opened
    assert done.exit_code == 1
    assert "1 mobile robot" in done.output and "check: the simulation would refuse this home" in done.output
    assert "P3DX01 (https://w3id.org/cbrs/service#P3DX01) starts at (30.00, 1.50), in no room" in done.output
    assert WORLD + "Cup" in links(drawing.read_text(encoding="utf-8"))
