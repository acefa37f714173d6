"""Which arm: an object written in Turtle where only one arm of the dual-arm robot reaches it, while only
the other reaches the mobile base's platform at the table's docking pose."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.grasping import GraspKind
from cbrs.sim.world import open_world

TASKS = Path(__file__).parent / "data" / "tasks"
HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
PENCIL_ON_THE_LEFT = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
world:Pencil1 a home:Pencil ; home:shapeKind "box" ; home:sizeX 0.16 ; home:sizeY 0.012 ; home:sizeZ 0.012 ;
    home:massKg 0.01 ; home:colourName "yellow" ; home:rgba "0.95 0.85 0.10 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 7.36 ; home:y 3.30 ; home:yaw 0.3 .
"""
FETCH_MY_CUP = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
req:FetchMyCup a cbrs:Requirement ; cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ;
    cbrs:serviceName "FetchMyCup" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ; cbrs:parameterType home:Cup ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "marker" ; cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Cup ; cbrs:conditionPredicate home:isWith ;
            cbrs:conditionObject home:Person ] ] .
"""
PEN_TRAY_ON_THE_RIGHT = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
home:PenTray a owl:Class ; rdfs:subClassOf home:ObjectPlace .
world:PenTray1 a home:PenTray ;
    home:minX 8.20 ; home:maxX 8.32 ; home:minY 3.05 ; home:maxY 3.17 ; home:minZ 0.75 ; home:maxZ 0.75 .
"""
PUT_CUP_ON_PEN_TRAY = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix req: <https://w3id.org/cbrs/requirement#> . @prefix svc: <https://w3id.org/cbrs/service#> .
req:PutCupOnPenTray a cbrs:Requirement ; cbrs:requestedBy svc:CytonDualArm01 ; cbrs:deviceName "CytonDualArm01" ;
    cbrs:serviceName "PutCupOnPenTray" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ; cbrs:parameterType home:Cup ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "place" ; cbrs:parameterType home:PenTray ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Cup ; cbrs:conditionPredicate home:isLocated ;
            cbrs:conditionObject home:PenTray ] ] .
