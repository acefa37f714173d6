"""ApproachToObject looks ahead to where the hold it starts ends, when the plan and the task say: the place
a later CarryObject is given by the task. An arm then takes the object by the first approach that serves
both ends (taking it where it is, letting it go at a spot of the place it reaches), and falls back to the
first it can take it by when where it goes is not known here (sim/arm_choice.py: taking, hold_end)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Source
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.arm_choice import hold_end
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimContext, SimEnvironment
from cbrs.sim.grasping import GraspKind
from cbrs.sim.values import designator
from cbrs.sim.world import open_world
from tests.test_grasp_approaches import cup_grasps
from tests.test_turtle_tasks_arms import knowledge

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
TASKS = Path(__file__).parent / "data" / "tasks"
APPROACH = PREFIXES["svc"] + "ApproachToObject_CytonDualArm01"


def tray(min_x: float, max_x: float, min_y: float, max_y: float) -> str:
    return f"""@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
world:TrayPlace a home:ObjectPlace ;
    home:minX {min_x} ; home:maxX {max_x} ; home:minY {min_y} ; home:maxY {max_y} ; home:minZ 0.75 ; home:maxZ 0.75 .
"""


# A tray just in front of the left arm's mount (7.57, 2.55), 0.53 m ahead: the left hand holds the cup
# over it from the top, but not by the side grasp aimed along the arm's facing; the right arm can do both.
TRAY_IN_FRONT_OF_THE_LEFT_ARM = tray(7.55, 7.57, 3.07, 3.09)


def cup_to_the_tray(tmp_path: Path, approaches: str = "side top") -> KnowledgeBase:
    return knowledge(
        tmp_path,
        ("ontology", cup_grasps(approaches)),
        ("map", TRAY_IN_FRONT_OF_THE_LEFT_ARM),
        ("requirements", TASKS / "put_cup_on_tray.ttl"),
    )


def test_the_arm_takes_the_cup_by_the_approach_it_can_also_set_it_down_on_the_tray_by(tmp_path: Path) -> None:
    """Taken by its side grasp (its class's first), the cup could not be let go over the tray by the left
    hand: the carry passed it to the right arm (17.8 s simulated at seed 0). Looking ahead, the left arm
    takes it from the top and sets it down itself."""
    kb = cup_to_the_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "PutCupOnTray", environment, composer=Composer(kb))
        choices = list(environment.context.choices)
        right_took_it = world.arm(ArmSide.RIGHT).released
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    assert right_took_it is None  # no pass
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Cup", HOME + "isLocated", WORLD + "TrayPlace") in facts
    assert [(c.arm, c.model.grasp) for c in choices] == [(ArmSide.LEFT, GraspKind.TOP)]
    assert str(choices[0]) == (
        "taking the Cup to TrayPlace: the left arm holds the Cup by its top grasp (not by its side grasp: the "
        "left arm cannot hold the Cup by its side grasp over the one spot of TrayPlace it reaches)"
    )


def test_where_the_hold_ends_is_the_carrys_place_when_the_task_gives_it_and_else_unknown(tmp_path: Path) -> None:
    kb = cup_to_the_tray(tmp_path)
    plan = Composer(kb).compose("PutCupOnTray").plan
    assert plan is not None
    cup, place = designator(WORLD + "Cup", HOME + "Cup"), designator(WORLD + "TrayPlace", HOME + "ObjectPlace")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        ctx = SimContext(world, kb)
        assert hold_end(ctx, "Cup") is None  # no plan: a component run on its own
        ctx.plan, ctx.given, ctx.component = plan, {"cup": cup, "place": place}, APPROACH
        found = hold_end(ctx, "Cup")
        assert found is not None
        where, surface, spots = found
        assert where.iri == WORLD + "TrayPlace" and spots[0] == pytest.approx((7.56, 3.08))
        assert surface.zmin == pytest.approx(0.75)

        carry = next(s for s in plan.steps if s.action == PREFIXES["act"] + "CarryingWhileLocomoting")
        from_a_step = replace(
            carry, bindings=tuple(replace(b, source=Source("objectPlace", step=1)) for b in carry.bindings)
        )
        ctx.plan = replace(plan, steps=tuple(from_a_step if s is carry else s for s in plan.steps))
        assert hold_end(ctx, "Cup") is None  # the place is another step's output: not known here

        approach = next(s for s in plan.steps if APPROACH in s.candidates)
        twice = replace(approach, index=len(plan.steps) + 1)
        ctx.plan = replace(plan, steps=(*plan.steps, twice))
        assert hold_end(ctx, "Cup") is None  # two steps of the component: which one runs is not passed

        ctx.plan = replace(plan, steps=tuple(s for s in plan.steps if s is not carry))
        assert hold_end(ctx, "Cup") is None  # no carry follows


def test_the_executor_says_which_step_runs_and_what_an_earlier_step_gave_the_carry(tmp_path: Path) -> None:
    """What the IRI alone leaves open, the executor's start of a step settles (SimEnvironment.starting):
    which of two steps of one component runs, and a place an earlier step output for the carry."""
    kb = cup_to_the_tray(tmp_path)
    plan = Composer(kb).compose("PutCupOnTray").plan
    assert plan is not None
    cup, place = designator(WORLD + "Cup", HOME + "Cup"), designator(WORLD + "TrayPlace", HOME + "ObjectPlace")
    carry = next(s for s in plan.steps if s.action == PREFIXES["act"] + "CarryingWhileLocomoting")
    approach = next(s for s in plan.steps if APPROACH in s.candidates)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        ctx = environment.context
        ctx.given, ctx.component = {"cup": cup}, APPROACH
        from_a_step = replace(
            carry, bindings=tuple(replace(b, source=Source("objectPlace", step=1)) for b in carry.bindings)
        )
        later = replace(approach, index=len(plan.steps) + 1)  # the same component again, after the carry
        ctx.plan = replace(plan, steps=(*(from_a_step if s is carry else s for s in plan.steps), later))
        assert hold_end(ctx, "Cup") is None  # neither which step runs nor the place is known

        environment.starting(approach, {carry.index: {"object": cup, "place": place}})
        found = hold_end(ctx, "Cup")
        assert found is not None and found[0].iri == WORLD + "TrayPlace"

        environment.starting(later, {carry.index: {"object": cup, "place": place}})
        assert hold_end(ctx, "Cup") is None  # no carry follows the later step

        environment.starting(approach, {carry.index: {"object": cup}})
        assert hold_end(ctx, "Cup") is None  # the place is not produced yet
