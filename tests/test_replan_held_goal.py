"""A re-plan of EraserCupPen (tests/test_room_by_free_arms.py's tasks) after the pen's take failed, the eraser on
the mat and the cup in the left hand (the part "KeepCup" done): composed from a stub belief, no world built.

In the simulated home the re-plan looked for the cup again, though the left hand held it, and the Kinect did not
see it ("red object not visible in Kinect01"): ``SimEnvironment.observe`` reports no (thing, isGraspedBy, hand)
fact, so the world graph the re-plan reads says nothing of what a hand holds and the part's goal does not hold
there. Given the fact, the composer drops the part (the first test); but the world state is offered to the
preconditions lifted to classes, so the held cup, (Cup, isGraspedBy, Gripper), also meets the pen's carry's
precondition (PhysicalObject, isGraspedBy, Gripper) and the plan carries the pen without taking it (the second
test, a known fault until the composer offers a grasp only to the part given the thing held)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_examples import EXAMPLES
from tests.test_room_by_free_arms import CUP, CUP_WEST, ERASER, LAB6, MAT, MAT_MAP, PEN, TASKS, WORLD

HOME = PREFIXES["home"]
HAND = WORLD + "CytonDualArm01LeftHand"  # home:Gripper in the map
TYPES = {ERASER: LAB6 + "Eraser", CUP: HOME + "Cup", PEN: HOME + "Pen", MAT: LAB6 + "Mat"}
ON_MAT = (ERASER, HOME + "isLocated", MAT)
HELD = (CUP, HOME + "isGraspedBy", HAND)


@pytest.fixture(scope="module")
def replans(tmp_path_factory: pytest.TempPathFactory) -> tuple[Plan, Plan]:
    """EraserCupPen composed as a re-plan from the belief with the eraser on the mat, then with the cup held too."""
    directory: Path = tmp_path_factory.mktemp("held")
    (directory / "mat.ttl").write_text(MAT_MAP, encoding="utf-8")
    (directory / "tasks.ttl").write_text(TASKS, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl", directory / "mat.ttl"], graph=graph)
    kb.load([directory / "tasks.ttl"], graph="requirements")
    kb.update(CUP_WEST)
    belief = BeliefState(kb)
    plans = []
    for facts in ({ON_MAT}, {ON_MAT, HELD}):
        belief.write(Observation(TYPES, frozenset(facts)))
        plan = Composer(kb).compose("EraserCupPen", belief=True).plan
        assert plan is not None
        plans.append(plan)
    return plans[0], plans[1]


def _given(plan: Plan) -> set[str]:
    """The task's inputs the plan's steps are given."""
    return {b.source.name for step in plan.steps for b in step.inputs if b.source.step is None}


def _components(plan: Plan) -> list[str]:
    return [step.component.rsplit("#", 1)[-1] for step in plan.steps]


def test_a_part_whose_goal_the_belief_holds_is_dropped(replans: tuple[Plan, Plan]) -> None:
    """The cup not held: the re-plan takes it, then the pen; held (the part's goal in the belief): no step is
    about it."""
    cup_free, cup_held = replans
    assert "cup" in _given(cup_free) and "eraser" not in _given(cup_free)
    assert "cup" not in _given(cup_held)


@pytest.mark.xfail(
    strict=True,
    reason="the held cup's grasp, lifted to classes, meets the pen's carry's precondition: the pen is not taken",
)
def test_a_thing_held_does_not_stand_for_another_things_take(replans: tuple[Plan, Plan]) -> None:
    """With the cup held, the re-plan is the pen's part of the plan without it: the pen taken, carried, set down."""
    cup_free, cup_held = replans
    pen_part = _components(cup_free)[-8:]
    assert pen_part.count("PickUpObject_CytonDualArm01") == 1
    assert _components(cup_held) == pen_part
