"""The plans page's pictures on a store where two components share a local name, and its drawing's cost.

On OWLS-TC three map services are each ``#_MAP_SERVICE`` (in three files), and the service resource
graph drew three boxes of one name. Here a lab's ceiling camera is registered as
``<http://lab.example/cameras#LocateMobileRobot_CeilingCamera01>``, the local name of the bundled
camera it is an alternative to. The drawing used to lay the figure out by drawing it whole, arrows
and all, then draw it again to save it.
"""

from __future__ import annotations

import io
import itertools
import re
import sys
from collections.abc import Iterator

import matplotlib.pyplot as plt
import pytest
from flask.testing import FlaskClient
from matplotlib.patches import FancyArrowPatch
from matplotlib.text import Annotation

from cbrs.actions.composer import Composer, CompositionResult
from cbrs.actions.draw import figure
from cbrs.actions.shown_names import file_qualifier, shown_names, two_lines
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app, plans

LAB = "http://lab.example/cameras#LocateMobileRobot_CeilingCamera01"
BUNDLED = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"
# Ceiling camera 2's description (ontologies/services.ttl) under the lab's name and device.
LAB_CAMERA = f"""
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
<{LAB}> a cbrs:DynamicPerceptionComponent ;
    rdfs:label "Locate mobile robot (the lab's ceiling camera)"@en ;
    cbrs:deviceName "LabCamera01" ;
    cbrs:serviceName "LocateMobileRobot" ;
    cbrs:serviceCategory "Localisation" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput  [ a cbrs:Parameter ; cbrs:parameterName "markerColour" ; cbrs:parameterType home:MarkerColour ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "robotLocation" ;
            cbrs:parameterType home:RobotLocation ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:isLocalisedIn ; cbrs:conditionObject home:Kitchen ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Kitchen ;
        cbrs:minX 6.0 ; cbrs:maxX 10.0 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime 0.15 ; cbrs:positionError 0.08 ;
        cbrs:availability 0.9 ; cbrs:updateRate 8.0 ] .
"""


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """The bundled store and a third ceiling camera named as camera 1 is, in the lab's namespace."""
    found = KnowledgeBase.open(":memory:")
    assert found.registry.register(LAB_CAMERA) == [LAB]
    yield found
    found.close()


@pytest.fixture(scope="module")
def composed(kb: KnowledgeBase) -> CompositionResult:
    return Composer(kb).compose("FetchMyPen")


@pytest.fixture(scope="module")
def client(kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(kb)).test_client()


def test_the_lab_camera_is_an_alternative_of_the_camera_of_its_name(composed: CompositionResult) -> None:
    assert composed.plan is not None
    assert any(s.component == BUNDLED and LAB in s.alternatives for s in composed.plan.steps)


@pytest.mark.parametrize(
    ("iris", "expected"),
    [
        pytest.param(["http://a/x.owls#S", "http://a/y.owls#T"], ["S", "T"], id="apart"),
        pytest.param(["http://a/x.owls#S", "http://a/y.owls#S"], ["x:S", "y:S"], id="qualified"),
        pytest.param(["http://a/x.owls#S", "http://b/x.owls#S"], ["x:S (1)", "x:S (2)"], id="numbered"),
        pytest.param(
            ["http://a/onto/S", "http://a/other/S", "http://a/onto/T"], ["onto:S", "other:S", "T"], id="slash"
        ),
    ],
)
def test_shown_names_are_unique_and_short(iris: list[str], expected: list[str]) -> None:
    for order in itertools.permutations(iris):  # the names depend on the set, not on its order
        names = shown_names(order)
        assert [names[iri] for iri in iris] == expected


def test_a_qualifier_can_be_given_and_the_default_is_the_file() -> None:
    iris = ["http://a/_Francemap_service.owls#_MAP_SERVICE", "http://a/_mapGerman_service.owls#_MAP_SERVICE"]
    assert [file_qualifier(iri) for iri in iris] == ["_Francemap_service", "_mapGerman_service"]
    given = {iris[0]: "France", iris[1]: "Germany"}
    assert shown_names(iris, given.__getitem__) == {iris[0]: "France:_MAP_SERVICE", iris[1]: "Germany:_MAP_SERVICE"}


