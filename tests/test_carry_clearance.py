"""Where on a place an object is set down is chosen by its carry too: of the spots the hand can let it go
over, the first whose carry keeps CARRY_CLEARANCE from the appliances, a tap's lever included
(sim/arm_choice.py: holdable_spot, carry_clear; sim/arms.py: PlannedArm.brushed). JarOntoTheTable at
seeds 1 and 2 carried a spice jar at the height it was lifted off a rack to the table's spot beside the
dispenser, met the tap's lever and the spout, and stopped 1.5-1.8 cm short twice. Checked here on the
kinematics copies only: the arm is put in the posture it lifts the jar to, and nothing is stepped."""

from __future__ import annotations

import math
from pathlib import Path

import pybullet as p

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import arm_choice, relay, skills
from cbrs.sim.arms import ARM_JOINTS, ArmSide
from cbrs.sim.components import SimEnvironment
from cbrs.sim.grasping import GraspKind, ObjectModel, compute_grasp_pose
from cbrs.sim.place_spots import other_objects, place_spots, spot_region
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
WORLD, LAB = "https://w3id.org/cbrs/world#", "https://example.org/lab#"


def _jar_kb() -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "spice_rack.ttl"], graph="ontology")
    kb.load([EXAMPLES / "spice_rack.ttl"], graph="map")
    kb.load([EXAMPLES / "jar_onto_the_table.ttl"], graph="requirements")
    return kb


def test_the_jar_is_set_down_where_its_carry_keeps_clear_of_the_tap() -> None:
    kb = _jar_kb()
    smap = SemanticMap.read(kb)
    with open_world(seed=1, semantic_map=smap) as world:
        ctx = SimEnvironment(world, kb).context
        side, arm, spec = ArmSide.LEFT, world.arm(ArmSide.LEFT), world.arm_specs[ArmSide.LEFT]
        jar = ObjectModel.of(world.map.objects[LAB + "SpiceJar1"]).by(GraspKind.SIDE)
        x, y, z = world.pose("SpiceJar1").position
        grasp = compute_grasp_pose(jar, (x, y, z), None, spec.mount, spec.yaw, (jar.width, jar.width), arm.hand)
        planned = arm.dry_run()  # the take and the lift, as pick_up_object makes them
        assert planned.reach(grasp.pregrasp, grasp.orientation).reached
        assert planned.move_to(grasp.position, grasp.orientation).reached
        lifted = (grasp.position[0], grasp.position[1], grasp.position[2] + skills.LIFT_HEIGHT)
        assert planned.move_to(lifted, planned.ee_pose().orientation, symmetric=False).reached
        for joint, angle in zip(ARM_JOINTS, planned.joint_positions(), strict=True):
            p.resetJointState(arm.body, joint, angle, physicsClientId=world.client)
        arm.held, arm.held_grasp = world.body("SpiceJar1"), grasp
        size = world.objects["SpiceJar1"].size
        others = other_objects(world, None, "SpiceJar1")
        mounts = [(spec.mount[0], spec.mount[1], spec.reach)]
        surface, spots = place_spots(smap, smap.things[WORLD + "KitchenTableTop"], size, mounts, others)
        first = spot_region(surface, *spots[0])
        unchecked = skills.can_carry_held(world, side, first)  # the arm's planning would; the jar meets the spout
        brushed = arm_choice.carry_clear(ctx, side, first)
        chosen = arm_choice.holdable_spot(ctx, side, surface, spots)
        assert chosen is not None
        clear = arm_choice.carry_clear(ctx, side, spot_region(surface, *chosen))
    assert spots[0] == (7.63, 3.33)  # beside the dispenser, nearest the table's centre
    assert "the SpiceJar1, carried with its bottom at" in unchecked and "of the Spout01" in unchecked  # held_meets
    assert "would come within 1 cm of the Spout01" in brushed  # the jar it holds, as the dry run says
    assert chosen != spots[0] and clear == ""
    # a spot farther from the appliances (relay.clear_asked), not the far side of the table: (7.59, 3.29);
    # (7.61, 3.29), a little nearer the tap, before those were asked first
    assert math.dist(chosen, spots[0]) <= 0.06
    away = relay.appliance_distance(world)
    assert away(chosen) > away(spots[0])
