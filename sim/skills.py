"""The robots' skills, one function per action-type component of the knowledge base.

Each skill acts only on what it is given (perception estimates, planned paths, regions from the
layout) and returns an ``Outcome``: succeeded, or failed with a reason. Success is judged by the
predicate of the skill's effect against the simulated world, not by the skill's own belief, so a
skill that "did its moves" but dropped the object reports a failure. Every loop is bounded in
simulated time: a skill never runs forever.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pybullet as p

from cbrs.kb.hands import Hand
from cbrs.sim import predicates as pred
from cbrs.sim.arms import CARRY_CLEARANCE, COLLISION_MARGIN, MEET_MARGIN, Arm, ArmSide, MotionResult, PlannedArm
from cbrs.sim.errors import GraspMisfitError, GraspTooWideError
from cbrs.sim.geometry import Pose2D, Pose3D, Quat, Region, Vec3, wrap_angle
from cbrs.sim.grasping import (
    GraspKind,
    GraspPose,
    ObjectModel,
    compute_grasp_pose,
    side_orientation,
    top_orientation,
)
from cbrs.sim.layout import PERSON_HAND_HEIGHT
from cbrs.sim.perception import ObjectEstimate, PersonEstimate, RobotPoseEstimate
from cbrs.sim.planning import PlannedPath
from cbrs.sim.world import HomeWorld

__all__ = [
    "ABOVE_CLEARANCE",
    "FILL_TIME_LIMIT",
    "LIFT_HEIGHT",
    "NAVIGATION_TOLERANCE",
    "ROUND_PULLS",
    "DryRun",
    "Outcome",
    "Round",
    "appliances",
    "approach_object",
    "can_carry",
    "can_carry_held",
    "can_grip",
    "can_hand_over",
    "can_load",
    "can_set_down",
    "can_take",
    "carry_object",
    "clear_view",
    "deliver_object",
    "fill_cup_from_tap",
    "hand_over_onto_platform",
    "held_meeting",
    "held_meets",
    "navigate",
    "navigate_to_person",
    "navigate_to_place",
    "pick_up_object",
    "plan_carry",
    "plan_carry_held",
    "plan_hand_over",
    "platform_region",
    "put_down_object",
    "set_down_meets",
]

LIFT_HEIGHT = 0.04
"""A picked object is lifted 4 cm: clear of the table, and the cup's top stays under the spout."""
ABOVE_CLEARANCE = 0.03
"""Carrying ends with the object's bottom 3 cm above the target surface."""
TRANSIT_SAG = 0.02
"""A joint-space transit may let the grasp point dip 2 cm below the transit height, no more."""
APPROACH_OVER = 0.03
"""A hand coming in to an object whose top stands above the pre-grasp pose goes first to 3 cm over that
top, above the pose (:func:`_approach`)."""
PLACE_CLEARANCE = 0.003
"""Putting down lowers the object to 3 mm above the surface, then lets go: it drops onto it."""
PLACE_SPEED = 0.10
SETTLE_TIME = 0.5
"""Seconds an object is given to come to rest after being let go."""
LEVER_PUSH = 0.015
"""How far past the lever's front face the closed fingers push (the tap opens after 6 mm)."""
PRESS_STANDOFF = 0.08
FILL_TIME_LIMIT = 6.0
"""Longest the tap is held open (a full cup takes 4 s)."""
SPILL_LIMIT = 0.5
"""If the water has run this long without reaching a cup, the lever is let go."""
NAVIGATION_TOLERANCE = 0.05
"""The base has arrived when it is within 5 cm of the last waypoint."""
PLATFORM_TARGET = 0.05
"""Half-size of the put-down window on the platform around its localised centre."""
ROUND_PULLS = (0.05, 0.10, 0.15, 0.20, 0.25)
"""How far (m) a carry whose straight way across comes within CARRY_CLEARANCE of a fixture pulls its way
in towards the arm's mount, each tried in turn until one keeps clear (:func:`_way_round`). Measured on
EraserCupPen's pen, carried west from (8.07, 3.30) under the tap's lever by the right arm: pulled in 10 cm
the forearm still comes within 1 cm of the lever, 15 cm and more it keeps clear."""


@dataclass(frozen=True)
class Round:
    """What a carry needs to go round a fixture its straight way would come near (:func:`carry_object`'s
    ``around``): where the arm is mounted (x, y; the way is pulled in towards it), and how high the held
    object's bottom must stay over the things standing by a way from one (x, y) to another
    (``transit.transit_floor``; None: nothing stands by it). A way round is taken only where nothing by it
    asks the object higher than the straight way's floor."""

    mount: tuple[float, float]
    floor: Callable[[tuple[float, float], tuple[float, float]], float | None]


@dataclass(frozen=True)
class Outcome:
    """What a skill (or a perception step of a scenario) reports."""

    skill: str
    succeeded: bool
    reason: str
    started: float
    """Simulated time at the start (s)."""
    finished: float

    @property
    def sim_seconds(self) -> float:
        return self.finished - self.started


def _done(world: HomeWorld, skill: str, started: float, ok: bool, reason: str = "") -> Outcome:
    return Outcome(skill, ok, "" if ok else reason, started, world.time)


def _arm(world: HomeWorld, side: ArmSide | str) -> Arm:
    return world.arm(side)


def clear_view(world: HomeWorld) -> Outcome:
    """Raise the arms (one or two) to their home posture, out of the Kinect's view (the first step of
    FindCupOnTable): 0.2 s of simulated time an arm at least."""
    start = world.time
    for arm in world.arms.values():
        result = arm.home()
        if not result.reached:
            return _done(world, "ClearView", start, False, f"{arm.side} arm: {result.reason}")
    return _done(world, "ClearView", start, True)


def approach_object(world: HomeWorld, side: ArmSide | str, grasp: GraspPose) -> Outcome:
    """ApproachToObject: open the gripper and bring it to the pre-grasp pose."""
    start = world.time
    arm = _arm(world, side)
    if arm.held is not None:
        return _done(world, "ApproachToObject", start, False, f"the {arm.side} gripper is holding something")
    arm.open_gripper()
    result = _approach(arm, grasp)
    if not result.reached:
        return _done(world, "ApproachToObject", start, False, result.reason)
    ok = pred.gripper_near(world, side, grasp.model.name)
    return _done(world, "ApproachToObject", start, ok, f"the gripper is not near the {grasp.model.name}")