@pytest.mark.parametrize(
    ("name", "lines"),
    [
        ("PlanPathAStar_HomeServer01", "PlanPathAStar\nHomeServer01"),
        ("svc:PlanPathAStar_HomeServer01", "svc:\nPlanPathAStar_HomeServer01"),
        ("_MAP_SERVICE", "_MAP_SERVICE"),  # it read "\nMAP_SERVICE", a first line left empty
        ("GOVERNMENT_FUNDING_SERVICE", "GOVERNMENT_FUNDING_SERVICE"),
    ],
)
def test_two_lines(name: str, lines: str) -> None:
    assert two_lines(name) == lines


def vertex_names(result: CompositionResult, qualifier: object = None) -> list[str]:
    drawn = figure(result, qualifier)  # type: ignore[arg-type]
    try:
        return [t.get_text() for axis in drawn.axes for t in axis.texts if t.get_text()]
    finally:
        plt.close(drawn)


def test_the_drawing_names_every_vertex_apart(composed: CompositionResult) -> None:
    names = vertex_names(composed)
    assert len(names) == len(set(names))
    assert "service:\nLocateMobileRobot_CeilingCamera01" in names  # the file part of its IRI, by default
    assert "cameras:\nLocateMobileRobot_CeilingCamera01" in names
    assert "PlanPathAStar\nHomeServer01" in names  # a name no other vertex has stays as it was


def test_the_page_s_flow_names_them_as_the_page_does(client: FlaskClient) -> None:
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    table = page[page.index('<table class="plan">') : page.index("</table>")]
    links = re.findall(r'title="([^"]+)">([^<]+)</a>', table)
    assert (BUNDLED, "svc:LocateMobileRobot_CeilingCamera01") in links
    assert (LAB, "cameras:LocateMobileRobot_CeilingCamera01") in links
    flow = page[page.index('<svg class="diagram"') : page.index("</svg>")]
    assert "svc:</tspan>" in flow and "LocateMobileRobot_CeilingCamera01</tspan>" in flow  # #2 and #11


def test_the_page_s_drawing_names_them_as_the_page_does(client: FlaskClient, composed: CompositionResult) -> None:
    """``/plans/graph.svg`` draws with :func:`plans.qualifier`, the prefixes the page shows (drawn and
    saved, the FetchMyPen drawing takes 0.6 s; the names are the figure's)."""
    with client.application.test_request_context():
        names = vertex_names(composed, plans.qualifier)
    assert "svc:\nLocateMobileRobot_CeilingCamera01" in names
    assert "cameras:\nLocateMobileRobot_CeilingCamera01" in names


def test_saving_the_drawing_draws_each_arrow_once(kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> None:
    """savefig drew a figure with a layout engine twice; the arrows were most of each drawing."""
    drawn_arrows: list[FancyArrowPatch] = []
    original = FancyArrowPatch.draw

    def counted(self: FancyArrowPatch, renderer: object) -> None:
        drawn_arrows.append(self)
        original(self, renderer)  # type: ignore[arg-type]

    drawn = figure(Composer(kb).compose("PutCupBelowOfTapOfWaterDispenser"))
    try:
        arrows = [t for axis in drawn.axes for t in axis.texts if isinstance(t, Annotation)]
        monkeypatch.setattr(FancyArrowPatch, "draw", counted)
        drawn.savefig(io.BytesIO(), format="svg")
    finally:
        plt.close(drawn)
    assert len(arrows) > 20 and len(drawn_arrows) == len(arrows)


def test_a_plan_page_loads_the_drawing_library_once(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    """The page (its form, or a plan) starts importing what a drawing needs (matplotlib, 1.1 s and more),
    once a process; the JSON twin, which has no drawing, does not. A small module stands for the
    drawing's here."""
    monkeypatch.setattr(plans, "DRAWING_MODULE", "colorsys")
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    plans._load_drawing_library.cache_clear()
    try:
        assert client.get("/plans.json", query_string={"task": "RobotSelfPosition"}).status_code == 200
        assert client.get("/plans.json").status_code == 200
        assert plans._load_drawing_library.cache_info().currsize == 0
        client.get("/plans")  # the form: the user is about to choose a task
        assert plans._load_drawing_library.cache_info().currsize == 1
        started = plans._load_drawing_library()
        assert started is not None
        started.join(timeout=10)
        assert "colorsys" in sys.modules
        client.get("/plans", query_string={"task": "FetchMyPen"})
        assert plans._load_drawing_library() is started
    finally:
        plans._load_drawing_library.cache_clear()
