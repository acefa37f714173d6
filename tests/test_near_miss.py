"""A "no plan" answer names the components that come close to an unmet need (actions.near_misses;
docs/composition.md, "Near misses").

The fifth round's visitor stands in the kitchen (docs/tasks.md, "A fifth round"): the living room's tracker
is passed over by its area, and the kitchen's bundled tracker gives a home:PersonLocation, not the
home:PersonPosition the drive to a person takes. Composed, as ``cbrs run`` does, without the laser
components the simulation cannot run; no simulation is needed.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, PlanStatus
from cbrs.actions.graph import Matcher
from cbrs.actions.near_misses import SAME_PARTS, SIBLINGS, Difference, NearMiss, near, statement_differences
from cbrs.actions.unmet import Unsatisfied
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_examples import EXAMPLES, lab5_store

SVC, HOME, LAB = PREFIXES["svc"], PREFIXES["home"], "https://example.org/near#"
KITCHEN_TRACKER = SVC + "TrackPerson_CeilingCamera02"
LASER = (SVC + "StreamLaserScan_LaserScanner01", SVC + "DetectPersonByLaser_LaserScanner01")

# A class below home:Position beside home:PersonPosition with a part of its own (a sibling, not the same
# parts), a kitchen tracker that gives it, and a bedroom tracker giving a home:PersonLocation: near too, but
# not effective where the visitor is.
_EXTRAS = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix lab:  <https://example.org/near#> .
@prefix owl:  <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .

lab:PersonSpot a owl:Class ; rdfs:subClassOf home:Position ,
    [ a owl:Restriction ; owl:onProperty home:hasTimestamp ; owl:someValuesFrom home:Timestamp ] .

lab:TrackSpot_CeilingCamera02 a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "CeilingCamera02" ; cbrs:serviceName "TrackSpot" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput  [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "spot" ; cbrs:parameterType lab:PersonSpot ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Kitchen ] .

lab:TrackPerson_Bedroom a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "CeilingCamera03" ; cbrs:serviceName "TrackPerson" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput  [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "personLocation" ;
            cbrs:parameterType home:PersonLocation ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Bedroom ] .
"""


@pytest.fixture(scope="module")
def matcher(bundled_kb: KnowledgeBase) -> Matcher:
    return Composer(bundled_kb).matcher


def _visitor_store() -> KnowledgeBase:
    kb = lab5_store(things=("lab5_visitor_in_kitchen.ttl",))
    kb.load([EXAMPLES / "lab5_fetch_pen_for_visitor.ttl"], graph="requirements")
    return kb


@pytest.fixture(scope="module")
def visitor_kb() -> Iterator[KnowledgeBase]:
    kb = _visitor_store()
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def extras_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    kb = _visitor_store()
    extras = tmp_path_factory.mktemp("near") / "extras.ttl"
    extras.write_text(_EXTRAS, encoding="utf-8")
    kb.load([extras], graph="ontology")
    kb.load([extras])
    yield kb
    kb.close()


def _compose(kb: KnowledgeBase, **config: int) -> CompositionResult:
    runnable = [ad for ad in kb.advertisements() if ad.iri not in LASER]
    return Composer(kb, ComposeConfig(**config), advertisements=runnable).compose("FetchPenForVisitor")


def _position_need(result: CompositionResult) -> Unsatisfied:
    assert result.status is PlanStatus.UNSOLVABLE
    return next(u for u in result.unsatisfied if "personPosition (home:PersonPosition)" in u.need)


def test_the_kitchen_tracker_is_named_with_what_differs_and_the_fix(visitor_kb: KnowledgeBase) -> None:
    need = _position_need(_compose(visitor_kb))
    assert [m.component for m in need.near_misses] == [KITCHEN_TRACKER]
    text = need.text()
    assert "TrackPerson_CeilingCamera01 was passed over" in text  # as before
    assert (
        "svc:TrackPerson_CeilingCamera02 comes close: it gives home:PersonLocation, svc:NavigateToPerson_P3DX01"
        " takes home:PersonPosition (the same parts, neither a kind of the other): register a component like it"
        " that gives home:PersonPosition, or, if every home:PersonLocation is a home:PersonPosition here, say so"
        " (home:PersonLocation rdfs:subClassOf home:PersonPosition, loaded into the ontology graph)"
    ) in text
    shown = need.to_dict()["near_misses"]
    assert shown == [
        {
            "component": KITCHEN_TRACKER,
            "offer": "personLocation",
            "gives": HOME + "PersonLocation",
            "wanted": HOME + "PersonPosition",
            "differs": [
                {"wanted": HOME + "PersonPosition", "offered": HOME + "PersonLocation", "relation": SAME_PARTS}
            ],
            "similarity": shown[0]["similarity"],
        }
    ]


