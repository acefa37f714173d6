"""How high a carried object passes over the other objects standing by its way.

Without a floor for the object's bottom, a pill box passed between the arms was carried 4 cm above the
table and the hand swept the cup beside its way off the table. Behind a side grasp the hand and the
forearm reach 30 cm back towards the robot, the wrist below the grasp point: a cup carried by its side
past a second cup 20 cm behind its way knocked that one off the table (:data:`SIDE_GRASP_ARM`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel

TRANSIT_CORRIDOR = 0.10
"""The hand's palm passes over another thing standing within 10 cm of the way, footprint to footprint (the
Panda hand is about 20 cm across along its fingers' axis)..."""


TRANSIT_CLEARANCE = 0.02
"""... 2 cm above its top; so does the carried object's bottom over a thing standing within 2 cm of the
fingers' or the object's footprint."""


@dataclass(frozen=True)
class ArmBand:
    """Where the arm is behind a side grasp's grasp point: from ``near`` to ``far`` back along the approach
    (m, level) and ``half_width`` either side of it, no part of the arm but the fingers is lower than
    ``underside`` above the grasp point (below it when negative)."""

    near: float
    far: float
    half_width: float
    underside: float


SIDE_GRASP_ARM = (ArmBand(0.0, 0.175, 0.10, 0.01), ArmBand(0.175, 0.325, 0.10, -0.03))
"""The bundled arms (Franka Panda) behind a side grasp tilted down by the default 35 degrees: the hand,
rising back from the grasp point, and the wrist and forearm, 17.5-32.5 cm back, as low as 3 cm below it.
Measured on the arms' kinematics at 239 side grasps the two arms reach over the kitchen table (grasp points
7.2-8.25 x 3.1-3.5, 0.78-0.95 m high), straight up from the table under each: the lowest point, 20-30 cm
back, was 3.0 cm below the grasp point; 12.5 cm or more to either side, or 32.5 cm or more back, the arm
was higher than the grasp point (tests/test_designate_subclass.py checks a sample). The carried object's
floor keeps this underside TRANSIT_CLEARANCE over the top of any object whose footprint comes within
TRANSIT_CLEARANCE of a band anywhere along the way, where the way ends too: there the arm comes down
whatever the floor, and a thing under it is met either way (from the side, or from above when the carry
was lifted over it)."""


def transit_floor(
    ctx: SimContext, held: ObjectModel, side: ArmSide, start: tuple[float, float], end: tuple[float, float]
) -> float | None:
    """How high the bottom of the object ``held`` (by its approach, in ``side``'s hand) must stay on its way
    from ``start`` to ``end`` (x, y) for it and the arm to pass over the other objects standing by the way,
    where each is believed to be (else where the map puts it): TRANSIT_CLEARANCE over the top of any whose
    footprint comes within that of the object's or the fingers' (the jaws' opening across), and the palm
    (the grasp height and the hand's palm depth above the object's bottom) as far over the top of any within
    TRANSIT_CORRIDOR; by a side grasp, the arm behind it (:data:`SIDE_GRASP_ARM`) as far over the top of any
    under it. None when no object stands by the way. Without it, a pill box passed between the arms was
    carried 4 cm above the table, and the hand swept the cup beside its way off the table."""
    world = ctx.world
    hand = world.arm(side).hand
    size = world.objects[held.name].size if held.name in world.objects else (held.width, held.width, held.height)
    near = max(math.hypot(size[0], size[1]) / 2.0, hand.jaw_opening / 2.0)
    palm = held.grasp_height + hand.palm_depth
    facing = world.arm_specs[side].yaw if held.grasp is GraspKind.SIDE else None
    floor: float | None = None
    for name, obj in world.objects.items():
        if name == held.name or any(arm.held == world.body(name) for arm in world.arms.values()):
            continue
        believed = ctx.belief.position(name) if ctx.belief is not None else None
        if believed is None:
            support = ctx.map.things.get(obj.support or "")
            rest = support.box.max_z if support is not None else 0.0
            believed = (obj.start.x, obj.start.y, rest + obj.size[2] / 2.0)
        x, y, z = believed
        radius = math.hypot(obj.size[0], obj.size[1]) / 2.0
        apart = _segment_distance(start, end, (x, y)) - radius
        top = z + obj.size[2] / 2.0 + TRANSIT_CLEARANCE
        needed: list[float] = []
        if apart < near + TRANSIT_CLEARANCE:
            needed.append(top)
        elif apart < near + TRANSIT_CORRIDOR:
            needed.append(top - palm)
        if facing is not None:
            needed += [top - band.underside - held.grasp_height for band in _under(start, end, facing, (x, y), radius)]
        if needed:
            floor = max(needed) if floor is None else max(floor, *needed)
    return floor


