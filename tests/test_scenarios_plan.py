"""Composition of the paper's two scenarios on the bundled home (section 6.2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.actions.composer import Composer, PlanStatus, store_plan
from cbrs.actions.draw import draw
from cbrs.actions.errors import UnknownTaskError
from cbrs.actions.model import ActionLibrary, resolve_task
from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase
from cbrs.kb.namespaces import expand

SVC = expand("svc:")
ACT = expand("act:")


@pytest.fixture(scope="module")
def composer(bundled_kb: KnowledgeBase) -> Composer:
    return Composer(bundled_kb)


def names(components: list[str]) -> list[str]:
    return [c.removeprefix(SVC) for c in components]


def test_put_cup_decomposes_into_the_four_actions_in_order(composer: Composer) -> None:
    result = composer.compose("PutCupBelowOfTapOfWaterDispenser")
    assert result.status is PlanStatus.PLANNED and result.plan is not None
    plan = result.plan
    actions = [s.action.removeprefix(ACT) for s in plan.steps if s.action]
    assert actions == ["ApproachToObject", "PickingUpAnObject", "CarryingWhileLocomoting", "PuttingDownAnObject"]
    by_name = {s.component.removeprefix(SVC): s for s in plan.steps}
    approach = by_name["ApproachToObject_CytonDualArm01"]
    feeds = {b.name: plan.step(b.source.step).component.removeprefix(SVC) for b in approach.inputs if b.source.step}
    assert feeds == {
        "objectPosition": "RecogniseObjectByColour_Kinect01",
        "graspPose": "ComputeGraspPose_CytonDualArm01",
    }
    recognise = by_name["RecogniseObjectByColour_Kinect01"]
    assert plan.step(recognise.inputs[0].source.step).component == SVC + "InferObjectProperty_HomeServer01"
    grasp = by_name["ComputeGraspPose_CytonDualArm01"]
    assert plan.step(grasp.inputs[0].source.step).component == SVC + "QueryManipulationProperty_HomeServer01"
    carry = by_name["CarryObject_CytonDualArm01"]
    assert [(b.name, b.source.step, b.source.name) for b in carry.inputs] == [("targetPlace", None, "belowOfTap")]
    assert plan.goals[0].source.step == by_name["PutDownObject_CytonDualArm01"].index


def test_fetch_my_pen_is_complete_and_every_input_is_bound(composer: Composer) -> None:
    result = composer.compose("FetchMyPen")
    assert result.status is PlanStatus.PLANNED and result.plan is not None
    plan = result.plan
    ads = {ad.iri: ad for ad in composer.advertisements}
    for step in plan.steps:
        ad = ads[step.component]
        assert len(step.inputs) == len(ad.inputs)
        assert len(step.preconditions) == len(ad.preconditions)
        for binding in step.bindings:
            assert binding.source.step is None or binding.source.step < step.index
    used = names(plan.components())
    for needed in (
        "InferObjectPlace_HomeServer01",
        "ProvideGridMap_HomeServer01",
        "PlanPathAStar_HomeServer01",
        "LocateMobileRobot_CeilingCamera01",
        "HandOverOntoPlatform_CytonDualArm01",
        "TrackPerson_CeilingCamera01",
        "DeliverObject_P3DX01",
    ):
        assert needed in used
    actions = [s.action.removeprefix(ACT) for s in plan.steps if s.action]
    assert actions == ["NavigatingToPlace", "HandingOverOntoPlatform", "NavigatingToPerson", "Delivering"]
    # each path planner gets the goal of the navigation it serves
    for navigation, goal_from in (
        ("NavigateToPlace_P3DX01", "InferObjectPlace"),
        ("NavigateToPerson_P3DX01", "TrackPerson"),
    ):
        nav = next(s for s in plan.steps if s.component == SVC + navigation)
        path = next(b for b in nav.inputs if b.name == "path")
        planner = plan.step(path.source.step)
        goal = next(b for b in planner.inputs if b.name == "goal")
        assert plan.step(goal.source.step).component.removeprefix(SVC).startswith(goal_from)
    locate = next(s for s in plan.steps if s.component == SVC + "LocateMobileRobot_CeilingCamera01")
    assert locate.alternatives == (SVC + "LocateMobileRobot_CeilingCamera02",)


def test_robot_arm_serve_a_cup_is_decomposed_by_its_sub_actions(composer: Composer) -> None:
    result = composer.compose("RobotArmServeACup")
    assert result.plan is not None and result.plan.method == "decomposed"
    subs = [s.removeprefix(ACT) for s in result.plan.sub_actions]
    assert subs == ["FindCupOnTable", "PutCupBelowOfTapOfWaterDispenser", "FillCupFromTapOfWaterDispenser"]
    assert names(result.plan.components())[0] == "FindCupOnTable_CytonDualArm01"
    assert names(result.plan.components())[-1] == "FillCupFromTap_CytonDualArm01"
    assert len(result.attempts) == 4 and result.attempts[0].plan is None


def test_deregistering_falls_back_then_reports_the_unmet_need(fresh_bundled_kb: KnowledgeBase) -> None:
    kb = fresh_bundled_kb
    kb.registry.deregister(SVC + "LocateMobileRobot_CeilingCamera01")
    plan = Composer(kb).compose("FetchMyPen").plan
    assert plan is not None
    assert SVC + "LocateMobileRobot_CeilingCamera02" in plan.components()
    kb.registry.deregister(SVC + "LocateMobileRobot_CeilingCamera02")
    result = Composer(kb).compose("FetchMyPen")
    assert result.status is PlanStatus.UNSOLVABLE and result.plan is None
    report = [u.text() for u in result.unsatisfied]
    assert any("precondition (home:MobileRobot, home:isLocalisedIn, home:Room)" in t for t in report)
    assert any("input start (home:RobotLocation)" in t for t in report)


def test_plan_is_stored_and_replaced(fresh_bundled_kb: KnowledgeBase) -> None:
    kb = fresh_bundled_kb
    plan = Composer(kb).compose("PutCupBelowOfTapOfWaterDispenser").plan
    assert plan is not None
    store_plan(kb, plan)
    first = kb.store.count(GraphName.PLANS)
    store_plan(kb, plan)
    assert kb.store.count(GraphName.PLANS) == first > 0
    rows = kb.query(
        "SELECT ?component WHERE { ?plan cbrs:hasStep ?step . "
        "?step cbrs:stepIndex ?i ; cbrs:usesComponent ?component } ORDER BY ?i"
    )
    assert [row["component"].value for row in rows] == plan.components()


def test_task_names_resolve(bundled_kb: KnowledgeBase) -> None:
    library = ActionLibrary.from_kb(bundled_kb)
    assert resolve_task(bundled_kb, library, "FetchMyPen").requirement.iri == expand("req:FetchMyPen")
    by_action = resolve_task(bundled_kb, library, "act:RobotArmServeACup")
    assert by_action.requirement.iri == expand("req:RobotArmServeACup")
    assert by_action.action is not None and len(by_action.action.sub_actions) == 3
    bare = resolve_task(bundled_kb, library, "act:OpeningADoor")
    assert bare.requirement.iri == expand("act:OpeningADoor") and bare.requirement.effects
    with pytest.raises(UnknownTaskError) as error:
        resolve_task(bundled_kb, library, "FetchMyPencil")
    assert "FetchMyPen" in str(error.value) and error.value.name == "FetchMyPencil"


def test_sub_actions_follow_ordering_constraints(bundled_kb: KnowledgeBase) -> None:
    action = ActionLibrary.from_kb(bundled_kb).get(expand("act:PuttingSomethingSomewhere"))
    order = [a.removeprefix(ACT) for a in action.ordered_sub_actions()]
    assert order == ["ApproachToObject", "PickingUpAnObject", "CarryingWhileLocomoting", "PuttingDownAnObject"]


@pytest.mark.parametrize("suffix", [".svg", ".png"])
def test_drawing(composer: Composer, tmp_path: Path, suffix: str) -> None:
    target = draw(composer.compose("FetchMyPen"), tmp_path / f"srg{suffix}")
    data = target.read_bytes()
    assert data.startswith(b"\x89PNG") if suffix == ".png" else b"<svg" in data[:2000]
    with pytest.raises(ValueError, match=r"\.svg or \.png"):
        draw(composer.compose("FetchMyPen"), tmp_path / "srg.pdf")


def test_cli_plan_json_and_exit_codes(tmp_path: Path) -> None:
    runner = CliRunner()
    store = str(tmp_path / "store")
    done = runner.invoke(cli, ["--store", store, "plan", "PutCupBelowOfTapOfWaterDispenser", "--json"])
    assert done.exit_code == 0, done.output
    found = json.loads(done.output)
    assert found["status"] == "planned" and len(found["steps"]) == 8
    assert found["steps"][4]["component"] == SVC + "ApproachToObject_CytonDualArm01"
    text = runner.invoke(cli, ["--store", store, "plan", "FetchMyPen", "--draw", str(tmp_path / "g.svg")])
    assert text.exit_code == 0 and "15 steps" in text.output and (tmp_path / "g.svg").exists()
    runner.invoke(cli, ["--store", store, "deregister", "svc:DeliverObject_P3DX01"])
    failed = runner.invoke(cli, ["--store", store, "plan", "FetchMyPen"])
    assert failed.exit_code == 1
    assert "no component provides" in failed.output and "isWith" in failed.output
    assert "register a component whose effect is (home:Pen, home:isWith, home:Person)" in failed.output
    unknown = runner.invoke(cli, ["--store", store, "plan", "Nope"])
    assert unknown.exit_code == 1 and "no requirement or action named 'Nope'" in unknown.output
    bad = runner.invoke(cli, ["--store", store, "plan", "FetchMyPen", "--draw", str(tmp_path / "g.pdf")])
    assert bad.exit_code == 2 and ".svg or .png" in bad.output