def _approach(arm: _Moving, grasp: GraspPose) -> MotionResult:
    """approach_object's move to the pre-grasp pose: through joint space, which keeps the arm clear of
    the fixed things but not of the objects; so for an object whose top stands above that pose (a vase
    25 cm tall taken at half its height), first to above the pose, APPROACH_OVER over the object's top,
    then straight down to it. Before, the hand swept into the vase's top on its way there and pushed it
    over. Where the arm has no way to above the pose, straight to it as before; where it has no straight
    line down from there (each piece of the line solved from the one before can lead the arm's posture
    to none at the pose, as for an 18 cm bottle at the edge of the left arm's reach), to the pose through
    joint space from above it: still clear of the object's top, which a hand coming in from its rest
    posture is not."""
    px, py, pz = grasp.pregrasp
    top = grasp.position[2] - grasp.bottom_offset + grasp.model.height
    if pz >= top:
        return arm.reach(grasp.pregrasp, grasp.orientation)
    above = arm.reach((px, py, top + APPROACH_OVER), grasp.orientation)
    if not above.reached and math.isinf(above.error):
        return arm.reach(grasp.pregrasp, grasp.orientation)
    if not above.reached:
        return above
    down = arm.move_to(grasp.pregrasp, grasp.orientation)
    if down.reached or not math.isinf(down.error):  # an infinite error: no line, nothing moved
        return down
    return arm.reach(grasp.pregrasp, grasp.orientation)


def _between_fingers(world: HomeWorld, arm: Arm) -> int | None:
    """The object both closed fingers touch (within 5 mm), if any: what the gripper actually holds."""
    for name in sorted(world.objects):
        body = world.body(name)
        touching = all(
            p.getClosestPoints(arm.body, body, 0.005, linkIndexA=finger, physicsClientId=world.client)
            for finger in (9, 10)
        )
        if touching:
            return body
    return None


def pick_up_object(world: HomeWorld, side: ArmSide | str, grasp: GraspPose) -> Outcome:
    """PickUpObject: move in to the grasp pose, close the fingers on the object and lift it."""
    start = world.time
    arm = _arm(world, side)
    name = grasp.model.name
    if arm.held is not None:
        return _done(world, "PickUpObject", start, False, f"the {arm.side} gripper is holding something")
    if not pred.gripper_near(world, side, name):
        return _done(world, "PickUpObject", start, False, f"the gripper is not near the {name}")
    result = arm.move_to(grasp.position, grasp.orientation, speed=PLACE_SPEED)
    if not result.reached:
        return _done(world, "PickUpObject", start, False, result.reason)
    arm.set_gripper(max(grasp.width - 0.004, 0.0), seconds=0.4)
    body = _between_fingers(world, arm)
    if body is None:
        arm.open_gripper()
        return _done(world, "PickUpObject", start, False, "nothing between the fingers")
    arm.attach(body, grasp)
    x, y, z = grasp.position
    result = arm.move_to((x, y, z + LIFT_HEIGHT), arm.ee_pose().orientation, speed=PLACE_SPEED, symmetric=False)
    if not result.reached:
        return _done(world, "PickUpObject", start, False, f"lifting: {result.reason}")
    held = world.name_of(body) or "?"
    ok = held == name and pred.is_grasped(world, name, side)
    return _done(world, "PickUpObject", start, ok, f"holding {held}, not the {name}" if held != name else "slipped")


def carry_object(
    world: HomeWorld,
    side: ArmSide | str,
    region: Region,
    yaw: float | None = None,
    floor: float | None = None,
    around: Round | None = None,
) -> Outcome:
    """CarryObject: take the held object over ``region`` (its centre over the region's centre, its
    bottom ABOVE_CLEARANCE over the surface), turning a top-grasped object's axis to ``yaw``; on the way
    its bottom stays at or above ``floor`` (over the other things standing by the way). With ``around``,
    a straight way across that would come within CARRY_CLEARANCE of a fixture is left for one pulled in
    towards the arm that keeps clear (:func:`_way_round`), where there is one."""
    start = world.time
    arm = _arm(world, side)
    grasp = arm.held_grasp
    if arm.held is None or grasp is None:
        return _done(world, "CarryObject", start, False, f"the {arm.side} gripper holds nothing")
    name = world.name_of(arm.held) or "?"
    result = _carry(arm, grasp, region, yaw, floor, appliances(world), around)
    if not result.reached:
        return _done(world, "CarryObject", start, False, result.reason)
    ok = pred.object_above_region(world, name, region)
    return _done(world, "CarryObject", start, ok, f"the {name} is not above {region.name}")


class _Moving(Protocol):
    """What moves a hand: the arm itself, or its dry run (:class:`cbrs.sim.arms.PlannedArm`)."""

    def ee_pose(self) -> Pose3D: ...

    def move_to(
        self, position: Vec3, orientation: Quat, speed: float = ..., tolerance: float = ..., symmetric: bool = ...
    ) -> MotionResult: ...

    def reach(
        self,
        position: Vec3,
        orientation: Quat,
        symmetric: bool = ...,
        min_height: float | None = ...,
        down_to: float | None = ...,
    ) -> MotionResult: ...

    def dry_run(self, *, clear_by: float | None = ...) -> PlannedArm: ...


