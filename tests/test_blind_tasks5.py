"""The fifth round of tasks written from the docs alone (docs/examples/lab5_*, docs/tasks.md "A fifth
round"): a lab's dual-arm robot stood elsewhere along the table and its mobile base started in the
bedroom, grippers of the lab's own described in the store, and a second person, a visitor in the kitchen,
brought the pen by name. One run in the simulation (FetchPenForVisitor at seed 0); the others are read
from the map, composed or refused at the load. The failures this round found are listed in
docs/tasks.md, not pinned here."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import check_home
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.person_choice import LookAlikePeopleError, person_for
from cbrs.kb.semantic_map import MapError, SemanticMap, designate
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from tests.helpers_examples import lab5_store as _store

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME, WORLD, SVC, LAB5 = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"], "https://example.org/lab5#"
LEFT, RIGHT = WORLD + "CytonDualArm01LeftArm", WORLD + "CytonDualArm01RightArm"


def _map_size(kb: KnowledgeBase) -> int:
    return len(list(kb.query(f"SELECT ?s ?p ?o WHERE {{ GRAPH <{PREFIXES['graph']}map> {{ ?s ?p ?o }} }}")))


def test_the_robot_moved_west_and_the_base_in_the_bedroom_make_a_home_that_builds_and_plans() -> None:
    """One update moves the torso, both mounts, the Kinect and the docking pose together; another starts the
    base in the bedroom. The home check passes, and FetchMyPen still composes (it ran at seeds 0-2)."""
    kb = _store(updates=("lab5_robot_west10.ru", "lab5_base_in_bedroom.ru"))
    smap = SemanticMap.read(kb)
    check_home(smap)
    assert [round(smap.arms[arm].mount[0], 3) for arm in (LEFT, RIGHT)] == [7.47, 7.83]
    torso = smap.things[SVC + "CytonDualArm01"].box
    assert (torso.min_x, torso.max_x) == pytest.approx((7.40, 7.90))
    kinect = smap.cameras[SVC + "Kinect01"]
    assert (kinect.position[0], kinect.yaw) == pytest.approx((7.65, 1.4659))
    bedroom = smap.things[WORLD + "Bedroom"].box
    base = smap.robots[SVC + "P3DX01"].start
    assert bedroom.contains_xy(base.x, base.y)
    assert Composer(kb).compose("FetchMyPen").plan is not None


def test_the_lab_hands_are_read_from_their_class_with_their_carry_and_bands() -> None:
    """Both hands take the model's values from their class: the jaws' 5 cm (too narrow for the 6 cm cup by
    the 3.5 mm each jaw keeps clear, wide enough for the 1.6 cm pen), the corridor and the two bands."""
    hands = SemanticMap.read(_store(hands="lab5_narrow_hands.ttl")).hands
    for arm in (LEFT, RIGHT):
        hand = hands[arm]
        assert (hand.jaw_opening, hand.palm_depth, hand.finger_length) == pytest.approx((0.05, 0.03, 0.045))
        assert hand.carry_corridor == pytest.approx(0.07)
        bands = sorted((band.near, band.far, band.half_width, band.underside) for band in hand.side_arm)
        assert [value for band in bands for value in band] == pytest.approx(
            [0.0, 0.15, 0.07, 0.01, 0.15, 0.33, 0.10, -0.03]
        )
        assert 0.016 < hand.widest < 0.06


@pytest.mark.parametrize(
    ("hands", "says"),
    [
        pytest.param(None, "an arm ends in one gripper", id="two-grippers"),
        pytest.param("unhanded", "a band ends further back than it begins", id="band-backwards"),
    ],
)
def test_a_hand_mistake_is_refused_at_the_load_and_the_map_is_as_it_was(hands: str | None, says: str) -> None:
    kb = _store()
    name = "lab5_narrow_hands.ttl"
    if hands == "unhanded":
        kb.update((EXAMPLES / "lab5_unhand.ru").read_text())
        name = "lab5_mistake_band_backwards.ttl"
    before = _map_size(kb)
    with pytest.raises(MapError, match=says):
        kb.load([EXAMPLES / name], graph="map")
    assert _map_size(kb) == before


def test_a_visitor_is_named_by_their_class_and_the_resident_by_home_person() -> None:
    kb = _store(things=("lab5_visitor_in_kitchen.ttl",))
    assert designate(kb, LAB5 + "Visitor") == LAB5 + "Visitor1"
    assert designate(kb, HOME + "Person") == WORLD + "Person"
    smap = SemanticMap.read(kb)
    assert person_for(smap, "a step", [LAB5 + "Visitor1"]).iri == LAB5 + "Visitor1"
    assert person_for(smap, "a step", [WORLD + "Person"]).iri == WORLD + "Person"


def test_two_people_in_one_colour_are_refused_for_either() -> None:
    smap = SemanticMap.read(_store(things=("lab5_visitor_in_yellow.ttl",)))
    for person in (LAB5 + "Visitor1", WORLD + "Person"):
        with pytest.raises(LookAlikePeopleError, match="wears a yellow shirt"):
            person_for(smap, "TrackPerson_CeilingCamera01", [person])


def test_the_pen_is_brought_to_the_visitor_in_the_kitchen_with_the_labs_tracker() -> None:
    """Without a tracker effective in the kitchen there is no plan, and the living room's is named as passed
    over; with the lab's registered, the pen reaches the visitor (seed 0), the resident untouched."""
    kb = _store(things=("lab5_visitor_in_kitchen.ttl",))
    kb.load([EXAMPLES / "lab5_fetch_pen_for_visitor.ttl"], graph="requirements")
    # the laser scanner's person detector is planned too, and the simulation has no skill for it: the run
    # composes without it, as here
    runnable = [ad for ad in kb.advertisements() if "LaserScanner01" not in ad.iri]
    alone = Composer(kb, advertisements=runnable).compose("FetchPenForVisitor")
    assert alone.plan is None
    passed = {component: why for need in alone.unsatisfied for component, why in need.out_of_area}
    assert "home:Kitchen" in passed.get(SVC + "TrackPerson_CeilingCamera01", ""), passed
    kb.registry.register((EXAMPLES / "lab5_kitchen_tracker.ttl").read_text())
    plan = Composer(kb).compose("FetchPenForVisitor").plan
    assert plan is not None and LAB5 + "TrackPersonInKitchen_CeilingCamera02" in plan.components()
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FetchPenForVisitor", SimEnvironment(world, kb), composer=Composer(kb))
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    # the goal is about the visitor, and the referee finds it holding in the world, not only believed
    assert [str(goal.statement.object) for goal in result.goals] == [LAB5 + "Visitor"]
    assert all(goal.believed and goal.holds for goal in result.goals)
