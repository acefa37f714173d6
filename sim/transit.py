"""How high a carried object passes over the other objects standing by its way.

Without a floor for the object's bottom, a pill box passed between the arms was carried 4 cm above the
table and the hand swept the cup beside its way off the table.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import ObjectModel

TRANSIT_CORRIDOR = 0.10
"""The hand's palm passes over another thing standing within 10 cm of the way, footprint to footprint (the
Panda hand is about 20 cm across along its fingers' axis)..."""


TRANSIT_CLEARANCE = 0.02
"""... 2 cm above its top; so does the carried object's bottom over a thing standing within 2 cm of the
fingers' or the object's footprint."""


def transit_floor(
    ctx: SimContext, held: ObjectModel, side: ArmSide, start: tuple[float, float], end: tuple[float, float]
) -> float | None:
    """How high the bottom of the object ``held`` (by its approach, in ``side``'s hand) must stay on its way
    from ``start`` to ``end`` (x, y) for it and the hand to pass over the other objects standing by the way,
    where each is believed to be (else where the map puts it): TRANSIT_CLEARANCE over the top of any whose
    footprint comes within that of the object's or the fingers' (the jaws' opening across), and the palm
    (the grasp height and the hand's palm depth above the object's bottom) as far over the top of any within
    TRANSIT_CORRIDOR; None when no object stands by the way. Without it, a pill box passed between the arms
    was carried 4 cm above the table, and the hand swept the cup beside its way off the table."""
    world = ctx.world
    hand = world.arm(side).hand
    size = world.objects[held.name].size if held.name in world.objects else (held.width, held.width, held.height)
    near = max(math.hypot(size[0], size[1]) / 2.0, hand.jaw_opening / 2.0)
    palm = held.grasp_height + hand.palm_depth
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
        apart = _segment_distance(start, end, (x, y)) - math.hypot(obj.size[0], obj.size[1]) / 2.0
        top = z + obj.size[2] / 2.0 + TRANSIT_CLEARANCE
        if apart < near + TRANSIT_CLEARANCE:
            needed: float | None = top
        elif apart < near + TRANSIT_CORRIDOR:
            needed = top - palm
        else:
            needed = None
        if needed is not None:
            floor = needed if floor is None else max(floor, needed)
    return floor


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
