"""Tasks written in Turtle that name several things: each step must handle the thing its goal is about.
The descriptions link no input to a statement, so the task's things are told apart by the classes the
goals name (a mug to fill and the tap that fills it; a cup for a tray and a pen for the person)."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
PREFIXES_TTL = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
@prefix world: <https://w3id.org/cbrs/world#> . @prefix act: <https://w3id.org/cbrs/action#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
"""
MUG = (
    PREFIXES_TTL
    + """world:Mug1 a home:Mug ; home:shapeKind "cylinder" ; home:sizeX 0.07 ; home:sizeY 0.07 ; home:sizeZ 0.09 ;
    home:massKg 0.2 ; home:colourName "magenta" ; home:rgba "0.8 0.1 0.8 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.95 ; home:y 3.32 ; home:yaw 0.0 .
"""
)
FILL_ANY_DRINKWARE = (
    PREFIXES_TTL
    + """svc:FillDrinkwareFromTap_CytonDualArm01 a cbrs:PhysicalManipulationComponent ;
    cbrs:device svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "FillCupFromTap" ; cbrs:serviceCategory "Manipulation" ;
    cbrs:realizesAction act:FillCupFromTapOfWaterDispenser ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ; cbrs:parameterType home:Drinkware ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "tap" ; cbrs:parameterType home:Tap ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:Drinkware ;
            cbrs:conditionPredicate home:isLocated ; cbrs:conditionObject home:BelowOfTap ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Drinkware ; cbrs:conditionPredicate home:contains ;
            cbrs:conditionObject home:Water ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Kitchen ;
        cbrs:minX 7.0 ; cbrs:maxX 8.5 ; cbrs:minY 3.0 ; cbrs:maxY 4.5 ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime 6.0 ; cbrs:availability 0.95 ] .
"""
)
FILL_MY_MUG = (
    PREFIXES_TTL
    + """req:FillMyMug a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "FillMyMug" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "mug" ; cbrs:parameterType home:Mug ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "tap" ; cbrs:parameterType home:Tap ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "belowOfTap" ; cbrs:parameterType home:BelowOfTap ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Mug ; cbrs:conditionPredicate home:contains ;
            cbrs:conditionObject home:Water ] ] .
"""
)
PEN_TRAY = (
    PREFIXES_TTL
    + """home:PenTray a owl:Class ; rdfs:subClassOf home:ObjectPlace .
world:PenTray1 a home:PenTray ;
    home:minX 8.20 ; home:maxX 8.32 ; home:minY 3.05 ; home:maxY 3.17 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""
)
TIDY_AND_FETCH = (
    PREFIXES_TTL
    + """req:TidyAndFetch a cbrs:Requirement ; cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ;
    cbrs:serviceName "TidyAndFetch" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ; cbrs:parameterType home:Cup ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "tray" ; cbrs:parameterType home:PenTray ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pen ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "marker" ; cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Cup ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject home:PenTray ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Pen ; cbrs:conditionPredicate home:isWith ;
            cbrs:conditionObject home:Person ] ] .
"""
)


def knowledge(tmp_path: Path, *files: tuple[str, str]) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for index, (graph, text) in enumerate(files):
        path = tmp_path / f"file{index}.ttl"
        path.write_text(text, encoding="utf-8")
        kb.load([path], graph=graph)
    return kb


def given(plan: Plan, service: str) -> list[dict[str, str]]:
    """For each step of ``service``: its inputs the task gives, name -> the task's input."""
    return [
        {b.name: b.source.name for b in step.inputs if b.source.step is None}
        for step in plan.steps
        if step.component.endswith("#" + service)
    ]


def test_the_grasp_is_for_the_mug_to_fill_not_for_the_tap_that_fills_it(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("map", MUG), ("requirements", FILL_MY_MUG))
    kb.registry.register(FILL_ANY_DRINKWARE)
    plan = Composer(kb).compose("FillMyMug").plan
    assert plan is not None
    assert given(plan, "QueryManipulationProperty_HomeServer01") == [{"objectType": "mug"}]
    assert given(plan, "InferObjectProperty_HomeServer01") == [{"objectType": "mug"}]
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FillMyMug", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Mug1", HOME + "contains", HOME + "Water") in facts


def test_each_goal_of_a_goal_only_task_gets_its_own_thing(tmp_path: Path) -> None:
    """The cup goes to the tray and the pen to the person: the cup's steps take the cup and the tray,
    the pen's steps take the pen, and the base parks where the pen is kept, not at the tray."""
    kb = knowledge(tmp_path, ("ontology", PEN_TRAY), ("map", PEN_TRAY), ("requirements", TIDY_AND_FETCH))
    plan = Composer(kb).compose("TidyAndFetch").plan
    assert plan is not None
    assert sorted(s["objectType"] for s in given(plan, "QueryManipulationProperty_HomeServer01")) == ["cup", "pen"]
    assert given(plan, "CarryObject_CytonDualArm01") == [{"targetPlace": "tray"}]
    assert given(plan, "InferObjectPlace_HomeServer01") == [{"object": "pen"}]
    assert given(plan, "NavigateToPlace_P3DX01") == [{}]  # the place comes from InferObjectPlace
