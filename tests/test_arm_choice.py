"""Which arm takes an object, and how it reaches the platform, by what each arm can do (sim/arm_choice.py:
who_takes, who_loads, _loading_by): the nearest arm that reaches an object is asked first, and when its
hand cannot take it the other arm that reaches it is asked; loading the platform asks each way in turn,
and so does the plan's loading check before anything moves (run_checks.PlanChecks). A loader
whose one hold's moves its planning refuses sets the object down and takes it anew, as where the end
poses rule every approach out. The arms' refusals are stand-ins (monkeypatched skills), so no task runs:
the cup is put where both arms reach it."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, grounding, run_checks, skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import CannotLoadError, SimEnvironment
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.errors import MovesRefusedError
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.values import designator
from cbrs.sim.world import HomeWorld, Spread, open_world
from tests.test_turtle_tasks_arms import FETCH_MY_CUP

WORLD = PREFIXES["world"]
LEFT, RIGHT = ArmSide.LEFT, ArmSide.RIGHT


def _cup_at(x: float, y: float) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "DELETE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } } "
        f"INSERT {{ GRAPH graph:map {{ world:Cup home:x {x} ; home:y {y} }} }} "
        "WHERE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } }"
    )
    return kb


@pytest.fixture(scope="module")
def both_reach() -> Iterator[tuple[KnowledgeBase, HomeWorld]]:
    """The cup at (7.70, 3.20): 0.66 m from the left mount, 0.69 m from the right one; neither arm holds
    anything and the platform is far."""
    kb = _cup_at(7.70, 3.20)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        yield kb, world


def _seen(world: HomeWorld) -> tuple[ObjectEstimate, ObjectModel]:
    x, y, z = world.pose("Cup").position
    estimate = ObjectEstimate(x, y, z, None, (0.06, 0.06, 0.10), "red", "Kinect01", world.time, 500)
    return estimate, ObjectModel.of(world.map.objects[WORLD + "Cup"])


def _refusing(*sides: ArmSide) -> object:
    real = skills.can_take

    def can_take(world: HomeWorld, seen: ObjectEstimate, side: ArmSide | str, held: ObjectModel) -> str:
        if ArmSide(side) in sides:
            return f"the stand-in refuses the {ArmSide(side).value} arm"
        return real(world, seen, side, held)

    return can_take


def test_the_nearest_arm_that_cannot_take_the_object_leaves_it_to_the_other(
    both_reach: tuple[KnowledgeBase, HomeWorld], monkeypatch: pytest.MonkeyPatch
) -> None:
    kb, world = both_reach
    context = SimEnvironment(world, kb).context
    seen, cup = _seen(world)
    assert arm_choice.reaching(context, seen.x, seen.y) == [LEFT, RIGHT]  # the left is nearer
    assert arm_choice.who_takes(context, seen, cup).arm is LEFT
    monkeypatch.setattr(skills, "can_take", _refusing(LEFT))
    chosen = arm_choice.who_takes(context, seen, cup)
    assert chosen.arm is RIGHT


def test_no_arm_that_can_take_it_is_refused_saying_why_for_each(
    both_reach: tuple[KnowledgeBase, HomeWorld], monkeypatch: pytest.MonkeyPatch
) -> None:
    kb, world = both_reach
    context = SimEnvironment(world, kb).context
    seen, cup = _seen(world)
    monkeypatch.setattr(skills, "can_take", _refusing(LEFT, RIGHT))
    with pytest.raises(SkillFailed) as refused:
        arm_choice.who_takes(context, seen, cup)
    message = str(refused.value)
    assert message.startswith("the stand-in refuses the left arm")  # the nearest arm's refusal first
    assert "nor could the right arm take it: the stand-in refuses the right arm" in message


def test_the_plans_loading_check_passes_the_object_when_the_arm_that_reaches_both_cannot_take_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The cup at (7.70, 3.20): both arms reach it, only the right one the platform. With the right hand
    unable to take it, the plan's check (the same decision the hand-over makes) has the left arm pass it
    to the right, instead of refusing the task; with neither able to, it refuses, saying each way."""
    task = tmp_path / "fetch_my_cup.ttl"
    task.write_text(FETCH_MY_CUP, encoding="utf-8")
    kb = _cup_at(7.70, 3.20)
    kb.load([task], graph="requirements")
    plan = Composer(kb).compose("FetchMyCup").plan
    assert plan is not None
    requirements = {r.iri: r for r in kb.requirements()}
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        joints = {side: world.arm(side).joint_positions() for side in ArmSide}
        monkeypatch.setattr(skills, "can_take", _refusing(RIGHT))
        SimEnvironment(world, kb).given(plan, requirements)  # the left arm passes it: no refusal
        monkeypatch.setattr(skills, "can_take", _refusing(LEFT, RIGHT))
        with pytest.raises(CannotLoadError) as refused:
            SimEnvironment(world, kb).given(plan, requirements)
        assert {side: world.arm(side).joint_positions() for side in ArmSide} == joints
    message = str(refused.value)
    assert refused.value.thing == WORLD + "Cup"
    assert "the stand-in refuses the right arm" in message
    assert "nor passed from the left arm to the right: " in message and "the stand-in refuses the left arm" in message