def _under(
    start: tuple[float, float], end: tuple[float, float], facing: float, point: tuple[float, float], radius: float
) -> list[ArmBand]:
    """The bands of :data:`SIDE_GRASP_ARM` that pass within TRANSIT_CLEARANCE of the footprint (``radius``
    round ``point``) of a thing standing by the way from ``start`` to ``end`` of a side grasp's grasp point,
    its approach level along ``facing``. In each band's frame (back along the approach, to the side) the
    grasp point's way is a segment and the band a rectangle."""
    ux, uy = math.cos(facing), math.sin(facing)

    def banded(grasp: tuple[float, float]) -> tuple[float, float]:
        dx, dy = grasp[0] - point[0], grasp[1] - point[1]
        return (dx * ux + dy * uy, dx * uy - dy * ux)  # how far the point is behind the grasp point, and aside

    a, b = banded(start), banded(end)
    reach = radius + TRANSIT_CLEARANCE
    return [band for band in SIDE_GRASP_ARM if _box_distance(a, b, band) < reach]


def _box_distance(a: tuple[float, float], b: tuple[float, float], band: ArmBand) -> float:
    """How far the segment from ``a`` to ``b`` is from the rectangle ``band`` spans (near..far along the
    first axis, within half_width of 0 along the second): 0 when it crosses it (Liang-Barsky clipping)."""
    low, high = (band.near, -band.half_width), (band.far, band.half_width)
    enter, leave = 0.0, 1.0
    for axis in (0, 1):
        step = b[axis] - a[axis]
        for along, room in ((-step, a[axis] - low[axis]), (step, high[axis] - a[axis])):
            if along == 0.0:
                if room < 0.0:
                    enter = 2.0  # parallel to this side and outside it
            elif along < 0.0:
                enter = max(enter, room / along)
            else:
                leave = min(leave, room / along)
    if enter <= leave:
        return 0.0
    corners = [(x, y) for x in (low[0], high[0]) for y in (low[1], high[1])]
    ends = [math.hypot(*(max(low[i] - end[i], 0.0, end[i] - high[i]) for i in (0, 1))) for end in (a, b)]
    return min(*ends, *(_segment_distance(a, b, corner) for corner in corners))


def floor_to(ctx: SimContext, held: ObjectModel, side: ArmSide, start: Sequence[float], to: Region) -> float | None:
    """:func:`transit_floor` from ``start`` (x, y, ...) to over the middle of ``to``."""
    cx, cy, _ = to.center
    return transit_floor(ctx, held, side, (start[0], start[1]), (cx, cy))


def _segment_distance(a: tuple[float, float], b: tuple[float, float], point: tuple[float, float]) -> float:
    """How far ``point`` is from the segment from ``a`` to ``b`` (all x, y)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length = dx * dx + dy * dy
    t = 0.0 if length <= 0.0 else max(0.0, min(1.0, ((point[0] - a[0]) * dx + (point[1] - a[1]) * dy) / length))
    return math.hypot(point[0] - (a[0] + t * dx), point[1] - (a[1] + t * dy))
