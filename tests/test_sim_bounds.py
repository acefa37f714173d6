"""The arm copies' contact queries skip what is too far away to touch (sim/arms.py: Kinematics._near):
a fixed thing or the other arm whose bounding box is farther from the copy's than the query's distance
is not asked, and `hits` and `strikes` answer as they would asking every one of them."""

from __future__ import annotations

import random
from collections.abc import Iterator
from typing import Any

import pybullet as p
import pytest

from cbrs.sim import arms
from cbrs.sim.arms import COLLISION_MARGIN, FINGER_JOINTS, STRIKE_DEPTH, ArmSide, Kinematics
from cbrs.sim.geometry import Region

MOUNTS = {
    ArmSide.LEFT: ((0.0, 0.2, 0.8), (0.0, 0.0, 0.0, 1.0)),
    ArmSide.RIGHT: ((0.0, -0.2, 0.8), (0.0, 0.0, 0.0, 1.0)),
}
OBSTACLES = [
    Region("Torso", -0.25, 0.1, -0.35, 0.35, 0.0, 0.8),
    Region("Table", 0.3, 1.2, -0.6, 0.6, 0.7, 0.75),
    Region("Shelf", 0.4, 0.6, 0.5, 0.8, 0.75, 1.3),
    Region("Far", 3.0, 3.5, 3.0, 3.5, 0.0, 2.0),  # out of every posture's reach
]


@pytest.fixture(scope="module")
def kinematics() -> Iterator[Kinematics]:
    k = Kinematics(MOUNTS, OBSTACLES)
    yield k
    k.close()


def _every_target(k: Kinematics, side: ArmSide, q: list[float], other: ArmSide, oq: list[float]) -> list[Any]:
    """The points each fixed thing and the other arm has within the margin and within contact of the copy at
    ``q``, asking every one of them."""
    body = k._bodies[side]
    k._set(body, q)
    k._set(k._bodies[other], oq)
    targets = [*k._obstacles, k._bodies[other]]
    return [
        (
            p.getClosestPoints(body, target, COLLISION_MARGIN, physicsClientId=k.client),
            p.getClosestPoints(body, target, 0.0, physicsClientId=k.client),
        )
        for target in targets
    ]


def test_far_things_are_not_asked_and_the_answers_are_those_of_asking_all(
    kinematics: Kinematics, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = random.Random(7)
    asked = [0]
    original = p.getClosestPoints

    def counted(*args: Any, **kwargs: Any) -> Any:
        asked[0] += 1
        return original(*args, **kwargs)

    hit, clear, struck = 0, 0, 0
    for _ in range(150):
        side = rng.choice(list(ArmSide))
        other = ArmSide.RIGHT if side is ArmSide.LEFT else ArmSide.LEFT
        q = [rng.uniform(a, b) for a, b in zip(arms._LOWER, arms._UPPER, strict=True)]
        oq = [rng.uniform(a, b) for a, b in zip(arms._LOWER, arms._UPPER, strict=True)]
        every = _every_target(kinematics, side, q, other, oq)
        names = [*(region.name for region in OBSTACLES), f"{other.value} arm"]
        expected_hit = next(
            (name for name, (near, _) in zip(names, every, strict=True) if any(pt[3] > 0 for pt in near)), ""
        )
        expected_strike = any(
            pt[3] > 0 and pt[3] not in FINGER_JOINTS and pt[8] < -STRIKE_DEPTH
            for _, touching in every
            for pt in touching
        )
        monkeypatch.setattr(p, "getClosestPoints", counted)
        got_hit = kinematics.hits(side, q, {other: oq})
        got_strike = kinematics.strikes(side, q, {other: oq})
        monkeypatch.setattr(p, "getClosestPoints", original)
        assert got_hit.removeprefix("the ") == expected_hit, (side, q, oq)
        assert got_strike == expected_strike, (side, q, oq)
        hit += bool(expected_hit)
        clear += not expected_hit
        struck += expected_strike
    assert hit and clear and struck  # both answers came up, so the comparison could fail
    assert asked[0] < 150 * 2 * len(OBSTACLES)  # the far thing at least was never asked


def test_an_arm_copy_put_elsewhere_has_its_box_taken_again(kinematics: Kinematics) -> None:
    """The box kept for a copy is its posture's: put elsewhere, the copy's box is taken anew."""
    left = kinematics._bodies[ArmSide.LEFT]
    kinematics._set(left, arms.HOME_CONFIGURATIONS[ArmSide.LEFT])
    home = kinematics._box_of(left)
    kinematics._set(left, [0.0, 0.9, 0.0, -0.5, 0.0, 1.4, 0.0])  # reaching forwards and down
    reaching = kinematics._box_of(left)
    assert reaching != home
    low, high = p.getAABB(left, 8, physicsClientId=kinematics.client)  # the hand
    assert all(reaching[0][i] <= low[i] and high[i] <= reaching[1][i] for i in range(3))
