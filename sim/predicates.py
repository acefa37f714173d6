"""Checks against the simulated world's state: is a statement of the knowledge base really true now?

These read the simulator's ground truth on purpose: they are the referee (:mod:`sim.referee`) that
tells whether a task's goal (for instance ``(Cup, isLocated, BelowOfTap)``) really holds, independent
of the perception the robots used, and the skills' own success checks. The robots' belief
(:mod:`sim.perceived`) shares their tolerances. ``objects_on_platform`` is also the platform's load
sensor. Each tolerance is a named constant with the reason for its value.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p

from cbrs.kb.hands import Hand
from cbrs.sim.arms import ArmSide
from cbrs.sim.cameras import project
from cbrs.sim.geometry import Pose2D, Region, Vec3, quat_to_matrix
from cbrs.sim.layout import PERSON_HAND_HEIGHT
from cbrs.sim.world import HomeWorld

__all__ = [
    "ABOVE_MAX",
    "ABOVE_MIN",
    "APPROACH_SLACK",
    "BASE_NEAR_DISTANCE",
    "BASE_NEAR_HEADING",
    "GRASP_DISTANCE",
    "HAND_HEIGHT_TOLERANCE",
    "NEAR_PERSON_DISTANCE",
    "PERSON_REACH",
    "PLATFORM_MARGIN",
    "RESTING_SPEED",
    "RESTING_TOLERANCE",
    "WATER_MIN",
    "base_near",
    "base_near_person",
    "contains_water",
    "distance_to_extent",
    "gripper_near",
    "gripper_near_distance",
    "is_grasped",
    "object_above_region",
    "object_bottom",
    "object_located_in",
    "objects_on_platform",
    "on_platform",
    "robot_visible",
    "upright_in",
    "with_person",
]

RESTING_TOLERANCE = 0.01
"""An object rests on a surface when its bottom is within 1 cm of it: contact jitter and the
settling of a dropped object stay well below that, while a held object is lifted by 3 cm or more."""
RESTING_SPEED = 0.05
"""...and it moves slower than 5 cm/s (it is not falling or sliding)."""
ABOVE_MIN = 0.005
ABOVE_MAX = 0.30
"""An object is above a region when its centre is over the region and its bottom is 0.5 cm to
30 cm over the surface: free of it, yet close enough that putting it down is a short straight move."""
GRASP_DISTANCE = 0.03
"""A grasped object's centre is within 3 cm of where the grasp holds it (``Arm.carried_centre``: the
grasp point less the grasp's height above the object's centre); more means the object slipped. It was
measured to the grasp point itself, which a grasp high on a tall object is far from (7 cm for an 18 cm
bottle held at 0.88 of its height), so such a pick-up was said to slip."""
APPROACH_SLACK = 0.05
"""How far from its planned pre-grasp pose an approach may end and still count (5 cm)."""
BASE_NEAR_DISTANCE = 0.10
"""The base is near a place (for a hand-over) within 10 cm: the arm plans its put-down on the
localised platform, and 10 cm keeps the pen well inside the platform's 20 cm middle strip."""
BASE_NEAR_HEADING = 0.20
"""...and, when a heading is asked for, within 0.2 rad (11 degrees) of it."""
NEAR_PERSON_DISTANCE = 1.0
"""The base is near a person when its centre is within 1 m of theirs: a standing adult reaches a
platform 0.8 m from their body (person radius 0.18 + arm) and the base's half-length adds 0.2 m."""
PERSON_REACH = 0.50
"""The pen is with the person when they hold it: within 50 cm of their body's axis (an arm's
length) and within ``HAND_HEIGHT_TOLERANCE`` of hand height."""
HAND_HEIGHT_TOLERANCE = 0.10
PLATFORM_MARGIN = 0.01
"""The pen's centre must be 1 cm inside the platform's edge to be on it."""
WATER_MIN = 0.5
"""The cup contains water once at least half full (a full cup takes 4 s of open tap)."""


