"""Tasks written in Turtle that cannot run fail before anything moves, with a typed error naming what
is wrong, and leave the store as it was: an object or a place no arm reaches, a class the ontology
does not have, an object that is not in the semantic map."""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.actions.composer import ComposeConfig, Composer, PlanStatus
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import NotGraspableError, SemanticMap, UnresolvedDesignatorError
from cbrs.sim.components import OutOfReachError, PlaceCrowdedError, SimEnvironment
from cbrs.sim.world import open_world

HOME, WORLD, SVC = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"]
TTL = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
@prefix world: <https://w3id.org/cbrs/world#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
"""
BOOK_ON_A_BEDSIDE_TABLE = (
    TTL
    + """home:Book home:graspApproach "top" ; home:graspHeightRatio 0.5 .
world:BedsideTable a home:Table ; home:minX 1.0 ; home:maxX 1.5 ; home:minY 7.0 ; home:maxY 7.5 ;
    home:minZ 0.0 ; home:maxZ 0.55 ; home:dockingPose world:BedsideDock .
world:BedsideDock a home:Pose2D ; home:x 1.25 ; home:y 6.6 ; home:yaw 1.5708 .
world:Book1 a home:Book ; home:shapeKind "box" ; home:sizeX 0.2 ; home:sizeY 0.14 ; home:sizeZ 0.03 ;
    home:massKg 0.4 ; home:colourName "magenta" ; home:rgba "0.8 0.1 0.8 1" ;
    home:isLocatedOn world:BedsideTable ; home:x 1.25 ; home:y 7.25 .
"""
)


def fetch(cls: str, name: str) -> str:
    """A goal-only task: bring the one thing of class ``cls`` to the person."""
    return (
        TTL
        + f"""req:{name} a cbrs:Requirement ; cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ;
    cbrs:serviceName "{name}" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "thing" ; cbrs:parameterType home:{cls} ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "colourOfMarker" ;
            cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:{cls} ; cbrs:conditionPredicate home:isWith ;
            cbrs:conditionObject home:Person ] ] .
"""
    )


PEN_HOLDER_OUT_OF_REACH = (
    TTL
    + """home:PenHolderPlace a owl:Class ; rdfs:subClassOf home:Region .
world:PenHolder a home:PenHolderPlace ;
    home:minX 8.15 ; home:maxX 8.30 ; home:minY 3.50 ; home:maxY 3.65 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""
)
PUT_PEN_IN_HOLDER = (
    TTL
    + """req:PutPenInHolder a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ;
    cbrs:deviceName "CytonDualArm01" ; cbrs:serviceName "PutPenInHolder" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pen ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "place" ; cbrs:parameterType home:PenHolderPlace ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Pen ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject home:PenHolderPlace ] ] .
"""
)


def store(kb: KnowledgeBase) -> set[ox.Quad]:
    return set(kb.store.quads())


def knowledge(tmp_path: Path, *files: tuple[str, str]) -> KnowledgeBase:
    """A fresh store with each (graph, Turtle text) loaded as a user would, from a file."""
    kb = KnowledgeBase.open(":memory:")
    for index, (graph, text) in enumerate(files):
        path = tmp_path / f"task{index}.ttl"
        path.write_text(text, encoding="utf-8")
        kb.load([path], graph=graph)
    return kb


def test_an_object_no_arm_reaches_is_refused_before_anything_moves(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("map", BOOK_ON_A_BEDSIDE_TABLE), ("requirements", fetch("Book", "FetchMyBook")))
    before = store(kb)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        start = world.base_pose()
        # composition would refuse it first (the arm's effective area is the kitchen's): this is the run's check
        unchecked = Composer(kb, ComposeConfig(respect_area=False))
        with pytest.raises(OutOfReachError) as refused:
            run_task(kb, "FetchMyBook", SimEnvironment(world, kb), composer=unchecked)
        assert world.base_pose().distance_to(start.x, start.y) < 0.01  # the base did not drive off
    assert refused.value.thing == WORLD + "Book1" and refused.value.robot == SVC + "CytonDualArm01"
    assert refused.value.where == pytest.approx((1.25, 7.25), abs=0.05)
    assert [arm[0] for arm in refused.value.arms] == sorted(arm[0] for arm in refused.value.arms)
    assert all(distance > reach for *_, reach, distance in refused.value.arms)
    assert "Book1" in str(refused.value) and "reach" in str(refused.value)
    assert store(kb) == before  # no belief written, no plan stored