def _carry(
    arm: _Moving,
    grasp: GraspPose,
    region: Region,
    yaw: float | None,
    floor: float | None = None,
    fixtures: Sequence[Region] = (),
    around: Round | None = None,
) -> MotionResult:
    """carry_object's moves: up to the transit height (the object's bottom where it is, ABOVE_CLEARANCE
    over the region, or ``floor``, whichever is highest), across to over the region's centre, down to
    ABOVE_CLEARANCE over its surface; the move across through joint space, the object kept up, when the
    straight line leaves the arm's reach; the way down through joint space too when the straight one
    would leave the hand where put_down_object cannot lower the object (:func:`_down`). Through joint
    space the hand keeps its turn about its approach axis unless that axis is vertical (a top grasp): a
    half turn about a side grasp's axis turns the object over. Before, a 15 cm vase reached a sill
    tilted 109 degrees and fell over as the hand opened. A way on which the held object would meet one of
    ``fixtures`` (:func:`held_meets`) is refused before any move, real or planned. With ``around``, the way
    across may go round a fixture the straight one comes near (:func:`_way_round`)."""
    ee = arm.ee_pose()
    orientation = ee.orientation
    if yaw is not None and grasp.model.grasp is GraspKind.TOP:
        orientation = top_orientation(yaw + math.pi / 2.0)
    bottom = ee.position[2] - grasp.bottom_offset
    above = region.zmin + ABOVE_CLEARANCE
    transit = max(bottom, above, bottom if floor is None else floor) + grasp.bottom_offset
    cx, cy, _ = region.center
    met = held_meets(fixtures, grasp, ee.position, (cx, cy, above + grasp.bottom_offset), transit - grasp.bottom_offset)
    if met:
        return MotionResult(False, math.inf, met)
    turnable = grasp.model.grasp is GraspKind.TOP
    legs: list[Vec3] = [
        (ee.position[0], ee.position[1], transit),
        (cx, cy, transit),
        (cx, cy, above + grasp.bottom_offset),
    ]
    if around is not None:
        legs = _way_round(arm, grasp, legs, orientation, floor, fixtures, around)
    result = MotionResult(True, 0.0)
    for index, leg in enumerate(legs):
        if math.dist(leg, arm.ee_pose().position) < 1e-3:
            continue
        last = index == len(legs) - 1
        result = _down(arm, grasp, region, leg, orientation) if last else arm.move_to(leg, orientation)
        if not result.reached and index == 1 and len(legs) == 3 and math.isinf(result.error):
            # The straight line leaves the arm's reach (it would have to change posture on the
            # way): go through joint space instead, keeping the object at the transit height.
            result = arm.reach(leg, orientation, symmetric=turnable, min_height=transit - TRANSIT_SAG)
        if not result.reached:
            return result
    return result


def _way_round(
    arm: _Moving,
    grasp: GraspPose,
    legs: list[Vec3],
    orientation: Quat,
    floor: float | None,
    fixtures: Sequence[Region],
    around: Round,
) -> list[Vec3]:
    """The legs a carry goes by (:func:`_carry`'s up, across and down, planned as straight lines): those
    given, unless, planned on a dry run, they would come within CARRY_CLEARANCE of a fixture (the arm,
    fingers included: :attr:`PlannedArm.brushed`) and a way pulled in towards the arm's mount by one of
    ROUND_PULLS keeps clear; then the first such: up, in, across at the same height, out, down. The arms'
    joint-space planning keeps 1 cm from the dispenser, not from its tap's lever, which a hand pushes to fill
    a cup; a straight carry under the lever brings the forearm into it (EraserCupPen's pen, carried west
    from east of the dispenser, stopped 0.16 m short). A way round is not taken where its lines are refused,
    the held object would meet an appliance on it (:func:`held_meets`), or a thing standing by it asks the
    object higher than ``floor`` (``around.floor``): it passes ground the straight way does not. Given legs
    refused on the dry run are kept (the carry's own fallbacks and refusals, as before)."""
    straight = arm.dry_run(clear_by=CARRY_CLEARANCE)
    if not _plans(straight, legs, orientation) or not straight.brushed:
        return legs
    up, across, down = legs
    transit = up[2]
    bottom = transit - grasp.bottom_offset
    highest = -math.inf if floor is None else floor
    for pull in ROUND_PULLS:
        way = [up, _pulled(up, around.mount, pull), _pulled(across, around.mount, pull), across]
        pairs = list(itertools.pairwise(way))
        floors = (around.floor((a[0], a[1]), (b[0], b[1])) for a, b in pairs)
        if any(height is not None and height > highest for height in floors):
            continue
        if any(held_meets(fixtures, grasp, a, b, bottom) for a, b in pairs):
            continue
        planned = arm.dry_run(clear_by=CARRY_CLEARANCE)
        if _plans(planned, [*way, down], orientation) and not planned.brushed:
            return [*way, down]
    return legs


def _pulled(point: Vec3, mount: tuple[float, float], by: float) -> Vec3:
    """``point`` moved ``by`` (m) towards ``mount`` (x, y) in the horizontal, at most onto it."""
    dx, dy = mount[0] - point[0], mount[1] - point[1]
    length = math.hypot(dx, dy)
    t = 1.0 if length <= by else by / length
    return (point[0] + dx * t, point[1] + dy * t, point[2])


def _plans(planned: PlannedArm, legs: Sequence[Vec3], orientation: Quat) -> bool:
    """Whether each of ``legs`` in turn is a straight line the planning makes (on the dry run ``planned``)."""
    for leg in legs:
        if math.dist(leg, planned.ee_pose().position) >= 1e-3 and not planned.move_to(leg, orientation).reached:
            return False
    return True


HELD_STEP = 0.005
"""How finely (m) :func:`held_meets` follows the held object along its way."""


def appliances(world: HomeWorld) -> list[Region]:
    """What a held object is carried clear of: each dispenser's body and spout, as the map places them, the
    appliances the arms' planning keeps the arm clear of (a tap's lever, which a hand pushes, is not one;
    the carry's clearance notes it, :data:`~cbrs.sim.arms.CARRY_CLEARANCE`). The planning knows nothing of
    the held object."""
    return [
        Region(thing.name, b.min_x, b.max_x, b.min_y, b.max_y, b.min_z, b.max_z)
        for dispenser in world.dispensers
        for thing in (dispenser.body, dispenser.spout)
        if (b := thing.box) is not None
    ]


def held_meets(fixtures: Sequence[Region], grasp: GraspPose, start: Vec3, end: Vec3, bottom: float) -> str:
    """Why the object held by ``grasp`` cannot go carry_object's way (empty if it can): carried with its
    bottom at ``bottom`` from over the grasp point at ``start`` to over ``end``, and lowered there until
    the grasp point is at ``end``, it would come within COLLISION_MARGIN (what the arm's joint-space moves
    keep from the fixed things) of one of ``fixtures`` (:func:`held_meeting`). The arms' planning sees the
    arm alone: with the floor a side grasp keeps for a lab's forearm band 6 cm below the grasp point over a
    second cup, a cup was carried with its top at 0.95 m, the height of the tap's lever and spout
    (0.94-0.98 m), towards the spot below the spout, and the carry stopped 10 cm short against them after
    the dry run had passed it."""
    met = held_meeting(fixtures, grasp, start, end, bottom)
    if met is None:
        return ""
    fixture, (x, y) = met
    model, top = grasp.model, bottom + grasp.model.height
    return (
        f"the {model.name}, carried with its bottom at {bottom:.3f} m (its top at {top:.3f} m), would "
        f"come within {COLLISION_MARGIN * 100:.0f} cm of the {fixture.name} ({fixture.zmin:.3f}-"
        f"{fixture.zmax:.3f} m high) at ({x:.3f}, {y:.3f}) on its way to ({end[0]:.3f}, {end[1]:.3f})"
    )


