"""An object one arm let go of and the other took on is believed where the taking hand holds it,
whichever arm the belief feels first (sim/perceived.py, ``PerceivedWorld.feel``)."""

from __future__ import annotations

import math

import pytest

from cbrs.sim.arms import ArmSide
from cbrs.sim.grasping import ObjectModel, compute_grasp_pose
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.world import HomeWorld, open_world


def _pass(world: HomeWorld, giver: ArmSide, taker: ArmSide) -> None:
    """The giver takes the pen and lets it go, then the taker holds it (no physics step: the hands stay
    where they are, so the giver's release and the taker's hold are far apart)."""
    pen = world.objects["Pen"]
    model = ObjectModel.of(world.map.objects[pen.iri])
    centre = world.pose("Pen").position
    for side in (giver, taker):
        spec = world.arm_specs[side]
        world.arm(side).attach(
            world.body("Pen"), compute_grasp_pose(model, centre, pen.start.yaw, spec.mount, spec.yaw)
        )
        if side is giver:
            world.arm(side).detach()


@pytest.mark.parametrize(("giver", "taker"), [(ArmSide.RIGHT, ArmSide.LEFT), (ArmSide.LEFT, ArmSide.RIGHT)])
def test_the_hand_that_holds_an_object_now_wins_over_where_the_other_let_it_go(giver: ArmSide, taker: ArmSide) -> None:
    with open_world(seed=0) as world:
        belief = PerceivedWorld(world)
        _pass(world, giver, taker)
        released = world.arm(giver).released
        held = world.arm(taker).carried_centre()
        assert released is not None and held is not None
        assert math.dist(released[1], held) > 0.1  # the two hands are apart: the belief tells them apart
        belief.feel()
        sighting = belief.objects["Pen"]
        assert sighting.source == f"{taker.value} hand"
        assert sighting.position == pytest.approx(held)
        belief.feel()  # felt again, the release (already felt) does not come back
        assert belief.objects["Pen"].position == pytest.approx(held)


def test_an_object_let_go_and_not_taken_on_is_where_the_hand_let_it_go() -> None:
    with open_world(seed=0) as world:
        belief = PerceivedWorld(world)
        belief.feel()
        right = world.arm(ArmSide.RIGHT)
        pen = world.objects["Pen"]
        spec = world.arm_specs[ArmSide.RIGHT]
        model = ObjectModel.of(world.map.objects[pen.iri])
        grasp = compute_grasp_pose(model, world.pose("Pen").position, pen.start.yaw, spec.mount, spec.yaw)
        right.attach(world.body("Pen"), grasp)
        right.detach()
        released = right.released
        assert released is not None
        belief.feel()
        assert belief.objects["Pen"].source == "right hand, let go"
        assert belief.objects["Pen"].position == pytest.approx(released[1])
