"""A grasp high on a tall object (home:graspHeightRatio 0.88 of an 18 cm bottle): the gripper at its
pre-grasp pose is near the bottle, and the bottle taken there is held, not "slipped". Both checks
measured to the object's centre (nu16 repro 03), which such a grasp point is 7 cm above."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import predicates as pred
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world

ONTOLOGY = """
@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix lab:   <https://example.org/lab#> .
@prefix owl:   <http://www.w3.org/2002/07/owl#> .
@prefix rdfs:  <http://www.w3.org/2000/01/rdf-schema#> .
home:Bottle home:graspApproach "side" ; home:graspHeightRatio 0.88 .
lab:BottleSpot a owl:Class ; rdfs:subClassOf home:ObjectPlace .
"""
MAP = """
@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab:   <https://example.org/lab#> .
@prefix owl:   <http://www.w3.org/2002/07/owl#> .
world:Bottle1 a home:Bottle , owl:NamedIndividual ;
    home:shapeKind "cylinder" ; home:sizeX 0.06 ; home:sizeY 0.06 ; home:sizeZ 0.18 ; home:massKg 0.2 ;
    home:colourName "green" ; home:rgba "0.10 0.70 0.20 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.30 ; home:y 3.15 ; home:yaw 0.0 .
world:BottleSpot1 a lab:BottleSpot , owl:NamedIndividual ;
    home:minX 7.45 ; home:maxX 7.60 ; home:minY 3.05 ; home:maxY 3.20 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""
TASK = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix svc:  <https://w3id.org/cbrs/service#> .
@prefix lab:  <https://example.org/lab#> .
lab:MoveBottle a cbrs:Requirement ;
    cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ; cbrs:serviceName "MoveBottle" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "bottle" ; cbrs:parameterType home:Bottle ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "spot" ; cbrs:parameterType lab:BottleSpot ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Bottle ; cbrs:conditionPredicate home:isLocated ;
                         cbrs:conditionObject lab:BottleSpot ] ] .
"""


@pytest.mark.parametrize(
    ("point", "distance"),
    [
        ((0.0, 0.0, 0.0), 0.0),  # inside
        ((0.13, 0.0, 0.0), 0.10),  # beside it: from its side, 3 cm from the axis
        ((0.0, 0.0, 0.19), 0.10),  # over it: from its top, 9 cm above the centre
        ((0.07, 0.0, 0.13), 0.0566),  # off its top edge: 4 cm out and 4 cm up
    ],
)
def test_the_distance_is_to_the_objects_extent_not_its_centre(
    point: tuple[float, float, float], distance: float
) -> None:
    got = pred.distance_to_extent(point, (0.0, 0.0, 0.0), (0.06, 0.06, 0.18))
    assert got == pytest.approx(distance, abs=1e-3)


def test_a_bottle_grasped_high_on_its_side_is_approached_taken_and_put_down(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    for name, text, graph in (("onto", ONTOLOGY, "ontology"), ("map", MAP, "map"), ("task", TASK, "requirements")):
        (tmp_path / f"{name}.ttl").write_text(text, encoding="utf-8")
        kb.load([tmp_path / f"{name}.ttl"], graph=graph)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "MoveBottle", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