def held_meeting(
    fixtures: Sequence[Region], grasp: GraspPose, start: Vec3, end: Vec3, bottom: float
) -> tuple[Region, tuple[float, float]] | None:
    """The first of ``fixtures`` the held object would come within COLLISION_MARGIN of on :func:`held_meets`'s
    way, and where (x, y); None when it would meet none. Its footprint is a circle round the grasp point
    (the object's width across, or its footprint's diagonal), followed every HELD_STEP."""
    model = grasp.model
    radius = (math.hypot(*model.footprint) if model.footprint is not None else model.width) / 2.0
    reach = radius + COLLISION_MARGIN
    top = bottom + model.height
    lowest = end[2] - grasp.bottom_offset
    steps = max(1, math.ceil(math.dist(start[:2], end[:2]) / HELD_STEP))
    for fixture in fixtures:
        for i in range(steps + 1):
            t = i / steps
            x, y = start[0] + (end[0] - start[0]) * t, start[1] + (end[1] - start[1]) * t
            low = lowest if i == steps else bottom  # lowered where the way ends
            level = fixture.zmin < top + COLLISION_MARGIN and fixture.zmax > low - COLLISION_MARGIN
            dx = max(fixture.xmin - x, 0.0, x - fixture.xmax)
            dy = max(fixture.ymin - y, 0.0, y - fixture.ymax)
            if level and math.hypot(dx, dy) < reach:
                return fixture, (x, y)
    return None


def _down(arm: _Moving, grasp: GraspPose, region: Region, leg: Vec3, orientation: Quat) -> MotionResult:
    """The carry's way down to ``leg``, over the region: a straight line, unless, planned first (a dry
    run), it would fail or end in a posture from which the hand cannot lower the object the rest of the
    way in a straight line (:func:`_lower`: its inverse kinematics run out there; reading glasses taken
    from a shelf 10 cm above the table came down over the base's platform with the elbow at the end of
    its range). Then through joint space, the object kept within TRANSIT_SAG below ``leg``, to the
    nearest posture from which it can (:meth:`Arm.reach`'s ``down_to``); the straight line when there is
    none, to fail as before."""
    line = arm.dry_run()
    if line.move_to(leg, orientation).reached and _lower(line, grasp, region)[0].reached:
        return arm.move_to(leg, orientation)
    low = region.zmin + PLACE_CLEARANCE + grasp.bottom_offset
    turnable = grasp.model.grasp is GraspKind.TOP  # a half turn about a side grasp's axis turns it over
    if arm.dry_run().reach(leg, orientation, turnable, min_height=leg[2] - TRANSIT_SAG, down_to=low).reached:
        return arm.reach(leg, orientation, turnable, min_height=leg[2] - TRANSIT_SAG, down_to=low)
    return arm.move_to(leg, orientation)


def _lower(arm: _Moving, grasp: GraspPose, region: Region) -> tuple[MotionResult, Vec3]:
    """put_down_object's way down: straight down from where the hand is until the held object's bottom
    is PLACE_CLEARANCE over the region's surface; and where the hand lets go."""
    ee = arm.ee_pose()
    place = (ee.position[0], ee.position[1], region.zmin + PLACE_CLEARANCE + grasp.bottom_offset)
    return arm.move_to(place, ee.orientation, speed=PLACE_SPEED, symmetric=False), place


BACK_OFF_STEP = 0.05
"""The retreat's collision check plans each straight line in pieces of up to 5 cm (:func:`_clear_way`):
each piece is a joint-space move checked for collisions every 0.05 rad, and asks the inverse kinematics
from every seed posture (about 0.1-0.3 s a piece), so fewer pieces cost less."""
BACK_OFF_TURN = 0.6
"""The most (rad) a joint may turn over one piece of the retreat's collision-checked line: a piece that
turns more has gone round to another posture, since the line's own was not clear (:func:`_clear_way`).
Measured: a piece turned a joint at most 0.14 rad along the bundled retreats and 0.09 along a 30 cm
bottle's; 1.3 rad where the line's own posture ran into the Kinect."""


def _retreat(grasp: GraspPose, place: Vec3) -> list[Vec3]:
    """Where the hand goes, in straight lines, after letting go of the object at ``place``: back along the
    approach by the pre-grasp distance (:meth:`GraspPose.backed_off`); then, when the object's top stands
    above the grasp point there (the hand is beside it), straight up to ABOVE_CLEARANCE over that top,
    before the joint-space fold home. Folded home from beside a 30 cm bottle, the hand swung forward over
    it below its top and knocked it over; the backed-off hand is above a cup's or a pen's top (by 2.8 cm
    over the cup under the tap) and folds home from there as before."""
    back = grasp.backed_off(place)
    top = place[2] - grasp.bottom_offset + grasp.model.height
    return [back] if back[2] >= top else [back, (back[0], back[1], top + ABOVE_CLEARANCE)]


def _clear_way(arm: _Moving, legs: Sequence[Vec3], orientation: Quat) -> str:
    """Why the hand, where it is, could not go along the straight ``legs`` in turn (empty if it can). A
    straight line is planned on inverse kinematics alone, so each is planned again here in pieces of
    BACK_OFF_STEP, each a joint-space move whose path keeps the arm clear of the fixed things and the
    other arm (:meth:`Arm.reach`, on a dry run) and turns no joint more than BACK_OFF_TURN. The first piece
    goes by its line and only its end is checked: the fingers start within the collision margin of the
    surface they let go on (a pen's fingertips 2 mm over the table), which every path from there meets; an
    arm that has run into something by then is caught there. Unchecked, the
    right arm setting a 30 cm bottle down beside the torso drove its upper arm into the Kinect 3 cm into
    the back-off, and the jammed wrist swung the open fingers into the bottle, which fell. A piece that went
    round is refused with why the leg's own straight line cannot be taken (:meth:`PlannedArm.blocked`)."""
    planned = arm.dry_run()
    lifting = True  # the fingers start on the surface, within the collision margin of it
    for leg in legs:
        along = planned.dry_run()  # the leg's straight line, to say why a piece went round
        start = np.asarray(planned.ee_pose().position)
        way = np.asarray(leg) - start
        pieces = max(1, math.ceil(float(np.linalg.norm(way)) / BACK_OFF_STEP))
        for i in range(1, pieces + 1):
            x, y, z = (float(v) for v in start + way * (i / pieces))
            before = np.asarray(planned.joint_positions())
            if lifting:  # so the first piece goes by its line, and the posture it ends in is checked
                lifting = False
                lifted = planned.move_to((x, y, z), orientation, symmetric=False)
                if not lifted.reached:
                    return lifted.reason
            moved = planned.reach((x, y, z), orientation, symmetric=False)
            if not moved.reached:
                return moved.reason
            turn = float(np.max(np.abs(np.asarray(planned.joint_positions()) - before)))
            if turn > BACK_OFF_TURN:
                return along.blocked((x, y, z), orientation) or (
                    f"the arm would turn a joint {turn:.2f} rad (more than {BACK_OFF_TURN} rad) over the piece to "
                    f"({x:.3f}, {y:.3f}, {z:.3f}), going round to another posture"
                )
    return ""


