"""The third round of tasks written only in Turtle from README and docs/tasks.md (docs/examples): a heavy,
tall wine bottle for a low cupboard; a long, thin ruler; the pen for a caregiver in the bedroom, tracked by
a camera registered in Turtle; a mug in a wall cabinet above the arms' reach; the pen and the cup put away
in an order of the user's; the pen brought while the cup stays where it is. One runs in the simulation
(FetchPenForCaregiver at seed 2); the others are loaded, planned or checked before anything moves. The
tasks that fail today are listed in docs/tasks.md ("A third round"), not pinned here."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.run_checks import OutOfReachError
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME, WORLD, SVC, LAB = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"], "https://example.org/lab#"


def _store(things: list[str], tasks: list[str], map_only: tuple[str, ...] = ()) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for name in things:
        kb.load([EXAMPLES / name], graph="ontology")
        kb.load([EXAMPLES / name], graph="map")
    for name in map_only:
        kb.load([EXAMPLES / name], graph="map")
    for name in tasks:
        kb.load([EXAMPLES / name], graph="requirements")
    return kb


@pytest.fixture(scope="module")
def cupboard() -> KnowledgeBase:
    """The low cupboard and the wine bottle, and the three tasks that use the cupboard."""
    return _store(
        ["low_cupboard.ttl", "wine_bottle.ttl"],
        ["put_wine_on_cupboard.ttl", "pen_then_cup_away.ttl", "pen_then_cup_in_order.ttl"],
    )


def _first_step_given(plan: Plan, name: str) -> int:
    """The position of the first step taking the task's input ``name``."""
    return next(
        n
        for n, step in enumerate(plan.steps)
        if any(b.source.step is None and b.source.name == name for b in step.bindings)
    )


def test_an_order_said_by_the_action_ontology_puts_the_pen_away_first(cupboard: KnowledgeBase) -> None:
    """Two sub-actions with a requirement each and an act:PartialOrderingStrict: the pen's steps first."""
    plan = Composer(cupboard).compose("PenThenCupInOrder").plan
    assert plan is not None and plan.method == "decomposed"
    assert _first_step_given(plan, "pen") < _first_step_given(plan, "cup")
    assert plan.components().count(SVC + "PutDownObject_CytonDualArm01") == 2


def test_two_goals_of_one_requirement_are_planned_in_the_order_of_their_subjects(cupboard: KnowledgeBase) -> None:
    """The store keeps no order of statements: written pen first, the goals are planned cup first
    (home:Cup sorts before home:Pen), as docs/tasks.md now says."""
    plan = Composer(cupboard).compose("PenThenCupAway").plan
    assert plan is not None and plan.method == "decomposed"
    assert _first_step_given(plan, "cup") < _first_step_given(plan, "pen")


def test_the_wine_bottle_is_carried_to_the_low_cupboard(cupboard: KnowledgeBase) -> None:
    plan = Composer(cupboard).compose("PutWineOnCupboard").plan
    assert plan is not None
    carry = next(step for step in plan.steps if step.component == SVC + "CarryObject_CytonDualArm01")
    assert [b.source.name for b in carry.bindings if b.name == "targetPlace"] == ["cupboard"]


def test_a_long_thin_ruler_is_brought_to_the_person_by_the_platform() -> None:
    kb = _store(["ruler.ttl"], ["fetch_my_ruler.ttl"])
    assert SemanticMap.read(kb).objects[LAB + "Ruler1"].size == (0.30, 0.03, 0.008)
    plan = Composer(kb).compose("FetchMyRuler").plan
    assert plan is not None
    components = plan.components()
    load, deliver = SVC + "HandOverOntoPlatform_CytonDualArm01", SVC + "DeliverObject_P3DX01"
    assert components.index(load) < components.index(deliver)


def test_a_goal_that_holds_already_is_in_the_world_before_the_run() -> None:
    """PenToMeCupStays: the cup's goal is, word for word, a statement of the world state composition reads
    at the start (the task is a known failure today: no plan, its direct attempt wanting a producer for
    that goal too, docs/tasks.md "A third round")."""
    kb = _store([], ["pen_to_me_cup_stays.ttl"])
    (requirement,) = [r for r in kb.requirements() if r.iri == LAB + "PenToMeCupStays"]
    held = set(Composer(kb).world_state())
    assert [goal for goal in requirement.effects if goal in held] == [
        next(goal for goal in requirement.effects if goal.subject == HOME + "Cup")
    ]


def test_a_mug_in_a_wall_cabinet_is_refused_before_anything_moves() -> None:
    """The shelf is 65 cm above the arms' mounts, within their reach on the floor plan (0.65 m) but not
    in three dimensions (its grasp point 0.97 m from the nearer mount): refused by the reach check before
    anything moves, naming both arms and their distances, not by the Kinect's view (which would advise a
    camera that could not help)."""
    kb = _store(["wall_cabinet.ttl"], ["mug_from_the_cabinet.ttl"])
    plan = Composer(kb).compose("MugFromTheCabinet").plan
    assert plan is not None
    requirements = {r.iri: r for r in kb.requirements()}
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        with pytest.raises(OutOfReachError) as refused:
            environment.given(plan, requirements)
        assert not world.arm("left").held and not world.arm("right").held
    error = refused.value
    assert error.thing == LAB + "Mug1" and error.height == pytest.approx(1.30 + 0.095 * 0.7)
    distances = {arm: distance for arm, _, _, _, distance in error.arms}
    assert distances == {
        WORLD + "CytonDualArm01LeftArm": pytest.approx(0.97, abs=0.005),
        WORLD + "CytonDualArm01RightArm": pytest.approx(1.14, abs=0.005),
    }
    assert all(reach == 0.85 for _, _, _, reach, _ in error.arms)
    assert "1.37 m up" in str(error) and "onto a lower surface" in str(error)


def test_the_pen_reaches_the_caregiver_in_the_bedroom_through_a_tracker_registered_in_turtle() -> None:
    """Without the bedroom camera's tracker the living-room tracker is passed over for the caregiver in
    the bedroom, saying so; with it registered (camera3.ttl, bedroom_camera.ttl) the run tracks them with
    it, drives through the bedroom's door and hands the pen over."""
    kb = _store([], ["fetch_pen_for_caregiver.ttl"], map_only=("caregiver_in_the_bedroom.ttl",))
    # the laser scanner's person detector is planned for them too, and the simulation has no skill for it:
    # the run composes without it, as here
    runnable = [ad for ad in kb.advertisements() if "LaserScanner01" not in ad.iri]
    alone = Composer(kb, advertisements=runnable).compose("FetchPenForCaregiver")
    assert alone.plan is None
    passed = {component: why for need in alone.unsatisfied for component, why in need.out_of_area}
    assert "home:Bedroom" in passed.get(SVC + "TrackPerson_CeilingCamera01", ""), passed
    kb.registry.register((EXAMPLES / "camera3.ttl").read_text())
    kb.registry.register((EXAMPLES / "bedroom_camera.ttl").read_text())
    plan = Composer(kb).compose("FetchPenForCaregiver").plan
    assert plan is not None and LAB + "TrackPerson_CeilingCamera03" in plan.components()
    with open_world(seed=2, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, "FetchPenForCaregiver", SimEnvironment(world, kb), composer=Composer(kb))
        base = world.base_pose()
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    bedroom = SemanticMap.read(kb).things[WORLD + "Bedroom"].box
    assert bedroom.contains_xy(base.x, base.y)