def gripper_near_distance(hand: Hand) -> float:
    """How near an object a gripper is near it: its grasp point within the hand's pre-grasp distance and
    APPROACH_SLACK of the object's extent (:func:`distance_to_extent`; 15 cm for the Panda hand), not of
    its centre: the pre-grasp pose is that distance back from a grasp point in the object, wherever on it
    the class grasps it (an 18 cm bottle held at 0.88 of its height is grasped 7 cm above its centre, and
    its pre-grasp pose is then 15.0 cm from the centre: a centre-based 15 cm left no slack and failed it),
    so an approach made within 5 cm of the plan counts."""
    return hand.pregrasp_distance + APPROACH_SLACK


def _position(world: HomeWorld, name: str) -> np.ndarray:
    pos, _ = p.getBasePositionAndOrientation(world.body(name), physicsClientId=world.client)
    return np.asarray(pos, dtype=np.float64)


def object_bottom(world: HomeWorld, name: str) -> float:
    """Height of the lowest point of an entity (from its bounding box)."""
    low, _ = p.getAABB(world.body(name), -1, physicsClientId=world.client)
    return float(low[2])


def _speed(world: HomeWorld, name: str) -> float:
    linear, _ = p.getBaseVelocity(world.body(name), physicsClientId=world.client)
    return float(np.linalg.norm(linear))


def is_grasped(world: HomeWorld, name: str, side: ArmSide | str | None = None) -> bool:
    """(object, isGraspedBy, gripper): an arm holds it and it is still where the fingers took it."""
    body = world.body(name)
    sides = [ArmSide(side)] if side is not None else list(world.arms)  # the arms the robot has
    for s in sides:
        arm = world.arm(s)
        if arm.held == body:
            held = arm.carried_centre() or arm.ee_pose().position  # where the grasp holds its centre
            distance = float(np.linalg.norm(_position(world, name) - np.asarray(held)))
            return distance <= GRASP_DISTANCE
    return False


def distance_to_extent(point: Vec3, centre: Vec3, size: Vec3) -> float:
    """How far ``point`` is from an object of ``size`` (x, y, z) centred at ``centre``, taking its extent
    as an upright cylinder of its half height and its longer half side: the same whether the object's
    yaw is known (the referee) or not (the robots' belief); 0 inside it."""
    radius = max(size[0], size[1]) / 2.0
    across = max(math.hypot(point[0] - centre[0], point[1] - centre[1]) - radius, 0.0)
    up = max(abs(point[2] - centre[2]) - size[2] / 2.0, 0.0)
    return math.hypot(across, up)


def gripper_near(world: HomeWorld, side: ArmSide | str, name: str) -> bool:
    """(gripper, isNear, object): its grasp point within :func:`gripper_near_distance` of the object's extent."""
    arm = world.arm(side)
    ee = arm.ee_pose().position
    x, y, z = (float(v) for v in _position(world, name))
    return distance_to_extent(ee, (x, y, z), world.objects[name].size) <= gripper_near_distance(arm.hand)


def object_above_region(world: HomeWorld, name: str, region: Region) -> bool:
    """(object, isAbove, region): over the region's footprint and a little above its surface."""
    x, y, _ = _position(world, name)
    gap = object_bottom(world, name) - region.zmin
    return region.contains_xy(float(x), float(y)) and ABOVE_MIN <= gap <= ABOVE_MAX


def object_located_in(world: HomeWorld, name: str, region: Region) -> bool:
    """(object, isLocated, region): centre over the region, resting on its surface, not held."""
    x, y, _ = _position(world, name)
    resting = abs(object_bottom(world, name) - region.zmin) <= RESTING_TOLERANCE
    return (
        region.contains_xy(float(x), float(y))
        and resting
        and _speed(world, name) <= RESTING_SPEED
        and not is_grasped(world, name)
    )


def upright_in(world: HomeWorld, name: str, region: Region) -> bool:
    """(object, isLocated, region) for a container: upright as well (a cup on its side catches nothing)."""
    _, orn = p.getBasePositionAndOrientation(world.body(name), physicsClientId=world.client)
    upright = quat_to_matrix((orn[0], orn[1], orn[2], orn[3]))[2, 2] > 0.95
    return upright and object_located_in(world, name, region)


