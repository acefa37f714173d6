"""The approach choice asks whether the arm's own motion planning would make the moves of the hold, not only
whether the hand can be at its end poses: a dry run of the approach, the pick-up and the carry on the
kinematics copies (skills.can_carry, arms.PlannedArm). An approach whose moves it would refuse is ranked
after one whose moves it would make; when it would refuse every one, the step fails before anything moves
(sim/arm_choice.py: taking; sim/hold_choice.py: first_clear)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, hold_choice, skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.errors import MovesRefusedError
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.perception import ObjectEstimate, recognise_object
from cbrs.sim.world import HomeWorld, open_world
from tests.test_grasp_approaches import cup_grasps
from tests.test_grasp_lookahead import TASKS, tray
from tests.test_turtle_tasks_arms import knowledge

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
LARGER_TRAY = tray(7.52, 7.60, 3.04, 3.12)
"""In front of the left mount, larger than test_grasp_lookahead's: its spot nearest the centre the left hand
can let the cup go over by its side grasp, (7.54, 3.10), it cannot carry it to without the cup dipping
(the straight line leaves its reach; every joint-space path swings the hand down)."""
SPOT = Region("TrayPlaceSpot", 7.52, 7.56, 3.08, 3.12, 0.75, 1.05)  # centred on (7.54, 3.10)


def cup_to_the_larger_tray(tmp_path: Path) -> KnowledgeBase:
    return knowledge(
        tmp_path,
        ("ontology", cup_grasps("side top")),
        ("map", LARGER_TRAY),
        ("requirements", TASKS / "put_cup_on_tray.ttl"),
    )


def _cup(world: HomeWorld) -> tuple[ObjectEstimate, ObjectModel]:
    assert skills.clear_view(world).succeeded
    seen = recognise_object(world.camera("Kinect01").capture(), "red", near=(7.45, 3.32), radius=0.1)
    return seen, ObjectModel.of(world.map.objects[WORLD + "Cup"])


def test_on_the_larger_tray_the_cup_is_taken_from_the_top_and_put_there_without_a_replan(tmp_path: Path) -> None:
    """Before, the side grasp passed the end poses' inverse kinematics, the cup was taken so, and the carry
    failed twice with no collision-free joint path to (7.54, 3.10) above 0.84 m: the run stopped."""
    kb = cup_to_the_larger_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "PutCupOnTray", environment, composer=Composer(kb))
        choices = list(environment.context.choices)
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    facts = {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}
    assert (WORLD + "Cup", HOME + "isLocated", WORLD + "TrayPlace") in facts
    assert [(c.arm, c.model.grasp) for c in choices] == [(ArmSide.LEFT, GraspKind.TOP)]
    assert str(choices[0]).startswith(
        "taking the Cup to TrayPlace: the left arm holds the Cup by its top grasp (not by its side grasp: the left "
        "arm would not get the Cup by its side grasp past carrying it to (7.54, 3.10): no inverse kinematics at "
        "(7.540, 3.100"
    )


def test_the_dry_run_refuses_what_the_end_poses_allow_and_moves_nothing(tmp_path: Path) -> None:
    kb = cup_to_the_larger_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        seen, cup = _cup(world)
        before, started = {side: world.arm(side).joint_positions() for side in ArmSide}, world.time
        side, top = cup.by(GraspKind.SIDE), cup.by(GraspKind.TOP)
        assert skills.can_take(world, seen, ArmSide.LEFT, side) == ""
        assert skills.can_set_down(world, seen, ArmSide.LEFT, side, SPOT) == ""  # the end poses: yes
        refused = skills.can_carry(world, seen, ArmSide.LEFT, side, SPOT)
        assert skills.can_carry(world, seen, ArmSide.LEFT, top, SPOT) == ""
        assert skills.can_carry(world, seen, ArmSide.LEFT, side) == ""  # taking and lifting it: yes
        after, ended = {s: world.arm(s).joint_positions() for s in ArmSide}, world.time
    assert "past carrying it to (7.54, 3.10): no inverse kinematics at (7.540, 3.100" in refused
    assert refused.endswith("from any seed posture: the arm cannot reach it, the hand so turned")
    assert after == before and ended == started  # nothing moved, no physics step


def test_the_dry_run_plans_the_moves_the_arm_makes(tmp_path: Path) -> None:
    """A dry run's reach ends where the arm's own reach, made after it, is planned to end: they are one plan."""
    kb = cup_to_the_larger_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        seen, cup = _cup(world)
        spec = world.arm_specs[ArmSide.LEFT]
        grasp = compute_grasp_pose(cup, seen.position, seen.yaw, spec.mount, spec.yaw, (seen.size[0], seen.size[1]))
        arm = world.arm(ArmSide.LEFT)
        planned = arm.dry_run()
        assert planned.reach(grasp.pregrasp, grasp.orientation).reached
        assert planned.move_to(grasp.position, grasp.orientation).reached
        assert arm.reach(grasp.pregrasp, grasp.orientation).reached
        assert arm.move_to(grasp.position, grasp.orientation).reached
        made = arm.joint_positions()
    assert made == pytest.approx(planned.joint_positions(), abs=0.02)


def test_an_approach_the_dry_run_refuses_is_ranked_after_not_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With every approach's moves refused by the dry run, the step fails before anything moves, naming
    each approach: the real moves, planned the same way, would fail after moving (nu16 repro 04)."""
    kb = cup_to_the_larger_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        seen, cup = _cup(world)
        context = SimEnvironment(world, kb).context
        monkeypatch.setattr(skills, "can_carry", lambda *args: "refused by the stand-in")
        with pytest.raises(MovesRefusedError) as everything_refused:
            arm_choice.taking(context, seen, cup, ArmSide.LEFT)
        monkeypatch.setattr(skills, "can_carry", lambda w, e, s, held, *r: "no" if held.grasp is GraspKind.SIDE else "")
        side_refused = arm_choice.taking(context, seen, cup, ArmSide.LEFT)
    refused = everything_refused.value
    assert (refused.name, refused.arm) == ("Cup", "left")
    assert refused.refused == (("side", None, "refused by the stand-in"), ("top", None, "refused by the stand-in"))
    assert side_refused.model.grasp is GraspKind.TOP and side_refused.passed == ((GraspKind.SIDE, "no"),)


