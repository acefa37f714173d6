"""The cameras' colour windows as knowledge (kb/colour_windows.py) and the warning for a thing painted where
they may not tell its colour (kb/colour_risk.py): read from the store by camera, its own or its class's or
home:Camera's; a bad window refused at the load; a paint inside, at an edge, outside, grey or dark said so by
cbrs load, cbrs update and a run's report, with no simulation run (the light's shading as the renderer
draws it: tests/test_run_colour_warnings.py)."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.colour_risk import (
    Risk,
    colour_risk,
    colour_risks,
    known_windows,
    written_colour_risks,
)
from cbrs.kb.colour_windows import (
    DEFAULT_HUE_MARGIN,
    SIMULATED_LIGHTING,
    ColourWindow,
    ColourWindowError,
    Lighting,
    hsv,
    read_colour_windows,
)
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.resources import ontology_dir

HOME, SVC, WORLD = PREFIXES["home"], PREFIXES["svc"], PREFIXES["world"]
APPLE = WORLD + "Apple"
PREAMBLE = """@prefix home: <https://w3id.org/cbrs/home#> .
@prefix svc: <https://w3id.org/cbrs/service#> .
@prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab: <http://example.org/lab#> .
"""
LAB_CAMERA = (
    PREAMBLE
    + """lab:TrolleyCamera a home:WebCamera ; home:x 8.4 ; home:y 2.75 ; home:z 1.6 ; home:fieldOfView 60.0 ;
    home:hasColourWindow lab:Orange , home:RedWindow .
lab:Orange a home:ColourWindow ; home:colourName "orange" ; home:hueCentre 30.0 ; home:hueTolerance 8.0 ;
    home:hueMargin 1.5 ; home:rgba "0.90 0.45 0.00 1" .
"""
)


def _apple(rgba: str, colour: str = "green") -> str:
    return (
        PREAMBLE
        + f"""world:Apple a home:Apple ; home:shapeKind "cylinder" ; home:sizeX 0.07 ; home:sizeY 0.07 ;
    home:sizeZ 0.07 ; home:massKg 0.1 ; home:colourName "{colour}" ; home:rgba "{rgba}" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.30 ; home:y 3.60 .
"""
    )


@pytest.fixture(scope="module")
def windows() -> list[ColourWindow]:
    """The bundled cameras' windows: the six home.ttl gives home:Camera."""
    kb = KnowledgeBase.open(":memory:")
    found = known_windows(kb)
    kb.close()
    return found


