"""Each skill's success and the predicate of its effect; the failures a skill must report."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from cbrs.kb.namespaces import PREFIXES
from cbrs.sim import (
    ArmSide,
    HomeWorld,
    Pose2D,
    compute_grasp_pose,
    locate_robot,
    recognise_object,
    skills,
    track_person,
)
from cbrs.sim import predicates as pred
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.mapping import build_occupancy_grid
from cbrs.sim.planning import approach_point, plan_path
from cbrs.sim.scene import bundled_map
from tests.home_layout import ARM_FACING, ARM_MOUNTS, BELOW_OF_TAP, HANDOVER_POSE, TABLE, TAP_LEVER
from tests.reference_scenarios import PERSON_APPROACH_DISTANCE

CUP = ObjectModel.of(bundled_map().objects[PREFIXES["world"] + "Cup"])
PEN = ObjectModel.of(bundled_map().objects[PREFIXES["world"] + "Pen"])


@pytest.fixture
def world() -> Iterator[HomeWorld]:
    with HomeWorld.create(seed=5) as w:
        yield w


def test_serving_a_cup_skill_by_skill(world: HomeWorld) -> None:
    left, right = ArmSide.LEFT, ArmSide.RIGHT
    assert skills.clear_view(world).succeeded
    cup = recognise_object(world.camera("Kinect01").capture(), CUP.colour)
    grasp = compute_grasp_pose(CUP, cup.position, cup.yaw, ARM_MOUNTS[left.value], ARM_FACING[left.value])

    assert not pred.gripper_near(world, left, "Cup")
    outcome = skills.approach_object(world, left, grasp)
    assert outcome.succeeded, outcome.reason
    assert pred.gripper_near(world, left, "Cup") and pred.object_located_in(world, "Cup", TABLE)

    outcome = skills.pick_up_object(world, left, grasp)
    assert outcome.succeeded, outcome.reason
    assert pred.is_grasped(world, "Cup", left) and not pred.is_grasped(world, "Cup", right)
    assert not pred.object_located_in(world, "Cup", TABLE)  # lifted

    outcome = skills.carry_object(world, left, BELOW_OF_TAP)
    assert outcome.succeeded, outcome.reason
    assert pred.object_above_region(world, "Cup", BELOW_OF_TAP) and not pred.upright_in(world, "Cup", BELOW_OF_TAP)

    outcome = skills.put_down_object(world, left, BELOW_OF_TAP)
    assert outcome.succeeded, outcome.reason
    assert pred.upright_in(world, "Cup", BELOW_OF_TAP) and not pred.is_grasped(world, "Cup")
    assert not pred.object_above_region(world, "Cup", BELOW_OF_TAP)

    assert not pred.contains_water(world, "Cup")
    outcome = skills.fill_cup_from_tap(world, right, TAP_LEVER, "Cup")
    assert outcome.succeeded, outcome.reason
    assert pred.contains_water(world, "Cup") and world.water_level("Cup") == pytest.approx(1.0)
    assert world.water_spilled < 0.2  # only while the lever moved in and out
    assert not world.tap_open()
    assert pred.upright_in(world, "Cup", BELOW_OF_TAP)
    for outcome_time in (outcome.started, outcome.finished):
        assert outcome_time <= world.time


def test_fetching_a_pen_skill_by_skill(world: HomeWorld) -> None:
    camera = world.camera("CeilingCamera01")
    grid = build_occupancy_grid(world)
    start = locate_robot(camera.capture(), world.marker_model)
    path = plan_path(grid, (start.x, start.y), HANDOVER_POSE.xy)
    assert not pred.base_near(world, HANDOVER_POSE)
    outcome = skills.navigate_to_place(world, path, HANDOVER_POSE)
    assert outcome.succeeded, outcome.reason
    assert pred.base_near(world, HANDOVER_POSE, heading=True)
    assert pred.robot_visible(world, "CeilingCamera01") and pred.robot_visible(world, "CeilingCamera02")

    parked = locate_robot(camera.capture(), world.marker_model)
    pen = recognise_object(world.camera("Kinect01").capture(), PEN.colour)
    assert not pred.on_platform(world, "Pen")
    outcome = skills.hand_over_onto_platform(world, pen, parked, ArmSide.RIGHT, PEN, 0.85)
    assert outcome.succeeded, outcome.reason
    assert pred.on_platform(world, "Pen") and not pred.is_grasped(world, "Pen")

    person = track_person(camera.capture())
    here = locate_robot(camera.capture(), world.marker_model)
    goal = approach_point((person.x, person.y), (here.x, here.y), PERSON_APPROACH_DISTANCE)
    path = plan_path(grid, (here.x, here.y), goal, "dijkstra")
    assert not pred.base_near_person(world)
    outcome = skills.navigate_to_person(world, path, person)
    assert outcome.succeeded, outcome.reason
    assert pred.base_near_person(world)
    assert pred.on_platform(world, "Pen"), "the pen must ride on the platform, carried by friction"

    assert not pred.with_person(world, "Pen")
    outcome = skills.deliver_object(world)
    assert outcome.succeeded, outcome.reason
    assert pred.with_person(world, "Pen") and not pred.on_platform(world, "Pen")


def test_skills_refuse_what_they_cannot_do(world: HomeWorld) -> None:
    cup = recognise_object(world.camera("Kinect01").capture(), CUP.colour)
    grasp = compute_grasp_pose(CUP, cup.position, cup.yaw, ARM_MOUNTS["left"], ARM_FACING["left"])
    refused = [
        (skills.pick_up_object(world, "left", grasp), "not near"),
        (skills.carry_object(world, "left", BELOW_OF_TAP), "holds nothing"),
        (skills.put_down_object(world, "left", BELOW_OF_TAP), "holds nothing"),
        (skills.deliver_object(world), "not near Person"),
        (
            skills.hand_over_onto_platform(world, cup, world.base_pose(), ArmSide.RIGHT, CUP, 0.85),
            "out of the right arm's reach",
        ),
        (skills.navigate(world, []), "no waypoints"),
    ]
    for outcome, reason in refused:
        assert not outcome.succeeded
        assert reason in outcome.reason
        assert outcome.sim_seconds == 0.0  # refused before moving
    assert pred.object_located_in(world, "Cup", TABLE)


def test_filling_with_no_cup_below_the_tap_fails_and_spills(world: HomeWorld) -> None:
    outcome = skills.fill_cup_from_tap(world, ArmSide.RIGHT, TAP_LEVER, "Cup")
    assert not outcome.succeeded
    assert "did not catch it" in outcome.reason
    assert world.water_level("Cup") == 0.0 and world.water_spilled > 0.3
    assert not world.tap_open()  # the lever was let go


def test_driving_into_a_wall_stops_blocked(world: HomeWorld) -> None:
    world.base.place(Pose2D(5.0, 1.0, 0.0))
    world.step(0.05)
    outcome = skills.navigate(world, [(7.0, 1.0)])  # straight through the wall at x = 6
    assert not outcome.succeeded
    assert "blocked" in outcome.reason
    assert world.base_pose().x < 6.0 - 0.2
    assert outcome.sim_seconds < 10.0


def test_navigation_that_cannot_finish_in_time_gives_up(world: HomeWorld) -> None:
    result = world.base.follow([(3.0, 3.0), (3.5, 3.5)], time_limit=0.5)
    assert not result.succeeded
    assert "time limit" in result.reason
    assert result.seconds == pytest.approx(0.5, abs=0.2)


def test_grasp_poses_follow_the_object_models() -> None:
    side = compute_grasp_pose(CUP, (7.45, 3.32, 0.80), None, ARM_MOUNTS["left"], ARM_FACING["left"])
    assert side.position[2] == pytest.approx(0.75 + CUP.grasp_height)
    assert side.approach[1] > 0.5 and side.approach[2] < 0  # in from the robot, tilted down
    assert math.dist(side.pregrasp, side.position) == pytest.approx(0.10)
    top = compute_grasp_pose(PEN, (8.07, 3.3, 0.758), 0.3, ARM_MOUNTS["right"], ARM_FACING["right"])
    assert top.approach == (0.0, 0.0, -1.0)
    assert top.pregrasp[2] == pytest.approx(top.position[2] + 0.10)
