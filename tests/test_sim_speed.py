"""What the simulation's speed changes must keep: static links meet nothing static, and a bad solver
threshold is refused before any client is connected (docs/simulation.md, "Speed")."""

from __future__ import annotations

import math
from collections.abc import Iterator

import pybullet as p
import pytest

from cbrs.sim.world import HomeWorld


@pytest.fixture(scope="module")
def world() -> Iterator[HomeWorld]:
    with HomeWorld.create(seed=0) as built:
        yield built


def _touching(world: HomeWorld, a: str, b: str) -> int:
    return len(p.getContactPoints(world.body(a), world.body(b), physicsClientId=world.client))


def test_the_tables_legs_make_no_contact_with_the_floor_and_the_objects_still_rest_on_the_table(
    world: HomeWorld,
) -> None:
    world.step(0.05)
    assert _touching(world, "Floor", "KitchenTable") == 0
    assert _touching(world, "KitchenTable", "Cup") > 0
    assert _touching(world, "KitchenTable", "Pen") > 0
    assert world.pose("Cup").position[2] > 0.75


@pytest.mark.parametrize(
    "value", [0.0, -1e-5, math.nan, math.inf, "1e-5"], ids=["zero", "negative", "nan", "inf", "str"]
)
def test_a_solver_residual_that_is_not_a_positive_number_is_refused(value: object) -> None:
    with pytest.raises(ValueError, match="solver_residual must be a positive number") as raised:
        HomeWorld.create(seed=0, solver_residual=value)  # type: ignore[arg-type]
    assert repr(value) in str(raised.value)
