"""``cbrs plan`` says, from the store alone, what ``cbrs run`` would plan without or refuse for what the
semantic map lacks (``unmapped`` in ``--json``): a step whose component looks with a camera the map does
not place, a thing the task names that the map does not hold. The run's own checks
(``sim.run_checks.unplaced_cameras``, ``actions.runner.ungrounded``); no world is built."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.run_checks import map_cameras, unplaced_cameras, without_camera
from tests.helpers_plan_cli import plan, planned

HOME, SVC = PREFIXES["home"], PREFIXES["svc"]
DATA = Path(__file__).parent / "data" / "turtle_tasks_more"
LOCATE, TRACK = SVC + "LocateMobileRobot_CeilingCamera01", SVC + "TrackPerson_CeilingCamera01"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The bundled home without its first ceiling camera, and a dish rack declared that the map lacks,
    asked for by a goal alone and by an input."""
    location = str(tmp_path_factory.mktemp("plan_unmapped") / "store")
    kb = KnowledgeBase.open(location)
    try:
        kb.update("DELETE WHERE { GRAPH graph:map { svc:CeilingCamera01 ?p ?o } }")
        kb.load([DATA / "dish_rack.ttl"], graph="ontology")
        kb.load([DATA / "put_cup_in_dish_rack_goal_only.ttl", DATA / "put_cup_in_dish_rack.ttl"], graph="requirements")
    finally:
        kb.close()
    return location


def test_a_step_looking_with_a_camera_the_map_does_not_place_is_noted(store: str) -> None:
    found = planned(store, "FetchMyPen")
    steps = {step["index"]: step["component"] for step in found["steps"]}
    cameras = [entry for entry in found["unmapped"] if entry["kind"] == "camera"]
    assert cameras and {entry["component"] for entry in cameras} == {LOCATE, TRACK}
    assert {entry["step"] for entry in cameras} == {n for n, c in steps.items() if c in (LOCATE, TRACK)}
    assert all(entry["camera"] == "CeilingCamera01" and entry["planned_without"] for entry in cameras)
    assert all("which the map does not place" in entry["why"] for entry in cameras)
    assert found["unrunnable"] == []  # the simulation has their skills: the camera is what it lacks
    code, text = plan(store, "FetchMyPen")
    assert code == 0
    track = next(entry["step"] for entry in cameras if entry["component"] == TRACK)
    assert (
        f"\nnote: step {track} svc:TrackPerson_CeilingCamera01 cannot run in the simulated home now: it looks with"
        " CeilingCamera01, which the map does not place" in text
    )
    assert text.count("cbrs run plans without it") == len(cameras)


@pytest.mark.parametrize(("task", "kinds"), [("RackTheCup", ["goal"]), ("PutCupInDishRack", ["input", "goal"])])
def test_a_thing_the_map_does_not_hold_is_noted_as_the_run_refuses_it(store: str, task: str, kinds: list[str]) -> None:
    """In the order the run finds them (it refuses with the first): the inputs, then the goals."""
    found = planned(store, task)
    things = [entry for entry in found["unmapped"] if entry["kind"] != "camera"]
    assert [entry["kind"] for entry in things] == kinds
    assert all(entry["concept"] == HOME + "DishRack" for entry in things)
    goal = things[-1]
    assert goal["goal"] == "(home:Cup, home:isLocated, home:DishRack)" and "nothing in the world is one" in goal["why"]
    code, text = plan(store, task)
    assert code == 0
    assert all(f"\nnote: cbrs run refuses the task: {entry['why']}" in text for entry in things)


def test_a_plan_the_map_fully_supports_has_no_such_note() -> None:
    found = planned(":memory:", "RobotArmServeACup")
    assert found["unmapped"] == []
    code, text = plan(":memory:", "RobotArmServeACup")
    assert code == 0 and "note:" not in text


def test_a_table_top_finder_without_a_placed_camera_on_its_robot_is_planned_and_fails() -> None:
    """The finder looks with the camera mounted on its robot: the run plans it (the simulation implements
    it) and its step fails when it looks; a recogniser of its own camera is planned without."""
    kb = KnowledgeBase.open(":memory:")
    ads = kb.advertisements()
    found = unplaced_cameras(kb, ads, {"CeilingCamera01", "CeilingCamera02"})
    finder = found[SVC + "FindCupOnTable_CytonDualArm01"]
    assert finder[0] == "Kinect01" and not finder[2] and "mounted on CytonDualArm01" in finder[1]
    recogniser = found[SVC + "RecogniseObjectByColour_Kinect01"]
    assert recogniser[0] == "Kinect01" and recogniser[2]
    assert without_camera(ads, {"CeilingCamera01", "CeilingCamera02"}) == {
        iri: why for iri, (_, why, without) in found.items() if without
    }
    assert unplaced_cameras(kb, ads, {"CeilingCamera01", "CeilingCamera02", "Kinect01"}) == {}
    assert map_cameras(kb) == {camera.name for camera in SemanticMap.read(kb).cameras.values()}