def _set_down(arm: _Moving, grasp: GraspPose, region: Region) -> MotionResult:
    """put_down_object's moves on a dry run: the way down (:func:`_lower`), then whether the hand can go
    its way back from there once it lets go (:func:`_retreat`, :func:`_clear_way`; not moving the dry run)."""
    lowered, place = _lower(arm, grasp, region)
    if not lowered.reached:
        return lowered
    blocked = _clear_way(arm, _retreat(grasp, place), arm.ee_pose().orientation)
    return MotionResult(False, math.inf, f"backing off once it is let go: {blocked}") if blocked else lowered


def put_down_object(world: HomeWorld, side: ArmSide | str, region: Region) -> Outcome:
    """PutDownObject: lower the held object onto the surface below, let go, back off (and rise over a tall
    object), raise the arm home. A way back that would run into something fails it before it lets go."""
    start = world.time
    arm = _arm(world, side)
    grasp = arm.held_grasp
    if arm.held is None or grasp is None:
        return _done(world, "PutDownObject", start, False, f"the {arm.side} gripper holds nothing")
    name = world.name_of(arm.held) or "?"
    ee = arm.ee_pose()
    result, place = _lower(arm, grasp, region)
    if not result.reached:
        return _done(world, "PutDownObject", start, False, result.reason)
    back, *rise = _retreat(grasp, place)
    blocked = _clear_way(arm, [back, *rise], ee.orientation)
    if blocked:
        return _done(
            world, "PutDownObject", start, False, f"the hand could not back off from the {name} once let go: {blocked}"
        )
    arm.detach()
    arm.open_gripper()
    retreat = arm.move_to(back, ee.orientation, speed=PLACE_SPEED, symmetric=False)
    if not retreat.reached:
        # The straight line failed all the same (its inverse kinematics asked tighter than the check's, or
        # the hand stopped short; a worktop 5 cm lower than the bundled table, at every seed, before the
        # check): back off through joint space, not fold home from beside the object.
        retreat = arm.reach(back, ee.orientation, symmetric=False)
    for leg in rise if retreat.reached else []:
        retreat = arm.move_to(leg, ee.orientation, speed=PLACE_SPEED, symmetric=False)
    world.step(SETTLE_TIME)
    folded = arm.home()
    ok = pred.object_located_in(world, name, region)
    if ok and not (retreat.reached and folded.reached):
        return _done(
            world, "PutDownObject", start, False, f"the arm did not back off: {retreat.reason or folded.reason}"
        )
    return _done(world, "PutDownObject", start, ok, f"the {name} did not come to rest in {region.name}")


def fill_cup_from_tap(world: HomeWorld, side: ArmSide | str, lever: Region, container: str) -> Outcome:
    """FillCupFromTap: the free arm pushes the tap's ``lever`` until ``container`` below is full.

    The water runs whenever the lever is in; if it reaches no container for SPILL_LIMIT seconds the
    arm lets go and the skill fails (the container was not below the tap).
    """
    start = world.time
    arm = _arm(world, side)
    if arm.held is not None:
        return _done(world, "FillCupFromTap", start, False, f"the {arm.side} gripper is holding something")
    facing = world.arm_specs[ArmSide(side)].yaw  # the way the arm faces, from the semantic map
    orientation = side_orientation(facing, arm.hand.side_pitch)
    approach = np.array([math.cos(facing), math.sin(facing), 0.0])
    x, z = (lever.xmin + lever.xmax) / 2.0, (lever.zmin + lever.zmax) / 2.0
    press = np.array([x, lever.ymin + LEVER_PUSH, z])
    pre = press - approach * (LEVER_PUSH + PRESS_STANDOFF)
    arm.set_gripper(0.0)
    result = arm.reach((float(pre[0]), float(pre[1]), float(pre[2])), orientation)
    if not result.reached:
        return _done(world, "FillCupFromTap", start, False, f"reaching the tap: {result.reason}")
    arm.move_to((float(press[0]), float(press[1]), float(press[2])), arm.ee_pose().orientation, speed=PLACE_SPEED)
    opened = world.tap_open()
    spilled = world.water_spilled
    held = 0.0
    while opened and held < FILL_TIME_LIMIT and world.water_level(container) < 1.0:
        world.step(0.1)
        held += 0.1
        if world.water_spilled - spilled >= SPILL_LIMIT:
            break
    arm.move_to((float(pre[0]), float(pre[1]), float(pre[2])), arm.ee_pose().orientation, speed=PLACE_SPEED)
    arm.open_gripper()
    arm.home()
    if not opened:
        return _done(world, "FillCupFromTap", start, False, "the lever did not open the tap")
    ok = pred.contains_water(world, container)
    return _done(world, "FillCupFromTap", start, ok, f"the water ran but the {container} did not catch it")


def platform_region(base: Pose2D | RobotPoseEstimate, height: float) -> Region:
    """Where on a base's platform (its top at ``height``) to put things: a small window around its centre."""
    return Region(
        "OnRobotPlatform",
        base.x - PLATFORM_TARGET,
        base.x + PLATFORM_TARGET,
        base.y - PLATFORM_TARGET,
        base.y + PLATFORM_TARGET,
        height,
        height + 0.3,
    )


def _grasp(world: HomeWorld, pen: ObjectEstimate, side: ArmSide | str, model: ObjectModel) -> GraspPose | str:
    """The grasp of ``side`` on the object where perception put it, by ``model``'s approach; or why the
    hand cannot hold it so (too wide across the jaws, too deep along a side grasp's approach: the words of
    :class:`GraspTooWideError` or :class:`GraspTooDeepError`)."""
    spec = world.arm_specs[ArmSide(side)]
    hand = world.arm(side).hand
    try:
        seen = (pen.size[0], pen.size[1])
        return compute_grasp_pose(model, pen.position, pen.yaw, spec.mount, spec.yaw, seen, hand, pen.size[2])
    except GraspMisfitError as misfit:
        return str(misfit)