def test_a_place_no_arm_reaches_is_refused_before_the_pen_is_picked_up(tmp_path: Path) -> None:
    kb = knowledge(
        tmp_path,
        ("ontology", PEN_HOLDER_OUT_OF_REACH),
        ("map", PEN_HOLDER_OUT_OF_REACH),
        ("requirements", PUT_PEN_IN_HOLDER),
    )
    before = store(kb)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        pen = world.pose("Pen").position
        with pytest.raises(OutOfReachError) as refused:
            run_task(kb, "PutPenInHolder", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.pose("Pen").position == pytest.approx(pen, abs=1e-3)
    assert refused.value.thing == WORLD + "PenHolder"
    assert store(kb) == before


def test_a_task_about_an_undeclared_class_says_to_declare_it(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("requirements", fetch("Frisbee", "FetchMyFrisbee")))
    before = store(kb)
    with open_world(seed=0) as world:
        result = run_task(kb, "FetchMyFrisbee", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.composition.status is PlanStatus.UNSOLVABLE and result.report is None
    [why] = result.composition.unsatisfied
    assert why.undeclared == (HOME + "Frisbee",)
    assert "effect (home:Frisbee, home:isWith, home:Person)" in why.text()
    assert "home:Frisbee is no class of the ontology" in why.text()
    assert store(kb) == before


def test_a_thing_declared_outside_the_map_is_not_in_the_world_and_the_store_is_kept(tmp_path: Path) -> None:
    # the wrong graph: the map does not have the book
    kb = knowledge(tmp_path, ("ontology", BOOK_ON_A_BEDSIDE_TABLE), ("requirements", fetch("Book", "FetchMyBook")))
    before = store(kb)
    with (
        open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world,
        pytest.raises(UnresolvedDesignatorError, match="Book"),
    ):
        run_task(kb, "FetchMyBook", SimEnvironment(world, kb), composer=Composer(kb))
    assert store(kb) == before


PEN_HOLDER_UNDER_THE_CUP = PEN_HOLDER_OUT_OF_REACH.replace(
    "home:minX 8.15 ; home:maxX 8.30 ; home:minY 3.50 ; home:maxY 3.65",
    "home:minX 7.38 ; home:maxX 7.52 ; home:minY 3.25 ; home:maxY 3.39",  # around the cup, within reach
)


def test_a_place_the_arms_reach_but_another_object_fills_is_refused_naming_that_object(tmp_path: Path) -> None:
    """The refusal said no arm reaches the place and to move it within reach, though an arm reaches it:
    what leaves no spot is the cup standing on it."""
    kb = knowledge(
        tmp_path,
        ("ontology", PEN_HOLDER_UNDER_THE_CUP),
        ("map", PEN_HOLDER_UNDER_THE_CUP),
        ("requirements", PUT_PEN_IN_HOLDER),
    )
    before = store(kb)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world, pytest.raises(PlaceCrowdedError) as refused:
        run_task(kb, "PutPenInHolder", SimEnvironment(world, kb), composer=Composer(kb))
    assert [iri for iri, _, _ in refused.value.blockers] == [WORLD + "Cup"]
    said = str(refused.value)
    assert "the Cup at (7.4" in said and "leaves no room; move it in the map" in said  # where it is believed
    assert "home:reach" not in said and "within reach" not in said
    assert store(kb) == before


BOWL_AND_BOOK_WITHOUT_GRASPS = (
    TTL
    + """world:Bowl9 a home:Bowl ; home:shapeKind "cylinder" ; home:sizeX 0.14 ; home:sizeY 0.14 ; home:sizeZ 0.06 ;
    home:massKg 0.3 ; home:colourName "magenta" ; home:rgba "0.8 0.1 0.8 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 8.30 ; home:y 4.20 .
world:Book1 a home:Book ; home:shapeKind "box" ; home:sizeX 0.2 ; home:sizeY 0.14 ; home:sizeZ 0.03 ;
    home:massKg 0.4 ; home:colourName "cyan" ; home:rgba "0.1 0.8 0.8 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.70 ; home:y 3.30 .
"""
)


def test_an_object_without_a_grasp_stops_only_the_task_that_would_take_it(tmp_path: Path) -> None:
    """A bowl no class says how to grasp blocked every task, FetchMyPen too, when the map was read; now the
    map is read, FetchMyPen plans, and only fetching the book without a grasp is refused, before anything
    moves, with what to add."""
    kb = knowledge(tmp_path, ("map", BOWL_AND_BOOK_WITHOUT_GRASPS), ("requirements", fetch("Book", "FetchMyBook")))
    smap = SemanticMap.read(kb)
    assert smap.objects[WORLD + "Bowl9"].grasp_approaches == ()
    assert Composer(kb).compose("FetchMyPen").plan is not None
    before = store(kb)
    with open_world(seed=0, semantic_map=smap) as world, pytest.raises(NotGraspableError) as refused:
        start = world.base_pose()
        try:
            run_task(kb, "FetchMyBook", SimEnvironment(world, kb), composer=Composer(kb))
        finally:
            assert world.base_pose().distance_to(start.x, start.y) < 0.01  # refused before the base moved
    assert refused.value.thing == WORLD + "Book1"
    assert "home:graspApproach and home:graspHeightRatio" in str(refused.value)
    assert store(kb) == before
