"""Where on a place, or on the surface an object rests on, an object can be set down.

A grid of spots over the surface, each far enough inside an arm's reach, from the edge, from the other
objects (where they are believed to be) and from the fixtures standing on the surface: the carry aims
at the first of them (or, when the plan puts more things there after it, at the spot nearest its own in
a packing of them all: :mod:`sim.packing`), the pass between arms looks among them, and the check before
a run refuses a place that has none.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from cbrs.kb.semantic_map import Arm, SemanticMap, Thing
from cbrs.settings import setting
from cbrs.sim import skills
from cbrs.sim.geometry import Region
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.relations import region_of
from cbrs.sim.world import HomeWorld

RELAY_MARGIN = 0.05
"""A relay spot is at least 5 cm inside both arms' reach."""


RELAY_CLEARANCE = 0.06
"""A relay spot keeps 6 cm between the object's footprint and any other object's or fixture's."""


RELAY_EDGE = 0.02
"""... and 2 cm between the object's footprint and the edge of the surface."""


RELAY_STEP = 0.02
"""The spots tried are a 2 cm grid over the surface."""


SPOT_INSET = 0.005
"""The least a spot's centre keeps inside its place's edge (:func:`place_inset`), where the place is too
small to hold the object's footprint, by default: the ``spot_inset`` setting (``CBRS_SPOT_INSET``) sets it
(:func:`spot_inset`). More than a set-down's centre was seen from its spot in the runs traced (0.3 mm, the
apple set down on the west bowl's edge; 0.9-1.4 mm, the cup below the tap). Half a centimetre keeps the
spot of the 5 cm place below the tap that the fifth round's robot 10 cm west sets the cup down at, 5 mm
inside its edge; 1 cm took it off, and a pass to the other arm was added."""


def spot_inset() -> float:
    """SPOT_INSET, or the ``spot_inset`` setting where it is given (metres, 0 to 5 cm): a lab whose
    perception sees set-downs farther from their spots keeps spots farther inside narrow places."""
    return float(setting("spot_inset").resolve())


def place_inset(half: float, width: float) -> float:
    """How far inside the edges of a place ``width`` wide (along one axis) a spot's centre keeps for an
    object whose footprint reaches ``half`` from its centre along it, so that the whole footprint is over
    the place: ``half`` where the place is that wide, else :func:`least_inset`. Such spots come first
    (:func:`place_spots`); the others keep only :func:`least_inset`."""
    if width >= 2.0 * half:
        return half
    return least_inset(width)


def least_inset(width: float) -> float:
    """The least a spot's centre keeps inside the edges of a place ``width`` wide: :func:`spot_inset`, or the middle
    of a place narrower than twice that. Whether a thing is on or in a place is asked of its centre as
    perception sees it (``predicates``): a centre on the edge counts either way by a fraction of a
    millimetre. Before, a spot's centre only had to be over the place, edge included, and a lab's apple
    carried to the one part of a bowl the arm reached, its edge, was seen 0.3 mm outside it
    (docs/simulation.md)."""
    return min(spot_inset(), width / 2.0)


def reach_of(arm: Arm) -> tuple[float, float, float]:
    """An arm's reach as :func:`place_spots` takes it: (mount x, mount y, reach)."""
    return (arm.mount[0], arm.mount[1], arm.reach)


def distance_to_extent(box: tuple[float, float, float, float], point: tuple[float, ...]) -> float:
    """From a point to the nearest point of an extent (min x, max x, min y, max y), on the floor plan."""
    dx = max(box[0] - point[0], 0.0, point[0] - box[1])
    dy = max(box[2] - point[1], 0.0, point[1] - box[3])
    return math.hypot(dx, dy)


def able_mounts(world: HomeWorld, carried: str, *also: str) -> list[tuple[float, float, float]]:
    """The reaches (:func:`reach_of`) of the world's arms that could set ``carried`` (a name) down: those
    holding nothing, it, or one of ``also`` (a thing a packing's later carry follows: set down first). An arm
    holding something else cannot take the step, so its spots must not take away another arm's
    (:func:`place_spots`' ``able``)."""
    names = {carried, *also}
    return [
        (spec.mount[0], spec.mount[1], spec.reach)
        for side, spec in sorted(world.arm_specs.items())
        if (held := world.arm(side).held) is None or world.name_of(held) in names
    ]


