"""A spot to set an object down by a side grasp keeps the arm behind the hand off what stands there
(sim/place_spots.py, ArmBehind): a cup 20-26 cm straight behind the spot below the tap, clear of the set-down
cup's footprint, was under the forearm as the hand came down. Given the arm behind the grasp (the hand's
bands from the store), such a spot is passed over for the next, and a place with no other is refused."""

from __future__ import annotations

import math

from cbrs.kb.namespaces import PREFIXES
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.place_spots import ArmBehind, place_spots, reach_of
from cbrs.sim.scene import bundled_map

WORLD = PREFIXES["world"]


def test_a_spot_whose_arm_comes_down_on_a_cup_behind_it_is_passed_over() -> None:
    smap = bundled_map()
    table, below = smap.things[WORLD + "KitchenTable"], smap.things[WORLD + "BelowOfTap"]
    cup = smap.objects[WORLD + "Cup"]
    left = smap.arms[WORLD + "CytonDualArm01LeftArm"]
    hand = smap.hands[left.iri]
    mounts = [reach_of(arm) for arm in smap.arms.values()]
    surface, first = place_spots(smap, table, cup.size, mounts, [])
    x, y = first[0]
    radius = math.hypot(cup.size[0], cup.size[1]) / 2.0
    behind = (x, y - 0.22, radius)  # the arms face +y: 22 cm straight back towards the robot
    grasp = ObjectModel.of(cup).grasp_height

    def standing(top: float) -> ArmBehind:
        return ArmBehind(left.yaw, grasp, hand.side_arm, ((*behind, surface.zmin + top),))

    # the cup behind is clear of the set-down cup's footprint: without the arm, the first spot stays first
    assert place_spots(smap, table, cup.size, mounts, [behind])[1][0] == (x, y)
    _, spots = place_spots(smap, table, cup.size, mounts, [behind], standing(cup.size[2]))
    assert spots and (x, y) not in spots
    assert standing(cup.size[2]).comes_down_on((x, y), surface.zmin)
    assert not standing(cup.size[2]).comes_down_on(spots[0], surface.zmin)
    # a thing lying flat there (1 cm high) is under the arm's underside: the spot stays first
    assert place_spots(smap, table, cup.size, mounts, [behind], standing(0.01))[1][0] == (x, y)
    # below the tap every spot has the cup under the forearm: the place is refused
    assert place_spots(smap, below, cup.size, mounts, [])[1]
    assert place_spots(smap, below, cup.size, mounts, [behind], standing(cup.size[2]))[1] == []