@pytest.fixture(scope="module")
def lab_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    """A bundled store with a lab's camera that names its own windows (orange, and the bundled red)."""
    path = tmp_path_factory.mktemp("lab") / "trolley_camera.ttl"
    path.write_text(LAB_CAMERA, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([path], "map")
    yield kb
    kb.close()


def test_each_camera_has_its_own_windows_else_home_cameras(lab_kb: KnowledgeBase) -> None:
    found = read_colour_windows(lab_kb)
    bundled = ["blue", "cyan", "green", "magenta", "red", "yellow"]
    for camera in ("CeilingCamera01", "CeilingCamera02", "Kinect01"):
        assert [window.name for window in found[SVC + camera]] == bundled
    own = found["http://example.org/lab#TrolleyCamera"]
    assert [(w.name, w.hue, w.hue_tolerance, w.hue_margin) for w in own] == [
        ("orange", 30.0, 8.0, 1.5),
        ("red", 0.0, 15.0, 3.0),
    ]
    assert own[0].min_saturation == 0.55 and own[0].rgba == (0.90, 0.45, 0.0, 1.0)  # the default floor
    assert read_colour_windows(lab_kb, SVC + "Kinect01") == {SVC + "Kinect01": found[SVC + "Kinect01"]}


def test_a_class_of_cameras_names_windows_for_its_individuals(tmp_path: Path) -> None:
    path = tmp_path / "model.ttl"
    path.write_text(
        PREAMBLE
        + """@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
lab:LabCam rdfs:subClassOf home:WebCamera ; home:hasColourWindow home:GreenWindow .
lab:Cam1 a lab:LabCam ; home:x 8.4 ; home:y 2.75 ; home:z 1.6 ; home:fieldOfView 60.0 .
""",
        encoding="utf-8",
    )
    kb = KnowledgeBase.open(":memory:")
    kb.load([path], "map")
    assert [w.name for w in read_colour_windows(kb)["http://example.org/lab#Cam1"]] == ["green"]
    kb.close()


def test_a_window_without_a_centre_is_refused_at_the_load(tmp_path: Path) -> None:
    path = tmp_path / "bad.ttl"
    path.write_text(LAB_CAMERA.replace("home:hueCentre 30.0 ; ", ""), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.count(GraphName.MAP.node)
    with pytest.raises(ColourWindowError) as refused:
        kb.load([path], "map")
    assert refused.value.window == "http://example.org/lab#Orange"
    assert "has no home:hueCentre" in str(refused.value)
    assert kb.store.count(GraphName.MAP.node) == before  # nothing written
    kb.close()


def test_hsv_is_the_segmentations_arithmetic() -> None:
    assert hsv((0.40, 0.80, 0.20, 1.0)) == pytest.approx((100.0, 0.75, 0.80))
    assert hsv((0.5, 0.5, 0.5, 1.0)) == (0.0, 0.0, 0.5)


@pytest.mark.parametrize(
    ("rgba", "risk", "said"),
    [
        pytest.param((0.10, 0.85, 0.15, 1.0), None, "", id="inside"),
        pytest.param((0.40, 0.80, 0.20, 1.0), Risk.EDGE, "hue 100°, within 3° of the edge", id="at-the-edge"),
        pytest.param((0.43, 0.80, 0.20, 1.0), Risk.EDGE, "hue 97°, within 3° of the edge", id="just-outside"),
        pytest.param((0.55, 0.85, 0.00, 1.0), Risk.OUTSIDE, "outside every window the cameras know", id="outside"),
        pytest.param(
            (0.50, 1.00, 0.00, 1.0), Risk.OUTSIDE, "outside green (100-150°) and every other", id="beside-its-own"
        ),
        pytest.param((0.90, 0.80, 0.10, 1.0), Risk.OUTSIDE, "in the window yellow (42-66°)", id="in-another"),
        pytest.param((0.50, 0.55, 0.50, 1.0), Risk.GREY, "saturation 0.09, below green's floor", id="grey"),
        pytest.param((0.02, 0.15, 0.03, 1.0), Risk.DARK, "brightness 0.15, seen at 0.15 on its lit top", id="dark"),
        # the floor is held to what the cameras see: the paint shaded by the simulated light, in bytes
        pytest.param((0.03, 0.203, 0.05, 1.0), Risk.DARK, "0.20, seen at 0.19 on its lit top, below", id="dark-lit"),
        pytest.param(
            (0.05, 0.30, 0.08, 1.0), Risk.SHADED, "0.30, seen at 0.18 on a face turned from the light", id="shaded"
        ),
        pytest.param((0.05, 0.35, 0.08, 1.0), None, "", id="bright-enough-in-shadow"),
    ],
)
def test_a_paint_is_held_to_its_colours_window(
    windows: list[ColourWindow], rgba: tuple[float, float, float, float], risk: Risk | None, said: str
) -> None:
    found = colour_risk(APPLE, "green", rgba, windows)
    if risk is None:
        assert found is None
        return
    assert found is not None and found.risk is risk
    assert found.text().startswith("world:Apple (green, home:rgba ") and said in found.text()
    assert "green (100-150°)" in found.text()  # the window it is held to
    assert found.to_dict()["risk"] == risk.value


def test_a_paint_is_seen_as_the_simulated_light_shades_it(windows: list[ColourWindow]) -> None:
    light = SIMULATED_LIGHTING
    assert light.lit == pytest.approx(0.6 + 0.4 / math.sqrt(1.13)) and light.shaded == 0.6
    assert light.factor((-1.0, 0.0, 0.0)) == 0.6  # a face turned from the light: the ambient part alone
    assert [round(light.seen(0.25, f) * 255) for f in (light.lit, light.shaded)] == [61, 37]  # measured bytes
    assert light.least(0.20, light.shaded) == pytest.approx(85 / 255)  # 85 * 0.6 = 51 = 0.20 of 255
    shaded = colour_risk(APPLE, "green", (0.05, 0.30, 0.08, 1.0), windows)
    assert shaded is not None and shaded.needed == pytest.approx(85 / 255) and "at least 0.33 bright" in shaded.text()
    assert shaded.to_dict()["seen"] == round(light.seen(0.30, 0.6), 3)
    brighter = Lighting(ambient=0.8, diffuse=0.2)  # another light: what the cameras see of the same paint
    assert colour_risk(APPLE, "green", (0.05, 0.30, 0.08, 1.0), windows, lighting=brighter) is None


def test_the_margin_is_the_windows_unless_given(windows: list[ColourWindow]) -> None:
    near = (0.35, 0.80, 0.20, 1.0)  # hue 105: 5 degrees inside green's edge
    assert DEFAULT_HUE_MARGIN == 3.0 and colour_risk(APPLE, "green", near, windows) is None
    edge = colour_risk(APPLE, "green", near, windows, margin=6.0)
    assert edge is not None and edge.risk is Risk.EDGE and "within 6° of the edge" in edge.text()


def test_an_unknown_colour_and_no_paint_are_said(windows: list[ColourWindow]) -> None:
    mauve = colour_risk(APPLE, "mauve", (0.6, 0.3, 0.6, 1.0), windows)
    assert mauve is not None and mauve.risk is Risk.UNKNOWN
    assert "no camera tells 'mauve' apart; the nearest window is magenta (280-320°)" in mauve.text()
    grey = colour_risk(APPLE, "green", None, windows)
    assert grey is not None and grey.risk is Risk.GREY and "no home:rgba (grey)" in grey.text()


def test_a_lab_cameras_own_window_is_held_to_its_margin(lab_kb: KnowledgeBase) -> None:
    orange = [w for w in known_windows(lab_kb) if w.name == "orange"]
    assert colour_risk(APPLE, "orange", (0.90, 0.45, 0.0, 1.0), orange) is None  # its own paint: hue 30
    edge = colour_risk(APPLE, "orange", (0.90, 0.59, 0.0, 1.0), orange)  # hue 39.3, 1.3 outside
    assert edge is not None and edge.risk is Risk.EDGE and "within 1.5° of the edge of the window orange" in edge.text()


def test_the_bundled_home_is_painted_well_inside(lab_kb: KnowledgeBase) -> None:
    assert colour_risks(lab_kb) == []


def test_a_write_is_checked_for_the_things_it_painted(windows: list[ColourWindow], tmp_path: Path) -> None:
    path = tmp_path / "apple.ttl"
    path.write_text(_apple("0.40 0.80 0.20 1"), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    report = kb.load([path], "map")
    quads = [quad for item in report.files for quad in item.quads]
    assert [risk.thing for risk in written_colour_risks(kb, quads)] == [APPLE]
    cup = [ox.Quad(ox.NamedNode(WORLD + "Cup"), ox.NamedNode(HOME + "rgba"), ox.Literal("x"), GraphName.MAP.node)]
    assert written_colour_risks(kb, cup) == []  # the cup is painted well inside red
    assert [r.thing for r in colour_risks(kb, {APPLE, WORLD + "Cup"})] == [APPLE]  # of those asked about
    kb.close()


def test_cbrs_load_warns_and_loads(tmp_path: Path) -> None:
    path = tmp_path / "apple.ttl"
    path.write_text(_apple("0.40 0.80 0.20 1"), encoding="utf-8")
    store = str(tmp_path / "store")
    result = CliRunner().invoke(cli, ["--store", store, "load", "--graph", "map", str(path)])
    assert result.exit_code == 0, result.output
    (line,) = [line for line in result.stderr.splitlines() if line.startswith("warning:") and " has hue " in line]
    assert line.startswith("warning: world:Apple (green, home:rgba 0.4 0.8 0.2 1) has hue 100°")
    assert "the edge of the window green (100-150°)" in line
    kb = KnowledgeBase.open(store)
    assert list(kb.store.quads(ox.NamedNode(APPLE), None, None, GraphName.MAP.node))  # loaded all the same
    kb.close()
    pear = _apple("0.10 0.85 0.15 1").replace("world:Apple", "world:Pear").replace("home:y 3.60", "home:y 4.20")
    path.write_text(pear, encoding="utf-8")
    result = CliRunner().invoke(cli, ["--store", store, "load", "--graph", "map", str(path)])
    assert result.exit_code == 0 and " has hue " not in result.output  # (home:Apple's class warning aside)


def test_cbrs_update_warns_of_what_it_painted() -> None:
    repaint = (
        "DELETE { GRAPH graph:map { world:Cup home:rgba ?old } } INSERT { GRAPH graph:map { world:Cup home:rgba "
        '"0.85 0.25 0.08 1" } } WHERE { GRAPH graph:map { world:Cup home:rgba ?old } }'
    )
    result = CliRunner().invoke(cli, ["--store", ":memory:", "update", repaint])
    assert result.exit_code == 0, result.output
    assert "warning: world:Cup (red, home:rgba 0.85 0.25 0.08 1) has hue 13°, within 3° of the edge" in result.stderr
    result = CliRunner().invoke(cli, ["--store", ":memory:", "update", "--json", repaint])
    assert [w["thing"] for w in json.loads(result.stdout)["warnings"]] == [WORLD + "Cup"]


def test_a_store_seeded_with_home_0_4_0_gets_the_windows(tmp_path: Path) -> None:
    location = str(tmp_path / "store")
    KnowledgeBase.open(location).close()
    old = Store.open(location)
    home = ontology_dir() / "home.ttl"
    old.replace(
        parse_file(home, GraphName.ONTOLOGY).quads,
        parse_file(ontology_dir() / "history" / "home-0.4.0.ttl", GraphName.ONTOLOGY).quads,
    )
    assert not list(old.quads(None, ox.NamedNode(HOME + "hasColourWindow"), None, None))
    old.close()
    kb = KnowledgeBase.open(location)  # upgraded as it opens
    assert [w.name for w in read_colour_windows(kb)[SVC + "Kinect01"]] == [
        "blue",
        "cyan",
        "green",
        "magenta",
        "red",
        "yellow",
    ]
    kb.close()


def test_the_run_page_lists_the_runs_colour_warnings(lab_kb: KnowledgeBase, windows: list[ColourWindow]) -> None:
    """A run's result carries its warnings (cbrs.tasks, as cbrs run --json does); its page lists them."""
    from markupsafe import escape

    from cbrs.sparql_service import SparqlService
    from cbrs.tasks import TaskRun, TaskRunner
    from cbrs.web import create_app

    risk = colour_risk(APPLE, "green", (0.40, 0.80, 0.20, 1.0), windows)
    assert risk is not None
    sparql = SparqlService(lab_kb)
    runner = TaskRunner(lab_kb, sparql.lock, camera=None)
    done = TaskRun("run-1", "FetchMyApple", 0, (), iri=PREFIXES["req"] + "FetchMyApple", status="failed")
    done.result = {"plan": {"status": "solved", "steps": []}, "sim_seconds": 0.0, "warnings": [risk.to_dict()]}
    runner._runs[done.id] = done
    client = create_app(sparql, tasks=runner).test_client()
    page = client.get("/tasks/run-1").text
    assert "Colours the cameras may not tell" in page and str(escape(risk.text())) in page
    assert client.get("/tasks/run-1.json").get_json()["run"]["result"]["warnings"][0]["risk"] == "edge"
