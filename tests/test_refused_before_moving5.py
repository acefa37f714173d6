"""What the fifth blind round (docs/tasks.md, "A fifth round") saw fail mid-run is refused before anything
moves: two people in one shirt colour at every seed (the cameras place neither, so a seed that saw the
other's patch larger no longer puts the resident at the visitor's place), a hand that grips but does not
reach no longer lets the grip check pass for one that reaches but cannot grip, and fingers too short for a
side grasp (and a palm too deep for a top one) are found before the run, in the step's own words. One
world is built and not stepped (seed 1, where the look-alike refusal used to be "no plan")."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any, cast

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.person_choice import LookAlikePeopleError
from cbrs.kb.semantic_map import SemanticMap, designate_each
from cbrs.sim.components import SimEnvironment
from cbrs.sim.run_checks import CannotGripError, PlanChecks
from cbrs.sim.values import designator
from cbrs.sim.world import open_world
from tests.helpers_examples import lab5_store as _store

WORLD, LAB5 = PREFIXES["world"], "https://example.org/lab5#"
LEFT, RIGHT = WORLD + "CytonDualArm01LeftArm", WORLD + "CytonDualArm01RightArm"


def test_two_people_in_one_colour_are_placed_by_no_camera_and_the_task_is_refused_at_seed_1() -> None:
    """At seed 1 the visitor's yellow patch is the larger: both people were believed at the visitor's place,
    the living room's tracker was passed over for the resident, and the run said "no plan". Neither is
    believed anywhere by sight now, and FetchMyPen is refused for the look-alike before anything moves."""
    kb = _store(things=("lab5_visitor_in_yellow.ttl",))
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        assert environment.belief.look_alikes == {WORLD + "Person", LAB5 + "Visitor1"}
        environment.perceive()
        assert environment.belief.people == {}
        start = world.time
        with pytest.raises(LookAlikePeopleError, match="as Visitor1 does") as refused:
            run_task(kb, "FetchMyPen", environment, composer=Composer(kb))
        assert refused.value.step.endswith("TrackPerson_CeilingCamera01")
        assert world.time == start  # nothing moved


class _Unseen:
    """A belief that has seen nothing yet: the checks take each object where the map puts it."""

    def position(self, name: str) -> None:
        return None


def _grip_refusal(kb: KnowledgeBase, task: str) -> CannotGripError:
    """The refusal the plan's reach and grip checks give ``task``, from the map alone (no world is built:
    those checks read nothing else), its inputs valued as the simulation's ``given`` values them."""
    plan = Composer(kb).compose(task).plan
    assert plan is not None
    requirement = next(r for r in kb.requirements() if r.service_name == task)
    wanted = [(parameter.type, requirement.requested_by) for parameter in requirement.inputs]
    things = designate_each(kb, wanted)
    values = {
        parameter.name: designator(iri, concept)
        for parameter, iri, (concept, _) in zip(requirement.inputs, things, wanted, strict=True)
    }
    world = cast(Any, SimpleNamespace(map=SemanticMap.read(kb)))
    checks = PlanChecks(world, kb, cast(Any, _Unseen()), cast(Any, None), lambda one, other: one == other)
    with pytest.raises(CannotGripError) as refused:
        checks._check_reach(plan, values)
    return refused.value


def test_a_hand_that_cannot_grip_is_not_let_off_by_a_hand_that_does_not_reach() -> None:
    """The narrow hand on the left arm only: the right arm's Panda hand would grip the cup but does not reach
    it, so the cup is refused for the left hand's jaws (it went on to ApproachToObject, and a re-plan)."""
    error = _grip_refusal(_store(hands="lab5_narrow_left_hand.ttl"), "RobotArmServeACup")
    assert {arm for arm, _, _ in error.refusals} == {LEFT}
    assert "the hand opens 5.0 cm" in str(error)
    assert "home:jawOpening says how far its jaws open" in str(error)  # the value the lab stated limits it
    assert "home:fingertipClearance" not in str(error)  # the cup is not too thin: that advice does not apply


def test_fingers_too_short_for_a_side_grasp_are_refused_before_the_run_in_the_steps_words() -> None:
    """3 cm fingers and a 2 cm palm: the cup too deep for the side grasp, its top too far above the grasp point
    for the top grasp's palm. ApproachToObject refused both after a re-plan; the check before the run now
    does, in the same words (``grasping.check_side_depth``, ``skills.can_grip``), naming the values that
    limit it."""
    error = _grip_refusal(_store(hands="lab5_short_fingers.ttl"), "RobotArmServeACup")
    said = str(error)
    assert {approach for _, approach, _ in error.refusals} == {"side", "top"}
    assert "deep along the hand's approach by its side grasp, and the fingers are 3.0 cm long" in said
    assert "the hand's palm is 2.0 cm above the fingers' grasp point" in said
    assert error.limits == ("deep", "palm")
    assert "home:fingerLength" in said and "home:palmDepth" in said and "home:jawOpening" not in said
