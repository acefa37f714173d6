"""The simulated home: layout, entities, life cycle, several worlds side by side, determinism."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from cbrs.sim import HomeWorld, UnknownEntityError, WorldClosedError, open_world
from cbrs.sim import predicates as pred
from cbrs.sim.skills import navigate
from tests.home_layout import (
    BASE_START,
    CAMERAS,
    CUP_START,
    HANDOVER_POSE,
    PEN_START,
    PERSON_START,
    ROOMS,
    TABLE,
    room_of,
)


@pytest.fixture(scope="module")
def world() -> Iterator[HomeWorld]:
    with HomeWorld.create(seed=0) as w:
        yield w


def test_the_entities_of_the_ontology_are_there(world: HomeWorld) -> None:
    for name in ("P3DX01", "CytonDualArm01", "Kinect01", "Cup", "Pen", "Person", "KitchenTable", "WaterDispenser01"):
        assert world.body(name) >= 0
    assert set(world.cameras) == {*CAMERAS, "Kinect01"}
    with pytest.raises(UnknownEntityError) as error:
        world.body("Sofa")
    assert error.value.name == "Sofa"
    assert "Cup" in error.value.known


def test_rooms_match_the_ontology_floor_plan() -> None:
    assert (ROOMS["LivingRoom"].xmax, ROOMS["LivingRoom"].ymax) == (6.0, 5.0)
    assert (ROOMS["Kitchen"].xmin, ROOMS["Kitchen"].xmax) == (6.0, 10.0)
    assert (ROOMS["Bedroom"].ymin, ROOMS["Bedroom"].ymax) == (5.0, 9.0)
    assert room_of(*BASE_START.xy) == "LivingRoom"
    assert room_of(*HANDOVER_POSE.xy) == "Kitchen"
    assert room_of(*PERSON_START) == "LivingRoom"
    assert room_of(8.0, 7.0) is None
    assert (TABLE.xmin, TABLE.xmax, TABLE.ymin, TABLE.ymax) == (7.0, 8.5, 3.0, 4.5)


def test_objects_start_on_the_table_near_their_nominal_place(world: HomeWorld) -> None:
    cup = world.pose("Cup").position
    pen = world.pose("Pen").position
    assert math.dist(cup[:2], CUP_START) < 0.03
    assert math.dist(pen[:2], PEN_START) < 0.03
    assert pred.object_located_in(world, "Cup", TABLE)
    assert pred.object_located_in(world, "Pen", TABLE)
    assert not pred.is_grasped(world, "Cup")
    assert world.water_level("Cup") == 0.0


def test_base_and_person_start_in_the_living_room(world: HomeWorld) -> None:
    base = world.base_pose()
    person = world.pose("Person").position
    assert base.distance_to(*BASE_START.xy) < 0.15
    assert math.dist(person[:2], PERSON_START) < 0.22
    assert room_of(base.x, base.y) == "LivingRoom"


def test_step_advances_fixed_steps(world: HomeWorld) -> None:
    before, steps = world.time, world.steps
    world.step(0.1)
    assert world.steps - steps == round(0.1 / world.time_step)
    assert world.time == pytest.approx(before + 0.1)


def test_seed_moves_things_deterministically() -> None:
    with HomeWorld.create(seed=7) as a, HomeWorld.create(seed=7) as b, HomeWorld.create(seed=8) as c:
        assert a.client != b.client != c.client
        assert a.snapshot() == b.snapshot()
        assert a.snapshot()["Cup"] != c.snapshot()["Cup"]
        assert a.perturbation == b.perturbation != c.perturbation


def test_two_worlds_interleaved_stay_independent_and_repeat_exactly() -> None:
    waypoints = [(4.0, 1.5), (4.0, 3.0)]
    with HomeWorld.create(seed=3) as a, HomeWorld.create(seed=3) as b:
        a.step(0.05)
        b.step(0.05)
        for waypoint in waypoints:  # one leg in a, the same leg in b, and so on
            assert navigate(a, [waypoint]).succeeded
            assert navigate(b, [waypoint]).succeeded
        assert a.base_pose() == b.base_pose()
        assert a.time == b.time


def test_a_closed_world_refuses_to_work() -> None:
    with open_world(seed=1) as world:
        pass
    assert world.closed
    with pytest.raises(WorldClosedError):
        world.step(0.1)
    world.close()  # twice is fine