def contains_water(world: HomeWorld, name: str) -> bool:
    """(container, contains, Water): filled at least half."""
    return world.water_level(name) >= WATER_MIN


def on_platform(world: HomeWorld, name: str) -> bool:
    """(object, isLocatedOn, RobotPlatform): resting on the platform, inside its edges, in the base's frame."""
    base = world.base_pose()
    x, y, _ = _position(world, name)
    dx, dy = x - base.x, y - base.y
    along = dx * math.cos(base.theta) + dy * math.sin(base.theta)
    across = -dx * math.sin(base.theta) + dy * math.cos(base.theta)
    length, width = world.robot.footprint
    inside = abs(along) <= length / 2 - PLATFORM_MARGIN and abs(across) <= width / 2 - PLATFORM_MARGIN
    resting = abs(object_bottom(world, name) - world.platform_height) <= RESTING_TOLERANCE
    return inside and resting and not is_grasped(world, name) and name not in world.holders


def objects_on_platform(world: HomeWorld) -> list[str]:
    """The movable objects resting on the base's platform now (what a load sensor in it reports)."""
    return [name for name in sorted(world.objects) if on_platform(world, name)]


def base_near(
    world: HomeWorld, place: Pose2D | tuple[float, float], distance: float = BASE_NEAR_DISTANCE, heading: bool = False
) -> bool:
    """(MobileRobot, isNear, place); with ``heading`` the place's theta must match too."""
    base = world.base_pose()
    target = place if isinstance(place, Pose2D) else Pose2D(place[0], place[1])
    if base.distance_to(target.x, target.y) > distance:
        return False
    return not heading or base.heading_error(target.theta) <= BASE_NEAR_HEADING


def base_near_person(world: HomeWorld, person: str | None = None) -> bool:
    """(MobileRobot, isNear, Person); the world's person by default."""
    person = person or world.person_name
    x, y, _ = _position(world, person)
    return world.base_pose().distance_to(float(x), float(y)) <= NEAR_PERSON_DISTANCE


def with_person(world: HomeWorld, name: str, person: str | None = None) -> bool:
    """(object, isWith, Person): the person took it and it is in their hand."""
    person = person or world.person_name
    if world.holders.get(name) != person:
        return False
    px, py, _ = _position(world, person)
    thing = _position(world, name)
    in_reach = math.hypot(thing[0] - px, thing[1] - py) <= PERSON_REACH
    return in_reach and abs(thing[2] - PERSON_HAND_HEIGHT) <= HAND_HEIGHT_TOLERANCE


def robot_visible(world: HomeWorld, camera: str) -> bool:
    """Whether a camera can localise the base now: it works, and the centres and corners of both
    marker patches are in its image with nothing between them and the camera (the precondition of
    isLocalisedIn)."""
    cam = world.camera(camera)
    if cam.failed:
        return False
    base = world.base_pose()
    spec = cam.spec
    c, s = math.cos(base.theta), math.sin(base.theta)
    marker = world.marker_model
    half_along, half_across = marker.patch[0] / 2 - 0.01, marker.patch[1] / 2 - 0.01
    # Centre and corners (1 cm inside) of both patches, in the world.
    local = [
        (sign * marker.separation / 2 + da * half_along, db * half_across)
        for sign in (1.0, -1.0)
        for da, db in ((0, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))
    ]
    points = np.array([[base.x + a * c - b * s, base.y + a * s + b * c, marker.height + 0.001] for a, b in local])
    pixels = project(cam.intrinsics, cam.camera_to_world, points)
    k = cam.intrinsics
    inside = (pixels[:, 0] >= 0) & (pixels[:, 0] < k.width) & (pixels[:, 1] >= 0) & (pixels[:, 1] < k.height)
    if not bool(np.all(inside)):  # NaN (behind the camera) compares False: not inside
        return False
    hits = p.rayTestBatch([spec.eye] * len(points), points.tolist(), physicsClientId=world.client)
    return all(hit[0] in (-1, world.body(world.base_name)) for hit in hits)