def test_a_loader_whose_one_hold_the_planning_refuses_sets_the_object_down_and_takes_it_anew(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The cup at (7.90, 3.20), where the right arm reaches it and the platform: its one hold to the
    platform, refused by the stand-in's dry run from where the cup is, is not the end: the right arm
    sets the cup down and takes it anew (before, MovesRefusedError refused the loading)."""
    kb = _cup_at(7.90, 3.20)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = SimEnvironment(world, kb).context
        seen, cup = _seen(world)
        real = arm_choice._loads

        def loads(ctx: SimContext, estimate: ObjectEstimate, *rest: object) -> str:
            if estimate is seen:
                return "the stand-in refuses the one hold"
            return real(ctx, estimate, *rest)  # type: ignore[arg-type]

        monkeypatch.setattr(arm_choice, "_loads", loads)
        base = grounding.docking_pose(world.map.things[WORLD + "KitchenTable"])
        loading = arm_choice.who_loads(context, seen, cup, base)
    assert loading.giver is not None and loading.spot is not None
    assert loading.giver.arm is RIGHT and loading.loader.arm is RIGHT
    assert str(loading.giver).startswith("setting the Cup down to take it anew")
    assert "the stand-in refuses the one hold" in str(loading.giver)
    assert loading.giver.model.grasp in (GraspKind.SIDE, GraspKind.TOP)


def test_a_pass_whose_holds_are_refused_at_one_relay_spot_tries_the_next(monkeypatch: pytest.MonkeyPatch) -> None:
    """The bundled cup, which only the left arm reaches, passed to the right arm, which loads the platform:
    with the left arm's carry to the first relay spot refused by the stand-in, the pass goes by the next
    spot; with every carry refused, by none, naming the first refusal (before, the first spot's refusal
    refused the pass)."""
    kb = KnowledgeBase.open(":memory:")
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = SimEnvironment(world, kb).context
        seen, cup = _seen(world)
        base = grounding.docking_pose(world.map.things[WORLD + "KitchenTable"])
        first = arm_choice.who_loads(context, seen, cup, base)
        assert first.giver is not None and first.giver.arm is LEFT and first.spot is not None
        refused_at = first.spot.center
        real = skills.plan_carry

        def plan_carry(
            world: HomeWorld, seen: ObjectEstimate, side: ArmSide | str, *rest: object, **kw: object
        ) -> skills.DryRun:
            region = rest[1] if len(rest) > 1 else None
            if ArmSide(side) is LEFT and isinstance(region, Region) and region.center == refused_at:
                return skills.DryRun("the stand-in refuses this spot")
            return real(world, seen, side, *rest, **kw)  # type: ignore[arg-type]

        monkeypatch.setattr(skills, "plan_carry", plan_carry)
        second = arm_choice.who_loads(context, seen, cup, base)
        monkeypatch.setattr(skills, "plan_carry", lambda *args, **kw: skills.DryRun("the stand-in refuses every spot"))
        with pytest.raises(MovesRefusedError) as refused:
            arm_choice.who_loads(context, seen, cup, base)
    assert second.spot is not None and second.spot.center != refused_at
    assert second.giver is not None and second.giver.arm is LEFT and second.loader.arm is RIGHT
    assert "the stand-in refuses every spot" in str(refused.value) and refused.value.arm == "left"


def test_of_two_arms_that_can_take_it_the_one_that_can_also_set_it_down_where_it_goes_takes_it() -> None:
    """The cup at (7.70, 3.20), the left mount nearer; a tray east of it only the right arm reaches. The
    left arm could take the cup only to pass it on; the right one takes it to the tray itself."""
    tasks = Path(__file__).parent / "data" / "tasks"
    kb = _cup_at(7.70, 3.20)
    kb.update(
        "INSERT DATA { GRAPH graph:map { world:TrayPlace a home:ObjectPlace ; home:minX 8.15 ; home:maxX 8.30 ; "
        "home:minY 3.15 ; home:maxY 3.30 ; home:minZ 0.75 ; home:maxZ 0.75 } }"
    )
    kb.load([tasks / "put_cup_on_tray.ttl"], graph="requirements")
    plan = Composer(kb).compose("PutCupOnTray").plan
    assert plan is not None
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        context = SimEnvironment(world, kb).context
        seen, cup = _seen(world)
        assert arm_choice.reaching(context, seen.x, seen.y) == [LEFT, RIGHT]
        assert arm_choice.who_takes(context, seen, cup).arm is LEFT  # no plan: where it goes is not known
        context.plan, context.component = plan, PREFIXES["svc"] + "ApproachToObject_CytonDualArm01"
        context.given = {
            "cup": designator(WORLD + "Cup", PREFIXES["home"] + "Cup"),
            "place": designator(WORLD + "TrayPlace", PREFIXES["home"] + "ObjectPlace"),
        }
        chosen = arm_choice.who_takes(context, seen, cup)
    assert chosen.arm is RIGHT and chosen.purpose == "taking the Cup to TrayPlace"


def test_the_loading_check_does_not_refuse_an_object_loadable_a_centimetre_from_where_it_is_believed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The perturbation benchmark's world seed 19: the pen at the edge of the right arm's planning, refused
    from its believed centre (8.1015, 3.3317) and loaded at the hand-over from the Kinect's estimate 6 mm
    away. The check asks LOADING_SLACK around the believed centre before it refuses."""
    kb = KnowledgeBase.open(":memory:")
    plan = Composer(kb).compose("FetchMyPen").plan
    assert plan is not None
    requirements = {r.iri: r for r in kb.requirements()}
    spread = Spread(object=0.04, yaw=0.5, person=0.8, base=0.3, base_yaw=math.pi)
    with open_world(seed=19, semantic_map=SemanticMap.read(kb), spread=spread) as world:
        environment = SimEnvironment(world, kb)
        environment.perceive()
        environment.given(plan, requirements)  # not refused
        monkeypatch.setattr(run_checks, "LOADING_SLACK", 0.0)
        with pytest.raises(CannotLoadError) as refused:
            environment.given(plan, requirements)
    assert "no inverse kinematics at" in str(refused.value)
