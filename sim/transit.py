"""How high a carried object passes over the other objects standing by its way.

Without a floor for the object's bottom, a pill box passed between the arms was carried 4 cm above the
table and the hand swept the cup beside its way off the table. Behind a side grasp the hand and the
forearm reach 30 cm back towards the robot, the wrist below the grasp point: a cup carried by its side
past a second cup 20 cm behind its way knocked that one off the table. How far the hand reaches either side
of its way and where the arm is behind a side grasp are the carrying hand's, as the store describes it
(:class:`kb.hands.Hand`'s ``carry_corridor`` and ``side_arm``: ``home:carryCorridor``, ``home:sideGraspBand``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import NamedTuple

from cbrs.kb.arm_bands import ArmBand
from cbrs.kb.semantic_map import local_name
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel

TRANSIT_CLEARANCE = 0.02
"""How far above the top of a thing standing by the way a carry keeps what passes over it (m): the carried
object's bottom over a thing within this of the fingers' or the object's footprint; the hand's palm over one
within the hand's carry corridor; by a side grasp, each band of the arm behind it over one whose footprint
comes within this of the band anywhere along the way, where the way ends too (there the arm comes down
whatever the floor, and a thing under it is met either way: from the side, or from above when the carry
was lifted over it)."""


def transit_floor(
    ctx: SimContext, held: ObjectModel, side: ArmSide, start: tuple[float, float], end: tuple[float, float]
) -> float | None:
    """How high the bottom of the object ``held`` (by its approach, in ``side``'s hand) must stay on its way
    from ``start`` to ``end`` (x, y) for it and the arm to pass over the other objects standing by the way,
    where each is believed to be (else where the map puts it): TRANSIT_CLEARANCE over the top of any whose
    footprint comes within that of the object's or the fingers' (the jaws' opening across), and the palm
    (the grasp height and the hand's palm depth above the object's bottom) as far over the top of any within
    the hand's ``carry_corridor``; by a side grasp, each band of the arm behind it (the hand's ``side_arm``)
    as far over the top of any under it. None when no object stands by the way. Without it, a pill box passed
    between the arms was carried 4 cm above the table, and the hand swept the cup beside its way off the
    table."""
    needs = floor_needs(ctx, held, side, start, end)
    return max(need.height for need in needs) if needs else None


def floor_cause(
    ctx: SimContext, held: ObjectModel, side: ArmSide, start: tuple[float, float], end: tuple[float, float]
) -> str:
    """What sets :func:`transit_floor` of the same way: the thing standing by it, and what of the hand or the
    arm keeps over it (a band of the arm behind a side grasp, as the store states it); empty when nothing
    stands by the way. A carry that cannot be made at that floor is refused naming it."""
    needs = floor_needs(ctx, held, side, start, end)
    return max(needs, key=lambda need: (need.height, need.why)).why if needs else ""


class FloorNeed(NamedTuple):
    """One height :func:`transit_floor` asks of the held object's bottom (m), and what asks it: ``why`` in
    words, the ``thing`` (its name) standing by the way, its ``top`` (m), and the ``band`` of the arm behind a
    side grasp kept over it (None: the object itself or the palm is)."""

    height: float
    why: str
    thing: str
    top: float
    band: ArmBand | None = None


def floor_needs(
    ctx: SimContext, held: ObjectModel, side: ArmSide, start: tuple[float, float], end: tuple[float, float]
) -> list[FloorNeed]:
    """Each height :func:`transit_floor` asks of the held object's bottom, with what asks it."""
    world = ctx.world
    hand = world.arm(side).hand
    size = world.objects[held.name].size if held.name in world.objects else (held.width, held.width, held.height)
    near = max(math.hypot(size[0], size[1]) / 2.0, hand.jaw_opening / 2.0)
    palm = held.grasp_height + hand.palm_depth
    facing = world.arm_specs[side].yaw if held.grasp is GraspKind.SIDE else None
    needs: list[FloorNeed] = []
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
        over = f"the {name} (its top at {top - TRANSIT_CLEARANCE:.3f} m)"
        bare = top - TRANSIT_CLEARANCE
        if apart < near + TRANSIT_CLEARANCE:
            itself = f"the {held.name} itself kept {TRANSIT_CLEARANCE * 100:.0f} cm over {over}"
            needs.append(FloorNeed(top, itself, name, bare))
        elif apart < near + hand.carry_corridor:
            corridor = f"{hand.carry_corridor * 100:.0f} cm carry corridor"
            needs.append(FloorNeed(top - palm, f"the hand's palm, over {over} within its {corridor}", name, bare))
        if facing is not None:
            for band in _under(hand.side_arm, start, end, facing, (x, y), radius):
                height = top - band.underside - held.grasp_height
                needs.append(FloorNeed(height, f"{_band(band)} over {over}", name, bare, band))
    return needs


def band_advice(
    ctx: SimContext,
    held: ObjectModel,
    side: ArmSide,
    start: tuple[float, float],
    end: tuple[float, float],
    need: FloorNeed,
    below: float,
) -> str:
    """What of ``need``'s band (a band of the arm behind a side grasp, over a thing by the way) would let the
    held object's bottom stay at ``below`` m: its underside no lower under the grasp point than that asks,
    or, when the thing is not behind the way itself, the band no wider than would miss it; empty for a need
    no band sets."""
    band = need.band
    if band is None:
        return ""
    world = ctx.world
    underside = math.ceil((need.top + TRANSIT_CLEARANCE - held.grasp_height - below) * 1000.0) / 1000.0  # to 1 mm, up
    hand = ctx.world.arm(side).hand
    whose = f"the {local_name(hand.iri)}'s" if hand.iri else "the hand's"
    said = (
        f"{whose} band (home:sideGraspBand) no lower than {_level(underside)} the grasp point (it is"
        f" {_level(band.underside)}"
    )
    obj = world.objects.get(need.thing)
    believed = ctx.belief.position(need.thing) if ctx.belief is not None else None
    if obj is not None:
        point = (believed[0], believed[1]) if believed is not None else (obj.start.x, obj.start.y)
        radius = math.hypot(obj.size[0], obj.size[1]) / 2.0
        facing = world.arm_specs[side].yaw

        def under(half_width: float) -> bool:
            return bool(_under([replace(band, half_width=half_width)], start, end, facing, point, radius))

        if under(0.0):
            return f"{said}; no narrower band would do: the {need.thing} is behind the way itself)"
        low, high = 0.0, band.half_width  # missed at ``low``, met at ``high``
        while high - low > 0.001:
            middle = (low + high) / 2.0
            low, high = (low, middle) if under(middle) else (middle, high)
        wide = f"{math.floor(low * 1000.0) / 10.0:.1f} cm to either side (it is {band.half_width * 100:.0f} cm)"
        return f"{said}), or that band no wider than {wide}"
    return f"{said})"


def _level(underside: float) -> str:
    """A band's underside against the grasp point, for a message."""
    if abs(underside) < 0.0005:
        return "level with"
    return f"{abs(underside) * 100:.1f} cm {'above' if underside > 0.0 else 'below'}"


def _band(band: ArmBand) -> str:
    """A band of the arm behind a side grasp, as the store states it, for a message."""
    level = "level with" if band.underside == 0.0 else f"{abs(band.underside) * 100:.1f} cm "
    level += "" if band.underside == 0.0 else ("above" if band.underside > 0.0 else "below")
    return (
        f"the arm's band {band.near:.3f}-{band.far:.3f} m back from the grasp point ({band.half_width * 100:.0f} cm "
        f"to either side, {level} the grasp point; home:sideGraspBand)"
    )


def _under(
    bands: Sequence[ArmBand],
    start: tuple[float, float],
    end: tuple[float, float],
    facing: float,
    point: tuple[float, float],
    radius: float,
) -> list[ArmBand]:
    """The ``bands`` of an arm behind a side grasp that pass within TRANSIT_CLEARANCE of the footprint (``radius``
    round ``point``) of a thing standing by the way from ``start`` to ``end`` of a side grasp's grasp point,
    its approach level along ``facing``. In each band's frame (back along the approach, to the side) the
    grasp point's way is a segment and the band a rectangle."""
    ux, uy = math.cos(facing), math.sin(facing)

    def banded(grasp: tuple[float, float]) -> tuple[float, float]:
        dx, dy = grasp[0] - point[0], grasp[1] - point[1]
        return (dx * ux + dy * uy, dx * uy - dy * ux)  # how far the point is behind the grasp point, and aside

    a, b = banded(start), banded(end)
    reach = radius + TRANSIT_CLEARANCE
    return [band for band in bands if _box_distance(a, b, band) < reach]


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