"""


def knowledge(tmp_path: Path, *files: tuple[str, str | Path]) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for index, (graph, text) in enumerate(files):
        path = text if isinstance(text, Path) else tmp_path / f"file{index}.ttl"
        if not isinstance(text, Path):
            path.write_text(text, encoding="utf-8")
        kb.load([path], graph=graph)
    return kb


def test_an_object_only_the_left_arm_reaches_is_passed_to_the_right_arm(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("map", PENCIL_ON_THE_LEFT), ("requirements", TASKS / "fetch_my_pencil.ttl"))
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FetchMyPencil", SimEnvironment(world, kb), composer=Composer(kb))
        left = world.arm(ArmSide.LEFT).released
        assert left is not None and world.name_of(left[0]) == "Pencil1"  # the left hand set it down for the right
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Pencil1", HOME + "isWith", WORLD + "Person") in facts


def test_the_cup_is_passed_by_its_side_grasp_and_loaded_by_its_top_grasp(tmp_path: Path) -> None:
    """The left arm reaches the cup and only the right arm the platform at the table's docking pose,
    which it cannot load by the cup's side grasp: home:Drinkware allows "side top", so the left arm
    passes the cup by its side grasp (its first) and the right arm takes it from the top and loads it,
    and the base brings it to the person. Each choice says why the approaches before it were passed
    over (a cup allowed only its side grasp is refused before anything moves:
    tests/test_grasp_approaches.py)."""
    kb = knowledge(tmp_path, ("requirements", FETCH_MY_CUP))
    smap = SemanticMap.read(kb)
    assert smap.objects[WORLD + "Cup"].grasp_approaches == ("side", "top")
    with open_world(seed=0, semantic_map=smap) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "FetchMyCup", environment, composer=Composer(kb))
        choices = environment.context.choices
        left = world.arm(ArmSide.LEFT).released
        assert left is not None and world.name_of(left[0]) == "Cup"  # set down by the left hand for the right
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Cup", HOME + "isWith", WORLD + "Person") in facts
    assert [(c.arm, c.model.grasp) for c in choices] == [(ArmSide.LEFT, GraspKind.SIDE), (ArmSide.RIGHT, GraspKind.TOP)]
    assert choices[0].passed == ()
    assert [kind for kind, _ in choices[1].passed] == [GraspKind.SIDE]
    why = str(choices[1])
    assert why.startswith("loading the Cup onto the platform: the right arm holds the Cup by its top grasp")
    assert "not by its side grasp: the right arm cannot hold the Cup by its side grasp over the platform" in why


def test_a_place_only_the_other_arm_reaches_gets_the_object_passed_to_that_arm(tmp_path: Path) -> None:
    """The left arm takes the cup; the pen tray is beyond its reach and within the right arm's: the left
    arm sets the cup down where both reach, and the right arm carries it on. The cup allows "side top"
    (home:Drinkware): the right arm can set it down on the tray by its side grasp, its first, so each
    arm takes it so, as with one approach (an approach that works for the whole hold is kept)."""
    kb = knowledge(
        tmp_path,
        ("ontology", PEN_TRAY_ON_THE_RIGHT),
        ("map", PEN_TRAY_ON_THE_RIGHT),
        ("requirements", PUT_CUP_ON_PEN_TRAY),
    )
    smap = SemanticMap.read(kb)
    assert smap.objects[WORLD + "Cup"].grasp_approaches == ("side", "top")
    with open_world(seed=0, semantic_map=smap) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "PutCupOnPenTray", environment, composer=Composer(kb))
        assert environment.context.arm is ArmSide.RIGHT
        left = world.arm(ArmSide.LEFT).released
        assert left is not None and world.name_of(left[0]) == "Cup"
        choices = list(environment.context.choices)
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Cup", HOME + "isLocated", WORLD + "PenTray1") in facts
    assert [(c.arm, c.model.grasp, c.passed) for c in choices] == [
        (ArmSide.LEFT, GraspKind.SIDE, ()),
        (ArmSide.RIGHT, GraspKind.SIDE, ()),
    ]


def test_an_object_a_failed_plan_left_in_a_hand_is_set_down_before_the_next_plan() -> None:
    """PutCupOnTray with the put-down broken: the first plan fails with the cup in the left hand; before
    re-planning the arm sets it down where it took it, so the next plan finds and takes it again (it
    used to look for the cup on the table while the hand held it up in the air)."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([TASKS / "tray_place.ttl"], graph="map")
    kb.load([TASKS / "put_cup_on_tray.ttl"], graph="requirements")
    broken = PREFIXES["svc"] + "PutDownObject_CytonDualArm01"
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "PutCupOnTray", environment, composer=Composer(kb), faults=[broken], max_replans=1)
    assert not result.succeeded and len(result.replans) == 1
    first, last = result.replans[0].report, result.report
    assert last is not None
    assert [s.outcome for s in first.steps][-1] == "failed"
    outcomes = {step.planned.rsplit("#", 1)[-1]: step.outcome for step in last.steps}
    assert outcomes["RecogniseObjectByColour_Kinect01"] == "succeeded"
    assert outcomes["PickUpObject_CytonDualArm01"] == "succeeded"
    assert outcomes["PutDownObject_CytonDualArm01"] == "failed"  # still broken


def test_a_pencil_taken_askew_is_let_go_where_it_was_taken_and_taken_again(tmp_path: Path) -> None:
    """Seed 6 (seed 3 before each object's start offsets were drawn from its IRI): the left hand takes the
    pencil askew at the edge of its reach, so the pass to the right arm fails with the pencil in the hand;
    lowering it back fails too, so the hand lets go of it just above the table where it took it, and the
    re-plan fetches it. Set down and seen again on the table, the pencil has moved, so the re-plan is the
    same plan (nothing avoided: actions.replanning, tests/test_replanning_memory.py). The hands keep no
    fingertip clearance here, so the pencil is taken at its class's 9 mm as when this was found (with the
    default 2 mm the grasp point is 10.2 mm up, and the left hand takes it cleanly at this seed)."""
    flush = (
        "@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .\n"
        "world:CytonDualArm01LeftHand home:fingertipClearance 0.0 .\n"
        "world:CytonDualArm01RightHand home:fingertipClearance 0.0 .\n"
    )
    files = (("map", PENCIL_ON_THE_LEFT), ("map", flush), ("requirements", TASKS / "fetch_my_pencil.ttl"))
    kb = knowledge(tmp_path, *files)
    with open_world(seed=6, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FetchMyPencil", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert len(result.replans) == 1 and "passing the Pencil1 from the left arm" in result.replans[0].reason
    assert not result.replans[0].avoided and not result.stopped
    (failure,) = result.replans[0].failures
    assert failure.component.endswith("HandOverOntoPlatform_CytonDualArm01")
    assert failure.things == frozenset({WORLD + "Pencil1"})
    assert result.report is not None
    assert [s.planned for s in result.replans[0].report.steps] == [s.planned for s in result.report.steps]