def held_now(world: HomeWorld, *leaving: str) -> dict[str, str]:
    """What the world's arms hold now: object IRI by arm IRI, but the things of ``leaving`` (names: set down
    before what is asked about)."""
    found = {}
    for side, spec in sorted(world.arm_specs.items()):
        body = world.arm(side).held
        name = world.name_of(body) if body is not None else None
        if name is not None and name in world.objects and name not in leaving:
            found[spec.iri] = world.objects[name].iri
    return found


def other_objects(world: HomeWorld, belief: PerceivedWorld | None, *names: str) -> list[tuple[float, float, float]]:
    """The objects other than ``names`` as (x, y, footprint radius): where each is believed to be, else
    where the map puts it."""
    found = []
    for other, obj in world.objects.items():
        if other in names:
            continue
        believed = belief.position(other) if belief is not None else None
        x, y = (believed[0], believed[1]) if believed is not None else (obj.start.x, obj.start.y)
        found.append((x, y, math.hypot(obj.size[0], obj.size[1]) / 2.0))
    return found


def fixtures_on(
    smap: SemanticMap, support: Thing, surface: float, up_to: float
) -> list[tuple[float, float, float, float]]:
    """The extents (min x, max x, min y, max y) of the things of the map standing on or hanging over the
    support's top within ``up_to`` above its ``surface`` (a dispenser), not the rooms and regions."""
    top = support.box
    return [
        (t.box.min_x, t.box.max_x, t.box.min_y, t.box.max_y)
        for iri, t in smap.things.items()
        if iri not in smap.rooms
        and iri not in smap.regions
        and iri != support.iri
        and t.box.max_z > surface + 0.005
        and t.box.min_z < surface + up_to
        and t.box.min_x < top.max_x
        and t.box.max_x > top.min_x
        and t.box.min_y < top.max_y
        and t.box.max_y > top.min_y
    ]


def place_spots(
    smap: SemanticMap,
    place: Thing,
    size: tuple[float, float, float],
    mounts: Sequence[tuple[float, float, float]],
    others: Sequence[tuple[float, float, float]],
    able: Sequence[tuple[float, float, float]] | None = None,
) -> tuple[Region, list[tuple[float, float]]]:
    """Where on a place an object of ``size`` can be set down by an arm mounted at one of ``mounts``
    (x, y, reach): the place's surface (a region's bottom, a piece of furniture's top), and the spots of
    a grid over the place, from its centre out, nearest the centre first, where the object's centre is
    over the place, :func:`place_inset` inside its edges (its footprint's circle where the place holds
    it), and at least RELAY_MARGIN inside a mount's reach, its footprint on the surface it
    rests on (the furniture under a region) RELAY_EDGE inside the edge, RELAY_CLEARANCE clear of
    ``others`` (x, y, radius) and of the fixtures it would meet on the way down (a dispenser's body; not
    the spout high above it). The place's centre is the first spot where it is one: a place an arm only
    partly reaches is worked at its reachable part, not at a centre no arm reaches.

    The spots are those with the whole footprint over the place where ``mounts`` have any; else none where
    another arm that can take the step has one (it sets the thing down wholly inside: the west bowl's apple
    goes to the arm that reaches its middle, not onto the edge the other reaches); else those whose centre
    is only :func:`least_inset` inside the place, so that a place with room for the whole footprint only
    where no arm can set it down (the pen's 20 x 15 cm spot beside the dispenser) is still used. The arms
    that can take the step are ``able`` (reaches as ``mounts``; :func:`able_mounts`: not one holding
    something else), else every arm of the map: an arm that is busy does not take the edge from one that
    is free."""
    surface, support = support_of(smap, place)
    cx, cy, z = surface.center
    box = support.box
    radius = math.hypot(size[0], size[1]) / 2.0
    fixtures = fixtures_on(smap, support, z, size[2] + skills.ABOVE_CLEARANCE)
    inset = radius + RELAY_EDGE
    width, depth = surface.xmax - surface.xmin, surface.ymax - surface.ymin
    whole_x, whole_y = place_inset(radius, width) - 1e-9, place_inset(radius, depth) - 1e-9
    in_x, in_y = least_inset(width) - 1e-9, least_inset(depth) - 1e-9
    everyone = [*mounts, *(able if able is not None else (reach_of(arm) for arm in smap.arms.values()))]

    def reached(x: float, y: float, by: Sequence[tuple[float, float, float]]) -> bool:
        return any(math.hypot(x - mx, y - my) <= reach - RELAY_MARGIN for mx, my, reach in by)

    found: list[tuple[bool, bool, float, float, float]] = []  # (whole, mine, distance from the centre, x, y)
    nx = int((surface.xmax - surface.xmin) / 2.0 / RELAY_STEP) + 1
    ny = int((surface.ymax - surface.ymin) / 2.0 / RELAY_STEP) + 1
    for i in range(-nx, nx + 1):
        x = cx + i * RELAY_STEP
        if not (surface.xmin + in_x <= x <= surface.xmax - in_x and box.min_x + inset <= x <= box.max_x - inset):
            continue
        for j in range(-ny, ny + 1):
            y = cy + j * RELAY_STEP
            if not (surface.ymin + in_y <= y <= surface.ymax - in_y and box.min_y + inset <= y <= box.max_y - inset):
                continue
            mine = reached(x, y, mounts)
            if not (mine or reached(x, y, everyone)):
                continue
            if any(math.hypot(x - ox_, y - oy) < radius + r + RELAY_CLEARANCE for ox_, oy, r in others):
                continue
            if any(distance_to_extent(extent, (x, y)) < radius + RELAY_CLEARANCE for extent in fixtures):
                continue
            whole = surface.xmin + whole_x <= x <= surface.xmax - whole_x and (
                surface.ymin + whole_y <= y <= surface.ymax - whole_y
            )
            found.append((whole, mine, math.hypot(x - cx, y - cy), x, y))
    if any(whole for whole, mine, *_ in found if mine):
        chosen = [(d, x, y) for whole, mine, d, x, y in found if whole and mine]
    elif any(whole for whole, *_ in found):
        chosen = []
    else:
        chosen = [(d, x, y) for _, mine, d, x, y in found if mine]
    return surface, [(x, y) for _, x, y in sorted(chosen)]


