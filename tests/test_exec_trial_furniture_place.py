"""An object put onto a piece of furniture that is a place too (new-user trial A): a tea tin, a class of
its own with its grasp, onto a counter typed ``home:Furniture`` and ``home:ObjectPlace``. Both are
physical objects as deep in the taxonomy, and both are the goal's, so which one the arm's steps take
(QueryManipulationProperty's ``objectType``) was decided by which input's name sorts first: with the
counter's input named ``counter`` and the tin's ``tin``, the plan took the counter's shape and grasp,
left the tin out, and the run failed ("the semantic map has no shape, size or grasp for Counter1").
Now the goal's subject decides the tie (actions/extraction.py, ``Extraction._fit``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase

LAB = "https://example.org/lab#"
TIN_AND_COUNTER = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab: <https://example.org/lab#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
lab:TeaTin a owl:Class ; rdfs:subClassOf home:Container ; home:graspApproach "side top" ; home:graspHeightRatio 0.5 .
lab:Counter a owl:Class ; rdfs:subClassOf home:Furniture , home:ObjectPlace .
lab:TeaTin1 a lab:TeaTin ; home:shapeKind "cylinder" ; home:sizeX 0.065 ; home:sizeY 0.065 ; home:sizeZ 0.09 ;
    home:massKg 0.12 ; home:colourName "green" ; home:rgba "0.10 0.60 0.25 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.90 ; home:y 3.18 ; home:yaw 0.0 .
lab:Counter1 a lab:Counter ; home:isLocated world:Kitchen ;
    home:minX 8.12 ; home:maxX 8.45 ; home:minY 2.72 ; home:maxY 2.98 ; home:minZ 0.0 ; home:maxZ 0.85 .
"""


def put_tin_on_counter(tin: str, counter: str, task: str = "PutTinOnCounter") -> str:
    return f"""@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix svc: <https://w3id.org/cbrs/service#> . @prefix lab: <https://example.org/lab#> .
lab:{task} a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "{task}" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "{tin}" ; cbrs:parameterType lab:TeaTin ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "{counter}" ; cbrs:parameterType lab:Counter ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject lab:TeaTin ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject lab:Counter ] ] .
"""


NAMES = {"PutTinOnCounter": ("tin", "counter"), "PutATinOnCounter": ("aTin", "counter")}
"""The inputs' names: the counter's sorts first, or the tin's."""


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    folder = tmp_path_factory.mktemp("furniture")
    store = KnowledgeBase.open(":memory:")
    tasks = "".join(put_tin_on_counter(tin, counter, task) for task, (tin, counter) in NAMES.items())
    for graph, text in (("ontology", TIN_AND_COUNTER), ("map", TIN_AND_COUNTER), ("requirements", tasks)):
        path = folder / f"{graph}.ttl"
        path.write_text(text, encoding="utf-8")
        store.load([path], graph=graph)
    return store


@pytest.mark.parametrize("task", sorted(NAMES))
def test_the_arm_takes_the_goals_subject_not_the_furniture_it_goes_onto(kb: KnowledgeBase, task: str) -> None:
    tin, counter = NAMES[task]
    result = Composer(kb).compose(LAB + task)
    assert result.plan is not None, result.unsatisfied
    given = {
        (step.component.rsplit("#", 1)[-1], binding.name): binding.source.name
        for step in result.plan.steps
        for binding in step.inputs
        if binding.source.step is None
    }
    assert given == {
        ("QueryManipulationProperty_HomeServer01", "objectType"): tin,
        ("InferObjectProperty_HomeServer01", "objectType"): tin,
        ("CarryObject_CytonDualArm01", "targetPlace"): counter,
    }
    assert result.unused_inputs == ()


def test_a_goal_no_component_provides_lists_what_they_provide_about_its_subject(tmp_path: Path) -> None:
    """The counter declared as furniture only and the goal `isLocatedOn` it (a user's first try): no plan.
    The refusal said only to register a component with that effect; it now lists what components provide
    about a tin, nearest first: the put-down's (PhysicalObject, isLocated, Place) tells what is missing."""
    furniture_only = TIN_AND_COUNTER.replace("home:Furniture , home:ObjectPlace", "home:Furniture")
    on_counter = put_tin_on_counter("tin", "counter").replace("home:isLocated ;", "home:isLocatedOn ;")
    kb = KnowledgeBase.open(":memory:")
    for graph, text in (("ontology", furniture_only), ("map", furniture_only), ("requirements", on_counter)):
        path = tmp_path / f"{graph}.ttl"
        path.write_text(text, encoding="utf-8")
        kb.load([path], graph=graph)
    result = Composer(kb).compose(LAB + "PutTinOnCounter")
    assert result.plan is None and len(result.unsatisfied) == 1
    provided = [
        (entry["component"].rsplit("#", 1)[-1], entry["effect"])
        for entry in result.unsatisfied[0].to_dict()["provided"]
    ]
    assert provided[:2] == [
        ("HandOverOntoPlatform_CytonDualArm01", "(home:PhysicalObject, home:isLocatedOn, home:RobotPlatform)"),
        ("PutDownObject_CytonDualArm01", "(home:PhysicalObject, home:isLocated, home:Place)"),
    ]
    assert len(provided) == 4
    assert (
        "what components provide about it: (home:PhysicalObject, home:isLocatedOn, home:RobotPlatform) by "
        "svc:HandOverOntoPlatform_CytonDualArm01; (home:PhysicalObject, home:isLocated, home:Place) by "
        "svc:PutDownObject_CytonDualArm01" in result.unsatisfied[0].text()
    )
