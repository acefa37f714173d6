"""A map with no rooms, drawn (cbrs.home_plan, the browser's /home, cbrs home): it says so instead of a
2 x 2 m grid with nothing on it. An emptied map (``DROP GRAPH graph:map``) is read as one until the store
is opened again; a map being built a file at a time may have furniture before its rooms. No simulation."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from urllib.parse import unquote

from click.testing import CliRunner

from cbrs.app import App
from cbrs.cli_home import home
from cbrs.home_canvas import MARGIN
from cbrs.home_plan import NO_ROOMS, draw_home, survey
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import Box, SemanticMap, Thing
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

SVG = "{http://www.w3.org/2000/svg}"
WORLD = "https://w3id.org/cbrs/world#"


def _texts(svg: str) -> str:
    return " ".join(text.text or "" for text in ET.fromstring(svg).iter(SVG + "text"))


def test_an_emptied_map_is_a_notice_not_an_empty_grid(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update("DROP GRAPH graph:map", check_map=False)
    drawing = tmp_path / "home.svg"
    done = CliRunner().invoke(home, ["--draw", str(drawing)], obj=App(":memory:", kb))
    assert done.exit_code == 1  # the simulation cannot build it
    assert "home: 0 rooms" in done.output and f"  {NO_ROOMS}" in done.output
    assert f"drew what the map places, under that notice, to {drawing}" in done.output
    picture = ET.fromstring(drawing.read_text(encoding="utf-8"))
    assert "The map has no rooms (no home:Room with home:minX" in _texts(drawing.read_text(encoding="utf-8"))
    assert int(picture.get("height", 0)) < 200, "no plan, no legend"
    assert not list(picture.iter(SVG + "a")) and not list(picture.iter(SVG + "g")), "no links, no metre grid"
    client = create_app(SparqlService(kb)).test_client()
    assert "The map has no rooms" in client.get("/home").get_data(as_text=True)
    assert client.get("/home.json").get_json()["counts"]["rooms"] == 0


def test_a_map_without_rooms_draws_what_it_places_under_the_notice() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(  # the rooms lose their extents: the walls, furniture and robots stay
        "DELETE { GRAPH graph:map { ?room home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d } } "
        "WHERE { VALUES ?room { world:LivingRoom world:Kitchen world:Bedroom } "
        "GRAPH graph:map { ?room home:minX ?a ; home:maxX ?b ; home:minY ?c ; home:maxY ?d } }",
        check_map=False,
    )
    found = survey(kb)
    assert found.semantic_map is not None and found.semantic_map.things
    picture = draw_home(found.semantic_map)
    assert picture.notice == NO_ROOMS
    root = ET.fromstring(picture.svg)
    notice = [t for t in root.iter(SVG + "text") if t.get("class") == "home-notice"]
    table = next(a for a in root.iter(SVG + "a") if unquote(a.get("href") or "").endswith(WORLD + "KitchenTable"))
    top = float(next(table.iter(SVG + "rect")).get("y", 0))
    assert notice and max(float(t.get("y", 0)) for t in notice) < top, "the notice is above the plan"
    assert not any(entry.kind == "room" for entry in picture.entries)


def test_one_small_thing_alone_is_drawn_to_a_sensible_scale() -> None:
    """A 10 cm box was drawn 0.7 m across the picture (its extent and 30 cm around it): 1,250 px a metre."""
    box = Thing("urn:lab#Stool", (), Box(1.0, 1.1, 1.0, 1.1, 0.0, 0.4))
    picture = draw_home(SemanticMap(things={box.iri: box}, furniture=frozenset({box.iri})), width=600)
    drawn = next(a for a in ET.fromstring(picture.svg).iter(SVG + "a") if "Stool" in (a.get("href") or ""))
    width_px = float(next(drawn.iter(SVG + "rect")).get("width", 0))
    assert width_px == round(0.1 * (600 - 2 * MARGIN) / 2.0, 1)  # the picture shows 2 m across