def support_of(smap: SemanticMap, place: Thing) -> tuple[Region, Thing]:
    """A place's surface (a region's bottom, a piece of furniture's top) and what an object set down there
    rests on: the furniture itself, or the furniture under a region (else the region)."""
    furniture = place.iri in smap.furniture
    surface = region_of(place, furniture)
    cx, cy, z = surface.center
    if furniture:
        return surface, place
    support = next(
        (
            smap.things[iri]
            for iri in sorted(smap.furniture)
            if iri in smap.things
            and smap.things[iri].box.contains_xy(cx, cy)
            and abs(smap.things[iri].box.max_z - z) <= 0.03
        ),
        place,
    )
    return surface, support


def resting_surface(smap: SemanticMap, place: Thing) -> tuple[Thing | None, float]:
    """What a thing set down in a region comes to rest on, and at what height: the highest top of the map's
    furniture under the region's centre that is not above the region's top (a carry lowers a thing from
    above until it rests), else the floor (None, 0 m). A region's ``home:minZ`` is where things in it rest
    (:func:`relations.region_of`), so it must be that height: nothing of a region is built to rest on."""
    box = place.box
    cx, cy = (box.min_x + box.max_x) / 2, (box.min_y + box.max_y) / 2
    under = [
        smap.things[iri]
        for iri in sorted(smap.furniture)
        if iri in smap.things
        and iri != place.iri
        and smap.things[iri].box.contains_xy(cx, cy)
        and smap.things[iri].box.max_z <= box.max_z + 1e-9
    ]
    if not under:
        return None, 0.0
    top = max(under, key=lambda thing: thing.box.max_z)
    return top, top.box.max_z


def spot_region(surface: Region, x: float, y: float) -> Region:
    """Where around a spot of a place's surface an object is carried to and set down (its centre over
    the spot, give or take a relay spot's tolerance): the place itself decides the step's effects."""
    half = RELAY_STEP * 2
    return Region(surface.name, x - half, x + half, y - half, y + half, surface.zmin, surface.zmin + 0.3)