def test_one_approach_left_to_choose_is_dry_run_too(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A lone candidate's moves are planned before it is taken: refused, the step fails before anything
    moves, naming the object, the arm, the approach and the spot the carry would aim at."""
    kb = cup_to_the_larger_tray(tmp_path)
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        seen, cup = _cup(world)
        context = SimEnvironment(world, kb).context
        asked: list[GraspKind] = []
        monkeypatch.setattr(skills, "can_carry", lambda w, e, s, held, *r: asked.append(held.grasp) or "")
        both = arm_choice.taking(context, seen, cup, ArmSide.LEFT)
    assert both.model.grasp is GraspKind.SIDE and asked == [GraspKind.SIDE]
    asked.clear()
    alone = hold_choice.Candidates([cup.by(GraspKind.TOP)], [(GraspKind.SIDE, "ruled out")])
    choice = hold_choice.first_clear(alone, ArmSide.LEFT, "taking the Cup", lambda held: asked.append(held.grasp) or "")
    assert choice.model.grasp is GraspKind.TOP and choice.passed == ((GraspKind.SIDE, "ruled out"),)
    assert asked == [GraspKind.TOP]
    with pytest.raises(MovesRefusedError) as refused:
        hold_choice.first_clear(
            alone, ArmSide.LEFT, "taking the Cup to TrayPlace", lambda held: "no path", {GraspKind.TOP: SPOT}
        )
    error = refused.value
    assert (error.name, error.arm, error.refused, error.ruled_out) == (
        "Cup",
        "left",
        (("top", pytest.approx((7.54, 3.10)), "no path"),),
        (("side", "ruled out"),),
    )
    assert str(error).startswith("taking the Cup to TrayPlace: refused before anything moved")