def _loading(
    world: HomeWorld, pen: ObjectEstimate, base: Pose2D | RobotPoseEstimate, side: ArmSide | str, model: ObjectModel
) -> tuple[GraspPose | None, Region, float, str]:
    """How an arm loads an object onto the platform: its grasp, the window on the platform, the axis it
    turns a top-grasped object to, and why it cannot (empty if it can): the hand must be able to hold
    the grasp where the object is let go on the platform, which is asked before anything moves."""
    region = platform_region(base, world.platform_height)
    grasp = _grasp(world, pen, side, model)
    if isinstance(grasp, str):
        return None, region, 0.0, grasp
    # The pen fits between the marker patches along or across the base: take the placement that
    # needs the smaller turn of the wrist.
    pen_yaw = pen.yaw or 0.0
    along = abs(wrap_angle(2.0 * (base.theta - pen_yaw))) / 2.0
    yaw = base.theta if along <= math.pi / 4.0 else base.theta + math.pi / 2.0
    orientation = top_orientation(yaw + math.pi / 2.0) if model.grasp is GraspKind.TOP else grasp.orientation
    cx, cy, _ = region.center
    letting_go = (cx, cy, region.zmin + PLACE_CLEARANCE + grasp.bottom_offset)
    if not world.arm(side).can_hold(letting_go, orientation):
        return (
            grasp,
            region,
            yaw,
            (
                f"the {ArmSide(side).value} arm cannot hold the {model.name} by its {model.grasp.value} grasp over the "
                f"platform at ({cx:.2f}, {cy:.2f}) to set it down there"
            ),
        )
    return grasp, region, yaw, ""


def can_load(
    world: HomeWorld, pen: ObjectEstimate, base: Pose2D | RobotPoseEstimate, side: ArmSide | str, model: ObjectModel
) -> str:
    """Why ``side`` cannot load the object onto the platform of the base parked at ``base`` (empty if it can)."""
    return _loading(world, pen, base, side, model)[3]


def can_grip(model: ObjectModel, hand: Hand) -> str:
    """Why ``hand`` cannot close on the object by the approach ``model`` is held by, wherever it is
    (empty if it can): a top grasp whose grasp point is deeper below the object's top than the palm
    is above the fingers' grasp point would press the palm on it; an object whose narrowest width (a
    cylinder's diameter, a box's narrower side) is wider than the jaws open, less each jaw's clearance,
    fits no approach."""
    if model.width > hand.widest:  # the opening less each jaw's clearance, as compute_grasp_pose holds it
        return str(GraspTooWideError(model.name, model.grasp.value, model.width, hand.jaw_opening, hand.jaw_clearance))
    if model.grasp is GraspKind.TOP and model.top_clearance(hand) < 0.0:
        depth = model.height - model.grasp_height
        least = math.ceil((1.0 - hand.palm_depth / model.height) * 100.0) / 100.0 if model.height > 0.0 else 1.0
        return (
            f"a top grasp would hold the {model.name} {depth * 100:.1f} cm below its top, and the hand's palm is "
            f"{hand.palm_depth * 100:.1f} cm above the fingers' grasp point (a home:graspHeightRatio of at least "
            f"{least:.2f} on its class lets the hand take it from the top)"
        )
    return ""


def can_take(world: HomeWorld, pen: ObjectEstimate, side: ArmSide | str, model: ObjectModel) -> str:
    """Why ``side`` cannot take the object where it is by the approach ``model`` is held by (empty if it
    can), asked without moving: the hand cannot close on it so (:func:`can_grip`; or it is wider across
    the jaws than they open, for the way the hand turns to it, or too deep along a side grasp's approach
    for the fingers), or cannot hold the pre-grasp or the grasp pose."""
    arm = ArmSide(side)
    x, y, _ = pen.position
    refused = can_grip(model, world.arm(arm).hand)
    if refused:
        return refused
    grasp = _grasp(world, pen, arm, model)
    if isinstance(grasp, str):
        return grasp
    hand = world.arm(arm)
    if not (hand.can_hold(grasp.pregrasp, grasp.orientation) and hand.can_hold(grasp.position, grasp.orientation)):
        return (
            f"the {arm.value} arm cannot hold the {model.name} by its {model.grasp.value} grasp at ({x:.2f}, {y:.2f})"
        )
    return ""


def can_set_down(world: HomeWorld, pen: ObjectEstimate, side: ArmSide | str, model: ObjectModel, region: Region) -> str:
    """Why ``side``, taking the object where it is by ``model``'s approach, cannot let it go over the
    middle of ``region`` (empty if it can): the hand keeps the orientation it took it with, as
    :func:`carry_object` and :func:`put_down_object` do."""
    arm = ArmSide(side)
    grasp = _grasp(world, pen, arm, model)
    if isinstance(grasp, str):
        return grasp
    cx, cy, _ = region.center
    letting_go = (cx, cy, region.zmin + PLACE_CLEARANCE + grasp.bottom_offset)
    if not world.arm(arm).can_hold(letting_go, grasp.orientation):
        return (
            f"the {arm.value} arm cannot hold the {model.name} by its {model.grasp.value} grasp over {region.name} "
            f"at ({cx:.2f}, {cy:.2f}) to set it down there"
        )
    return ""


