"""A place written in Turtle that the mobile base is sent to: a desk in the bedroom with its docking
pose, named by the task itself (not as where an object is kept)."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world

SVC, WORLD, HOME = PREFIXES["svc"], PREFIXES["world"], PREFIXES["home"]
THE_DESK = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
@prefix world: <https://w3id.org/cbrs/world#> .
world:Desk1 a home:Desk , home:ObjectPlace ;
    home:minX 3.8 ; home:maxX 4.6 ; home:minY 7.6 ; home:maxY 8.2 ; home:minZ 0.0 ; home:maxZ 0.72 ;
    home:dockingPose world:Desk1Dock .
world:Desk1Dock a home:Pose2D ; home:x 4.2 ; home:y 7.0 ; home:yaw 1.5708 .
"""
GO_TO_THE_DESK_TASK = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
req:GoToDesk a cbrs:Requirement ; cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "GoToDesk" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "desk" ; cbrs:parameterType home:Desk ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "marker" ; cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:MobileRobot ; cbrs:conditionPredicate home:isNear ;
            cbrs:conditionObject home:ObjectPlace ] ] .
"""


def test_the_base_is_sent_to_a_new_desk_by_its_docking_pose(tmp_path: Path) -> None:
    desk, task = tmp_path / "desk.ttl", tmp_path / "go_to_the_desk.ttl"
    desk.write_text(THE_DESK, encoding="utf-8")
    task.write_text(GO_TO_THE_DESK_TASK, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([desk], graph="map")
    kb.load([task], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "GoToDesk", SimEnvironment(world, kb), composer=Composer(kb))
        parked = world.base_pose()
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert parked.distance_to(4.2, 7.0) < 0.1
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (SVC + "P3DX01", HOME + "isNear", WORLD + "Desk1") in facts


def test_an_object_on_a_new_side_table_is_found_by_a_camera_registered_for_it() -> None:
    """docs/examples: a side table the Kinect does not see, a camera hung over it in the map, its
    recogniser registered in Turtle; the Kinect's recogniser fails and the new one stands in."""
    examples = Path(__file__).parent.parent / "docs" / "examples"
    kb = KnowledgeBase.open(":memory:")
    kb.load([examples / "side_table.ttl"], graph="map")
    kb.registry.register((examples / "side_table_camera.ttl").read_text(encoding="utf-8"))
    kb.load([examples / "fetch_my_keys.ttl"], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FetchMyKeys", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert result.report is not None
    used = [step.component for step in result.report.steps]
    assert SVC + "RecogniseObjectByColour_SideCamera01" in used
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Keys1", HOME + "isWith", WORLD + "Person") in facts
