"""The twentieth blind round (docs/tasks.md, "A twentieth round"): what its tasks found, checked without a
full run where a check suffices."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import sight
from cbrs.sim.components import SimEnvironment
from cbrs.sim.geometry import Pose2D
from cbrs.sim.run_checks import CannotGripError, PlaceMovesError
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
LAB20 = "https://example.org/lab20#"


def _desk_store(camera: bool) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab20_writing_desk.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab20_desk_then_me.ttl"], graph="ontology")
    if camera:
        kb.load([EXAMPLES / "lab20_bedroom_camera_map.ttl"], graph="map")
        kb.registry.register((EXAMPLES / "lab20_bedroom_locator.ttl").read_text())
    return kb


def test_a_base_sent_where_no_camera_sees_its_marker_is_refused_before_it_drives() -> None:
    """DeskThenMe parks the base at a desk in the bedroom, then locates it to drive to the person: no
    bundled camera sees the bedroom, and the run drove there and failed, "robot marker front (green) not
    visible in CeilingCamera01". It is refused before anything moves, naming the place and the cameras."""
    kb = _desk_store(camera=False)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        started, base = world.time, world.base_pose()
        with pytest.raises(sight.BaseOutOfViewError) as refused:
            run_task(kb, "DeskThenMe", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base  # nothing moved
    error = refused.value
    assert error.place == LAB20 + "Desk1" and (error.pose.x, error.pose.y) == (4.2, 7.2)
    assert {camera for camera, _ in error.cameras} == {"CeilingCamera01", "CeilingCamera02"}
    assert "Desk1's docking pose (4.20, 7.20)" in str(error) and "Hang a camera over the place" in str(error)


def test_the_bedroom_camera_sees_the_marker_at_the_desk() -> None:
    """With the lab's third camera hung over the bedroom, the check's model sees both patches at the desk's
    docking pose, and the bundled cameras still do not."""
    kb = _desk_store(camera=True)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        centres = sight.marker_centres(world.marker_model, Pose2D(4.2, 7.2, 1.5708))
        assert sight.unseen(world.cameras["CeilingCamera03"], centres) == ""
        assert sight.unseen(world.cameras["CeilingCamera01"], centres) != ""


def test_a_thing_heavier_than_the_hand_lifts_is_refused_before_anything_moves() -> None:
    """FetchMyHandWeight: a 4.5 kg hand weight was picked up, loaded and brought to the person (41.4 s, seed
    0): the simulated grasp holds far more than the Panda's rated 3 kg. It is refused before anything
    moves, by its mass and the hand's payload (``home:payloadKg``, 3 kg where the store states none)."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab20_hand_weight.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab20_fetch_my_hand_weight.ttl"], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        assert {hand.payload for hand in world.map.hands.values()} == {3.0}
        started, base = world.time, world.base_pose()
        with pytest.raises(CannotGripError) as refused:
            run_task(kb, "FetchMyHandWeight", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base  # nothing moved
    error = refused.value
    assert error.thing == LAB20 + "HandWeight1" and error.limits == ("heavy",)
    assert "can lift the HandWeight1" in str(error) and "it weighs 4.5 kg (home:massKg)" in str(error)
    assert "the hand lifts 3 kg" in str(error) and "home:payloadKg" in str(error)


def test_a_place_that_is_a_movable_object_is_refused_as_such() -> None:
    """PenOntoTheTray: the tray a thing (a shape, a size, a pose) and a home:ObjectPlace. The check took the
    place the carry is given for an object to take ("no hand of CytonDualArm01 can grip the Tray1"); it
    now says that nothing is put onto a thing that moves, and how to describe the tray instead."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab20_serving_tray.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab20_pen_onto_the_tray.ttl"], graph="requirements")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        started = world.time
        with pytest.raises(PlaceMovesError) as refused:
            run_task(kb, "PenOntoTheTray", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started
    error = refused.value
    assert error.place == LAB20 + "Tray1" and error.component.endswith("CarryObject_CytonDualArm01")
    assert "onto the Tray1 (the task's tray)" in str(error) and "under home:Furniture and home:ObjectPlace" in str(
        error
    )


def test_a_hands_own_payload_is_read_where_the_property_is_declared() -> None:
    """``home:payloadKg`` on a gripper is read as its other values are (home.ttl declares it; world.ttl
    states the Panda's 3 kg on each bundled hand): the right hand's changed to 5 kg, the right arm lifts 5."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "DELETE { GRAPH graph:map { world:CytonDualArm01RightHand home:payloadKg ?kg } }"
        " INSERT { GRAPH graph:map { world:CytonDualArm01RightHand home:payloadKg 5.0 } }"
        " WHERE { GRAPH graph:map { world:CytonDualArm01RightHand home:payloadKg ?kg } }"
    )
    hands = SemanticMap.read(kb).hands
    assert {iri.rsplit("#", 1)[1]: hand.payload for iri, hand in hands.items()} == {
        "CytonDualArm01LeftArm": 3.0,
        "CytonDualArm01RightArm": 5.0,
    }