def set_down_meets(
    world: HomeWorld, pen: ObjectEstimate, side: ArmSide | str, model: ObjectModel, region: Region
) -> str:
    """Why ``side``, taking the object where it is by ``model``'s approach, would let it go over the middle of
    ``region`` only with the arm, fingers included, within CARRY_CLEARANCE of a fixture (an appliance, or a
    tap's lever), in every posture that holds the hand there or backed off from there (:func:`_retreat`'s
    first pose): empty when some posture keeps clear at each, or the hand there could come near none by the
    map (:meth:`Arm.fixture_near`; then nothing is solved). The arms' joint-space moves keep that margin
    from the appliances, so a pose no posture holds clear has no way to it; and a carry keeps it from a
    lever (``arm_choice.carry_clear``). Asked with :func:`can_set_down` of a later thing's spots, which the
    end poses' inverse kinematics alone let through under a tap's spout (EraserCupPen's pen)."""
    arm = ArmSide(side)
    grasp = _grasp(world, pen, arm, model)
    if isinstance(grasp, str):
        return grasp
    cx, cy, _ = region.center
    letting_go = (cx, cy, region.zmin + PLACE_CLEARANCE + grasp.bottom_offset)
    back = grasp.backed_off(letting_go)
    hand = world.arm(arm)
    if not hand.fixture_near(back, letting_go, CARRY_CLEARANCE):
        return ""
    for what, pose in (("letting it go", letting_go), ("backing off once it is let go", back)):
        name = hand.hold_meets(pose, grasp.orientation, CARRY_CLEARANCE)
        if name:
            return (
                f"the {arm.value} arm holding the {model.name} by its {model.grasp.value} grasp over {region.name} at "
                f"({cx:.2f}, {cy:.2f}), {what}, would come within {CARRY_CLEARANCE * 100:.0f} cm of the {name} in "
                f"every posture that holds the hand there"
            )
    return ""


@dataclass(frozen=True)
class DryRun:
    """What a hold's moves, planned and not made, came to (:func:`plan_carry`)."""

    refused: str
    """Why the arm's planning would refuse them; empty: it would make them."""
    brushed: str = ""
    """Where they first came within the clearance asked of the appliances (:attr:`PlannedArm.brushed`);
    empty: they kept it, or none was asked."""
    met: str = ""
    """Where the take's moves to the pre-grasp and grasp poses touched a fixture (:attr:`PlannedArm.met`),
    what ``refused`` says unless the planning refused them for its own reason; empty: they touched none."""


def can_carry(
    world: HomeWorld,
    pen: ObjectEstimate,
    side: ArmSide | str,
    model: ObjectModel,
    region: Region | None = None,
    yaw: float | None = None,
    floor: float | None = None,
    folded: Sequence[ArmSide] = (),
) -> str:
    """Why ``side``'s own motion planning would refuse to take the object where it is by ``model``'s
    approach and, given a ``region``, carry it over its middle (empty if it would not): :func:`plan_carry`'s
    refusal."""
    return plan_carry(world, pen, side, model, region, yaw, floor, folded).refused


def plan_carry(
    world: HomeWorld,
    pen: ObjectEstimate,
    side: ArmSide | str,
    model: ObjectModel,
    region: Region | None = None,
    yaw: float | None = None,
    floor: float | None = None,
    folded: Sequence[ArmSide] = (),
    clearance: float | None = None,
    around: Round | None = None,
) -> DryRun:
    """The moves of ``side`` taking the object where it is by ``model``'s approach and, given a ``region``,
    carrying it over its middle: approach_object, pick_up_object and carry_object, and put_down_object's
    way down and back, planned one after the other on the kinematics copies from the arm's posture now,
    without moving (a dry run, :meth:`Arm.dry_run`). The inverse kinematics
    of the end poses alone (:func:`can_take`, :func:`can_set_down`) misses a joint-space move whose every
    path collides or lets the held object dip, and a straight line that leaves the arm's reach. ``yaw``
    turns a top-grasped object on the way, and ``floor`` keeps its bottom up on the way, as
    :func:`carry_object` does; the arms of ``folded`` are taken to be home (:meth:`Arm.dry_run`). With
    ``clearance``, also where the moves first come within that distance of an appliance, a tap's lever
    too (:attr:`DryRun.brushed`), which the planning does not refuse them for; with ``around``, the carry
    going round a fixture as :func:`carry_object` does given it."""
    arm = ArmSide(side)
    grasp = _grasp(world, pen, arm, model)
    if isinstance(grasp, str):
        return DryRun(grasp)
    hand = world.arm(arm).dry_run(folded, clear_by=clearance, meet_by=MEET_MARGIN)
    x, y, z = grasp.position
    moves: list[tuple[str, Callable[[], MotionResult]]] = [
        ("reaching the pre-grasp pose", lambda: _unmet(hand, _approach(hand, grasp))),
        ("moving in to grasp it", lambda: _unmet(hand, hand.move_to(grasp.position, grasp.orientation), last=True)),
        ("lifting it", lambda: hand.move_to((x, y, z + LIFT_HEIGHT), hand.ee_pose().orientation, symmetric=False)),
    ]
    if region is not None:
        cx, cy, _ = region.center
        carrying = f"carrying it to ({cx:.2f}, {cy:.2f})"
        moves.append((carrying, lambda: _carry(hand, grasp, region, yaw, floor, appliances(world), around)))
        lowering = f"lowering it onto {region.name} at ({cx:.2f}, {cy:.2f})"
        moves.append((lowering, lambda: _set_down(hand, grasp, region)))
    return DryRun(_first_refused(moves, arm, model), hand.brushed, hand.met)


def _unmet(hand: PlannedArm, result: MotionResult, last: bool = False) -> MotionResult:
    """A take's planned move (``result``) refused where it touched a fixture (:attr:`PlannedArm.met`, asked
    with MEET_MARGIN): the arm's planning does not avoid a tap's lever, and the hand that meets it on its way
    to the object stops there. After the ``last`` of the take's moves, the others are not asked (a carry
    keeps CARRY_CLEARANCE, asked apart)."""
    if result.reached and hand.met:
        return MotionResult(False, math.inf, hand.met)
    if last:
        hand.meet_by = None
    return result


def can_hand_over(
    world: HomeWorld, pen: ObjectEstimate, base: Pose2D | RobotPoseEstimate, side: ArmSide | str, model: ObjectModel
) -> str:
    """Why ``side`` cannot load the object onto the platform of the base parked at ``base`` by
    :func:`hand_over_onto_platform`'s moves (empty if it can): :func:`plan_hand_over`'s refusal."""
    return plan_hand_over(world, pen, base, side, model).refused


def plan_hand_over(
    world: HomeWorld,
    pen: ObjectEstimate,
    base: Pose2D | RobotPoseEstimate,
    side: ArmSide | str,
    model: ObjectModel,
    clearance: float | None = None,
) -> DryRun:
    """:func:`hand_over_onto_platform`'s moves: the end poses (:func:`can_load`), then a dry run of the take
    and of the carry over the platform with the wrist turned as the hand-over turns it (:func:`plan_carry`,
    with ``clearance``)."""
    _, region, yaw, reason = _loading(world, pen, base, side, model)
    return DryRun(reason) if reason else plan_carry(world, pen, side, model, region, yaw, clearance=clearance)