def test_near_misses_are_ranked_capped_and_kept_to_the_area(extras_kb: KnowledgeBase) -> None:
    """The sibling (Sem-Str nearer) before the same parts; the bedroom tracker, near too, is not effective in
    the kitchen, so it is not named; the cap holds, and 0 names none."""
    need = _position_need(_compose(extras_kb))
    assert [(m.component, m.differs[0].relation) for m in need.near_misses] == [
        (LAB + "TrackSpot_CeilingCamera02", SIBLINGS),
        (KITCHEN_TRACKER, SAME_PARTS),
    ]
    assert need.near_misses[0].similarity > need.near_misses[1].similarity
    assert f"{LAB}TrackSpot_CeilingCamera02 comes close: it gives {LAB}PersonSpot" in need.text()
    assert [m.component for m in _position_need(_compose(extras_kb, near_misses=1)).near_misses] == [
        LAB + "TrackSpot_CeilingCamera02"
    ]
    none = _position_need(_compose(extras_kb, near_misses=0))
    assert none.near_misses == () and "comes close" not in none.text()


def test_the_fix_named_composes(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Declaring, as the answer says, that a home:PersonLocation is a home:PersonPosition: then it plans."""
    kb = _visitor_store()
    declared = tmp_path_factory.mktemp("fix") / "declared.ttl"
    declared.write_text(
        "@prefix home: <https://w3id.org/cbrs/home#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "home:PersonLocation rdfs:subClassOf home:PersonPosition .\n",
        encoding="utf-8",
    )
    kb.load([declared], graph="ontology")
    result = _compose(kb)
    assert result.plan is not None, [u.text() for u in result.unsatisfied]
    assert KITCHEN_TRACKER in {step.component for step in result.plan.steps}
    kb.close()


@pytest.mark.parametrize(
    ("wanted", "offered", "relation"),
    [
        pytest.param("PersonPosition", "PersonLocation", SAME_PARTS, id="same-parts-cousins"),
        pytest.param("PersonPosition", "RobotPosition", None, id="sibling-about-another-thing"),
        pytest.param("Person", "PersonProfile", None, id="same-parts-through-the-root-only"),
        pytest.param("PersonPosition", "Position", None, id="a-superclass-is-a-provider"),
        pytest.param("PersonIdentity", "PersonProfile", SIBLINGS, id="siblings"),
    ],
)
def test_which_concepts_are_near(matcher: Matcher, wanted: str, offered: str, relation: str | None) -> None:
    assert near(matcher, HOME + wanted, HOME + offered) == relation


def test_a_statement_is_near_by_its_subject_or_object_never_its_predicate(matcher: Matcher) -> None:
    wanted = Statement(HOME + "Mug", HOME + "isLocated", HOME + "BelowOfTap")
    cup = Statement(HOME + "Cup", HOME + "isLocated", HOME + "BelowOfTap")
    assert statement_differences(matcher, wanted, cup) == (Difference(HOME + "Mug", HOME + "Cup", SIBLINGS, "subject"),)
    assert statement_differences(matcher, wanted, Statement(HOME + "Cup", HOME + "isAbove", HOME + "BelowOfTap")) == ()
    assert statement_differences(matcher, wanted, Statement(HOME + "Cup", HOME + "isLocated", HOME + "Kitchen")) == ()
    miss = NearMiss(
        SVC + "PutCup",
        "effect",
        "(home:Cup, home:isLocated, home:BelowOfTap)",
        "(home:Mug, home:isLocated, home:BelowOfTap)",
        statement_differences(matcher, wanted, cup),
        0.9,
    )
    assert miss.text("svc:Fill needs") == (
        "svc:PutCup comes close: its effect (home:Cup, home:isLocated, home:BelowOfTap) differs from the"
        " (home:Mug, home:isLocated, home:BelowOfTap) svc:Fill needs: its subject home:Cup for home:Mug (siblings,"
        " neither a kind of the other): register a component like it whose effect is (home:Mug, home:isLocated,"
        " home:BelowOfTap)"
    )