def can_carry_held(world: HomeWorld, side: ArmSide | str, region: Region, floor: float | None = None) -> str:
    """Why ``side``'s planning would refuse to carry what it holds over the middle of ``region`` and lower
    it there (empty if it would not): :func:`plan_carry_held`'s refusal."""
    return plan_carry_held(world, side, region, floor).refused


def plan_carry_held(
    world: HomeWorld,
    side: ArmSide | str,
    region: Region,
    floor: float | None = None,
    clearance: float | None = None,
    around: Round | None = None,
) -> DryRun:
    """The moves of ``side`` carrying what it holds over the middle of ``region`` and lowering it there, as
    :func:`carry_object` (given ``around``) and :func:`put_down_object` move it: a dry run from the arm's
    posture now; with ``clearance``, also where they first come within that distance of an appliance, a
    tap's lever too (:attr:`DryRun.brushed`)."""
    arm = _arm(world, side)
    grasp = arm.held_grasp
    if arm.held is None or grasp is None:
        return DryRun(f"the {arm.side} gripper holds nothing")
    hand = arm.dry_run(clear_by=clearance)
    cx, cy, _ = region.center
    moves: list[tuple[str, Callable[[], MotionResult]]] = [
        (
            f"carrying it to ({cx:.2f}, {cy:.2f})",
            lambda: _carry(hand, grasp, region, None, floor, appliances(world), around),
        ),
        (f"lowering it onto {region.name} at ({cx:.2f}, {cy:.2f})", lambda: _set_down(hand, grasp, region)),
    ]
    return DryRun(_first_refused(moves, ArmSide(side), grasp.model), hand.brushed)


def _first_refused(moves: list[tuple[str, Callable[[], MotionResult]]], arm: ArmSide, model: ObjectModel) -> str:
    """Plan ``moves`` (what each does, the planning) in turn; why the first refused one was (empty: none)."""
    for what, move in moves:
        result = move()
        if not result.reached:
            return (
                f"the {arm.value} arm would not get the {model.name} by its {model.grasp.value} grasp past {what}: "
                f"{result.reason}"
            )
    return ""


def hand_over_onto_platform(
    world: HomeWorld,
    pen: ObjectEstimate,
    base: Pose2D | RobotPoseEstimate,
    side: ArmSide | str,
    model: ObjectModel,
    reach: float,
) -> Outcome:
    """HandOverOntoPlatform: pick the object up from the table and put it on the middle of the platform
    of the base, which must be parked within the arm's ``reach`` (``base`` is where it was localised)."""
    start = world.time
    mount = world.arm_specs[ArmSide(side)].mount
    if math.hypot(base.x - mount[0], base.y - mount[1]) > reach:
        return _done(
            world, "HandOverOntoPlatform", start, False, f"the base's platform is out of the {side} arm's reach"
        )
    grasp, region, yaw, reason = _loading(world, pen, base, side, model)
    if reason or grasp is None:
        return _done(world, "HandOverOntoPlatform", start, False, reason)
    steps: list[Callable[[], Outcome]] = [
        lambda: approach_object(world, side, grasp),
        lambda: pick_up_object(world, side, grasp),
        lambda: carry_object(world, side, region, yaw=yaw),
        lambda: put_down_object(world, side, region),
    ]
    for step in steps:
        outcome = step()
        if not outcome.succeeded:
            return _done(world, "HandOverOntoPlatform", start, False, f"{outcome.skill}: {outcome.reason}")
    ok = pred.on_platform(world, model.name)
    return _done(world, "HandOverOntoPlatform", start, ok, f"the {model.name} is not on the platform")


def navigate(world: HomeWorld, waypoints: Sequence[tuple[float, float]], final_heading: float | None = None) -> Outcome:
    """DriveBase along waypoints: stop at the last one (then turn to ``final_heading``)."""
    start = world.time
    if not waypoints:
        return _done(world, "Navigate", start, False, "no waypoints")
    result = world.base.follow(list(waypoints), final_heading)
    if not result.succeeded:
        return _done(world, "Navigate", start, False, result.reason)
    gx, gy = waypoints[-1]
    ok = world.base_pose().distance_to(gx, gy) <= NAVIGATION_TOLERANCE
    return _done(world, "Navigate", start, ok, "stopped away from the goal")


def navigate_to_place(world: HomeWorld, path: PlannedPath, place: Pose2D) -> Outcome:
    """NavigateToPlace: follow a planned path and stop at ``place`` with its heading."""
    start = world.time
    outcome = navigate(world, [*path.waypoints[:-1], place.xy], place.theta)
    if not outcome.succeeded:
        return _done(world, "NavigateToPlace", start, False, outcome.reason)
    ok = pred.base_near(world, place, heading=True)
    return _done(world, "NavigateToPlace", start, ok, "the base is not at the place")


def navigate_to_person(world: HomeWorld, path: PlannedPath, person: PersonEstimate, name: str | None = None) -> Outcome:
    """NavigateToPerson: follow a planned path that ends next to the tracked person (``name``, the
    home's only person by default), facing them."""
    start = world.time
    gx, gy = path.waypoints[-1]
    outcome = navigate(world, path.waypoints, math.atan2(person.y - gy, person.x - gx))
    if not outcome.succeeded:
        return _done(world, "NavigateToPerson", start, False, outcome.reason)
    ok = pred.base_near_person(world, name)
    return _done(world, "NavigateToPerson", start, ok, f"the base stopped too far from {name or 'the person'}")


def deliver_object(world: HomeWorld, receiver: str | None = None) -> Outcome:
    """DeliverObject: standing next to the person, the base waits while they take what is on its platform."""
    start = world.time
    receiver = receiver or world.person_name
    if not pred.base_near_person(world, receiver):
        return _done(world, "DeliverObject", start, False, f"the base is not near {receiver}")
    carried = pred.objects_on_platform(world)
    if not carried:
        return _done(world, "DeliverObject", start, False, "there is nothing on the platform")
    person = world.pose(receiver).position
    base = world.base_pose()
    dx, dy = base.x - person[0], base.y - person[1]
    norm = math.hypot(dx, dy)
    reach = min(0.35, norm)
    hand = (person[0] + dx / norm * reach, person[1] + dy / norm * reach, PERSON_HAND_HEIGHT)
    for name in carried:
        world.give_to(name, receiver, hand)
    world.step(0.5)
    ok = all(pred.with_person(world, name, receiver) for name in carried)
    return _done(world, "DeliverObject", start, ok, f"{receiver} does not have the {', '.join(carried)}")
