"""Several things the plan puts on one place: where each is set down so that the rest still fit, and the
refusal before the run of a place that cannot hold them all.

A carry used to set its object down at the place's spot nearest the centre (:func:`place_spots`), so a
small eraser put first in the middle of a 40 x 40 cm shelf left no spot for the 14 cm pen the plan put
there next, and the run failed after the first thing had moved (docs/tasks.md, "A sixth round"). The
footprints (the things' boxes turned as they lie, :class:`Footprint`; else the circles :func:`place_spots`
keeps apart) are packed on the place's spots by a small exact search (:func:`arrange`), each later thing
only where an arm can set it down (:func:`arm_choice.cannot_set_down`): a carry sets its object down at the
spot nearest the centre, as for one thing alone, among those that leave room for the things the plan puts
there after it, and the checks before the run refuse a place on which no arrangement holds them all.
docs/simulation.md, "Several things onto one place" and "Footprints, and the arms' say over the spots",
gives the reasoning.
"""

from __future__ import annotations

import functools
import itertools
import logging
import math
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any, NamedTuple, ParamSpec

from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import Arm, MapObject, SemanticMap, Thing, local_name
from cbrs.sim import skills
from cbrs.sim.arm_choice import ARM_TIE, TAKING, cannot_set_down, let_go_held
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext
from cbrs.sim.geometry import Region
from cbrs.sim.grounding import task_inputs_of
from cbrs.sim.place_spots import (
    RELAY_CLEARANCE,
    RELAY_EDGE,
    RELAY_MARGIN,
    RELAY_STEP,
    able_mounts,
    fixtures_on,
    held_now,
    other_objects,
    place_inset,
    place_spots,
    reach_of,
    support_of,
)
from cbrs.sim.relations import region_of
from cbrs.sim.relay import RELAY_TRIES

log = logging.getLogger("cbrs.sim")
_P = ParamSpec("_P")

CARRYING = PREFIXES["act"] + "CarryingWhileLocomoting"
"""The action of the steps that set an object down on the place they are given."""

Size = tuple[float, float, float]
Mount = tuple[float, float, float]
Spot = tuple[float, float]


@dataclass(frozen=True)
class PackingRule:
    """How footprints are packed on a place: in which order (``largest``: the largest footprint first,
    the one the fewest spots hold; ``plan``: as the plan puts them there) and at which of its spots each
    goes (``rim``: the spot farthest from the place's centre, nearest an arm on a tie, so the middle stays
    open for what comes after; ``centre``: the spot nearest the centre, as one thing alone is set down)."""

    order: str = "largest"
    toward: str = "rim"
    footprint: str = "auto"
    """``box``: each thing covers its box (:class:`Footprint`) turned as the set-down leaves it; ``circle``:
    the circle about its diagonal, as :func:`place_spots` keeps one thing alone (the packing's first form);
    ``auto``: circles where circles hold them all, else boxes. Circles ask nothing of the turn a thing
    comes to rest at, which a carry does not set (the hand keeps the turn it took the thing by, give or
    take how it slipped), so they are the safer where they fit; boxes fit what circles refuse (two long
    things side by side on a narrow shelf). Boxes everywhere moved the cup of PenThenCupAway so that
    the pen's carry stopped 4 cm short of its spot (docs/simulation.md, "Footprints")."""

    def __post_init__(self) -> None:
        if self.order not in ("largest", "plan") or self.toward not in ("rim", "centre"):
            raise ValueError(
                f"a packing rule orders 'largest' or 'plan' and goes toward 'rim' or 'centre', not {self.order!r}"
                f" and {self.toward!r}"
            )
        if self.footprint not in FOOTPRINTS:
            raise ValueError(f"a packing rule's footprint is one of {', '.join(FOOTPRINTS)}, not {self.footprint!r}")


FOOTPRINTS = ("auto", "box", "circle")
"""The footprints a :class:`PackingRule` may pack (docs/simulation.md, "Footprints")."""


@dataclass(frozen=True)
class Footprint:
    """What a thing covers of the surface it rests on: the map's box of it (home:sizeX by home:sizeY; a round
    thing's box holds its disc), its long side along ``axis`` (radians). A carry keeps the turn the hand
    took the thing by (``skills.carry_object`` is given no yaw), so a thing comes to rest turned as it lay
    where it was taken: the map's home:yaw, give or take the world's spread (docs/simulation.md)."""

    length: float
    width: float
    axis: float

    @classmethod
    def lying(cls, size: Size, yaw: float) -> Footprint:
        """The footprint of a thing of ``size`` whose x side lies along ``yaw`` (as the map's home:yaw)."""
        across = size[1] > size[0]
        return cls(max(size[0], size[1]), min(size[0], size[1]), yaw + (math.pi / 2.0 if across else 0.0))

    @property
    def radius(self) -> float:
        """The circle about it (its half diagonal): nothing of it is farther from its centre."""
        return math.hypot(self.length, self.width) / 2.0

    def grown(self, by: float) -> Footprint:
        return Footprint(self.length + 2.0 * by, self.width + 2.0 * by, self.axis)

    def half_extent(self) -> tuple[float, float]:
        """How far it reaches from its centre along x and along y."""
        c, s = abs(math.cos(self.axis)), abs(math.sin(self.axis))
        return (c * self.length + s * self.width) / 2.0, (s * self.length + c * self.width) / 2.0

    def corners(self, x: float, y: float) -> list[Spot]:
        """Its corners, in turn, centred at (x, y)."""
        c, s = math.cos(self.axis), math.sin(self.axis)
        a, b = self.length / 2.0, self.width / 2.0
        return [(x + c * u - s * v, y + s * u + c * v) for u, v in ((a, b), (-a, b), (-a, -b), (a, -b))]


def footprint_of(obj: MapObject) -> Footprint:
    """The footprint of an object of the map, turned as the map says it lies."""
    return Footprint.lying(obj.size, obj.start.yaw)


def gap(a: Sequence[Spot], b: Sequence[Spot]) -> float:
    """The distance between two convex polygons (corners in turn; one corner: a point), 0 where they meet."""
    if _overlap(a, b):
        return 0.0
    return min(min(_to_polygon(p, b) for p in a), min(_to_polygon(p, a) for p in b))


def _overlap(a: Sequence[Spot], b: Sequence[Spot]) -> bool:
    for poly in (a, b):  # separated along the normal of an edge of one of them, else they meet
        for (x0, y0), (x1, y1) in zip(poly, [*poly[1:], poly[0]], strict=True):
            nx, ny = y0 - y1, x1 - x0
            on_a = [nx * x + ny * y for x, y in a]
            on_b = [nx * x + ny * y for x, y in b]
            if max(on_a) < min(on_b) or max(on_b) < min(on_a):
                return False
    return True


def _to_polygon(p: Spot, poly: Sequence[Spot]) -> float:
    best = math.inf
    for (x0, y0), (x1, y1) in zip(poly, [*poly[1:], poly[0]], strict=True):
        dx, dy = x1 - x0, y1 - y0
        length = dx * dx + dy * dy
        t = 0.0 if length == 0.0 else max(0.0, min(1.0, ((p[0] - x0) * dx + (p[1] - y0) * dy) / length))
        best = min(best, math.hypot(p[0] - x0 - t * dx, p[1] - y0 - t * dy))
    return best


Lying = tuple[float, float, Footprint]
"""A thing on a place as the box packing takes it: (x, y, its footprint)."""


def clear_of(
    foot: Footprint,
    x: float,
    y: float,
    others: Sequence[tuple[float, float, float]],
    lying: Sequence[Lying],
    fixtures: Sequence[Sequence[Spot]] = (),
) -> bool:
    """Whether ``foot`` at (x, y) keeps RELAY_CLEARANCE from ``others`` (circles: x, y, radius), from the
    footprints of ``lying`` and from ``fixtures`` (polygons)."""
    radius = foot.radius
    near = [(ox, oy, r) for ox, oy, r in others if math.hypot(x - ox, y - oy) < radius + r + RELAY_CLEARANCE]
    close = [
        (ox, oy, other)
        for ox, oy, other in lying
        if math.hypot(x - ox, y - oy) < radius + other.radius + RELAY_CLEARANCE
    ]
    if not (near or close or fixtures):
        return True
    corners = foot.corners(x, y)
    if any(gap(corners, [(ox, oy)]) < r + RELAY_CLEARANCE for ox, oy, r in near):
        return False
    if any(gap(corners, other.corners(ox, oy)) < RELAY_CLEARANCE for ox, oy, other in close):
        return False
    return all(gap(corners, fixture) >= RELAY_CLEARANCE for fixture in fixtures)


def box_spots(
    smap: SemanticMap,
    place: Thing,
    foot: Footprint,
    height: float,
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    lying: Sequence[Lying] = (),
) -> tuple[Region, list[Spot]]:
    """:func:`place_spots` for a thing of footprint ``foot`` (``height`` tall): the same grid, reach and
    order (a point's spots), its centre :func:`place_inset` inside the place's edges by the footprint's
    half extent, and the footprint itself RELAY_EDGE inside the edge of what it rests on and
    RELAY_CLEARANCE clear of the fixtures it would meet on the way down, of ``others`` (x, y, radius) and
    of the footprints of ``lying``."""
    surface, points = place_spots(smap, place, (0.0, 0.0, height), mounts, [])
    _, support = support_of(smap, place)
    box = support.box
    hx, hy = foot.half_extent()
    in_x = place_inset(hx, surface.xmax - surface.xmin) - 1e-9
    in_y = place_inset(hy, surface.ymax - surface.ymin) - 1e-9
    extents = fixtures_on(smap, support, surface.center[2], height + skills.ABOVE_CLEARANCE)
    fixtures = [[(x0, y0), (x1, y0), (x1, y1), (x0, y1)] for x0, x1, y0, y1 in extents]
    return surface, [
        (x, y)
        for x, y in points
        if box.min_x + hx + RELAY_EDGE <= x <= box.max_x - hx - RELAY_EDGE
        and box.min_y + hy + RELAY_EDGE <= y <= box.max_y - hy - RELAY_EDGE
        and surface.xmin + in_x <= x <= surface.xmax - in_x
        and surface.ymin + in_y <= y <= surface.ymax - in_y
        and clear_of(foot, x, y, others, lying, fixtures)
    ]


@dataclass(frozen=True)
class PutDown:
    """A step of a plan that sets an object down on a place (IRIs), by the robot ``device``."""

    step: int
    device: str
    place: str
    obj: str


class PlaceOverfilledError(KnowledgeBaseError):
    """The plan puts more on a place than it holds: each object has a spot there alone, but no arrangement
    of their footprints (with what is on it already, the set-down's clearance and edge), each where an arm
    can set it down, holds them all. The run is refused before anything moves. ``objects``: (IRI, size) of
    those the plan puts there; ``already``: (IRI, x, y, radius) of those on it now; ``top``: its width and
    depth; ``reached``: the part of its top the arms reach, and ``free``: what the objects on it leave of
    that, in square metres; ``footprint``: the packing's (:data:`FOOTPRINTS`); ``unheld``: for each object
    the arms were asked about, (IRI, spots refused, spots asked, the first refusal); ``busy``: (side, IRI)
    of each arm of the robot not counted at a carry of them, holding that object then (:func:`arms_free`)."""

    http_status = 422

    def __init__(
        self,
        place: str,
        objects: Sequence[tuple[str, Size]],
        already: Sequence[tuple[str, float, float, float]],
        top: tuple[float, float],
        reached: float,
        footprint: str = "circle",
        unheld: Sequence[tuple[str, int, int, str]] = (),
        busy: Sequence[tuple[str, str]] = (),
    ) -> None:
        self.place = place
        self.objects = tuple(objects)
        self.already = tuple(already)
        self.top = top
        self.reached = reached
        self.footprint = footprint
        self.unheld = tuple(unheld)
        self.busy = tuple(busy)
        self.free = max(reached - sum(math.pi * r * r for *_, r in self.already), 0.0)
        boxed = footprint == "box"
        each = ", ".join(
            f"the {local_name(iri)} ({100 * size[0]:.1f} x {100 * size[1]:.1f} cm"
            + (")" if boxed else f", {200 * radius_of(size):.1f} cm across)")
            for iri, size in self.objects
        )
        on_it = (
            ", and "
            + " and ".join(f"the {local_name(iri)} at ({x:.2f}, {y:.2f})" for iri, x, y, _ in self.already)
            + f" on it already {'leaves' if len(self.already) == 1 else 'leave'} {self.free:.3f} m2 free"
            if self.already
            else ", nothing on it now"
        )
        c = RELAY_CLEARANCE
        if boxed:
            need = sum((s[0] + c) * (s[1] + c) for _, s in self.objects)
            shape = "their footprints (their boxes, turned as they lie)"
        else:
            need = sum(math.pi * (radius_of(s) + c / 2) ** 2 for _, s in self.objects)
            shape = "their footprints (the circles about their diagonals)"
        held = "".join(
            f"; the arms cannot hold the {local_name(iri)} over {no} of the {asked} spots asked ({why})"
            for iri, no, asked, why in self.unheld
        )
        holding = " and ".join(f"the {side} arm holds the {local_name(iri)}" for side, iri in self.busy)
        arms = f"the arms free to set them down reach (when {holding})" if self.busy else "the arms reach"
        super().__init__(
            f"the plan puts {each} on the {local_name(place)}, which cannot hold them together: of its"
            f" {100 * top[0]:.0f} x {100 * top[1]:.0f} cm top ({top[0] * top[1]:.3f} m2) {arms}"
            f" {reached:.3f} m2{on_it}; {shape}, {100 * c:.0f} cm apart and {100 * RELAY_EDGE:.0f} cm inside its"
            f" edge, need about {need:.3f} m2, and no arrangement of them on its spots (a {100 * RELAY_STEP:.0f} cm"
            f" grid) holds them all, each where an arm can set it down, though each alone has a spot{held}; put"
            " fewer things there, clear it first, or make it larger (home:minX, home:maxX, home:minY, home:maxY)"
        )


def radius_of(size: Size) -> float:
    """The footprint's radius: the circle about the diagonal, as :func:`place_spots` keeps them apart."""
    return math.hypot(size[0], size[1]) / 2.0


PACK_BUDGET = 200_000
"""The most pairs of spots a packing compares before it gives up undecided (a few tenths of a second):
then the carry sets down as one thing alone is, and the check before the run refuses nothing."""


def pack(
    smap: SemanticMap,
    place: Thing,
    sizes: Sequence[Size],
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    rule: PackingRule = PackingRule(),
) -> list[Spot] | None:
    """A spot for each of ``sizes`` (in their order) on ``place``, each of :func:`place_spots` (reach, edge,
    fixtures, ``others`` as (x, y, radius)) and the footprints RELAY_CLEARANCE apart: the first arrangement
    found taking them in the ``rule``'s order, each at the first spot it prefers that is clear of those
    before it, going back to the one before when none is. None when no arrangement of the spots holds them
    all, or when PACK_BUDGET comparisons did not decide (:class:`Undecided`)."""
    try:
        return arrange(smap, place, sizes, mounts, others, rule)
    except Undecided:
        return None


class Undecided(Exception):
    """A packing gave up after PACK_BUDGET comparisons: whether the footprints fit is not known."""


Holds = Callable[[int, Spot], bool]
"""Whether the thing of a packing (by its index) can be set down at a spot: an arm can hold it over it."""


def arrange(
    smap: SemanticMap,
    place: Thing,
    sizes: Sequence[Size],
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    rule: PackingRule = PackingRule(),
    budget: int = PACK_BUDGET,
    feet: Sequence[Footprint] | None = None,
    lying: Sequence[Lying] = (),
    holds: Holds | None = None,
    able: Sequence[Sequence[Mount] | None] | None = None,
    by: Sequence[Sequence[Mount]] | None = None,
) -> list[Spot] | None:
    """As :func:`pack`, but None only when no arrangement of the spots holds them all; :class:`Undecided`
    when ``budget`` comparisons did not decide. A footprint's spots do not depend on the others' but for
    their distance, so each list is asked once (:func:`place_spots`, or :func:`box_spots` for the rule's
    ``box`` footprints: ``feet``, else each box along x) and the search compares centres. ``lying``: the
    footprints of things on the place kept clear of (circles about them, for ``circle``); ``holds``: asked
    of each spot the search would take, which it passes over when refused; ``able``: for each thing, the
    arms that can set it down (:func:`place_spots`' ``able``; None: every arm of the map); ``by``: for each
    thing, the arms whose reach its spots are in (else ``mounts``)."""
    shapes = list(feet) if feet is not None else [Footprint.lying(size, 0.0) for size in sizes]
    lists = _spot_lists(smap, place, sizes, mounts, others, rule, shapes, lying, able, by)
    if not all(lists):
        return None
    return _search(lists, sizes, shapes, rule, budget, holds)


def _spot_lists(
    smap: SemanticMap,
    place: Thing,
    sizes: Sequence[Size],
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    rule: PackingRule,
    shapes: Sequence[Footprint],
    lying: Sequence[Lying],
    able: Sequence[Sequence[Mount] | None] | None = None,
    by: Sequence[Sequence[Mount]] | None = None,
) -> list[list[Spot]]:
    """Each thing's spots alone, in the order the rule prefers them, in the reach of its entry of ``by``
    (else ``mounts``); by circles, each counting only the arms of ``able`` that can set it down (its entry;
    None: every arm of the map), as one thing alone does (:func:`place_spots`: an arm holding something
    else takes no spot away from another). A box's spots (:func:`box_spots`) keep its whole footprint over
    the place, whichever arm has them."""
    surface = region_of(place, place.iri in smap.furniture)
    cx, cy, _ = surface.center
    boxed = rule.footprint == "box"
    circles = list(others) if boxed else [*others, *((x, y, foot.radius) for x, y, foot in lying)]
    lists: list[list[Spot]] = []
    ables = list(able) if able is not None else [None] * len(sizes)
    reaches = list(by) if by is not None else [mounts] * len(sizes)
    for size, foot, arms, reach in zip(sizes, shapes, ables, reaches, strict=True):
        if boxed:
            _, spots = box_spots(smap, place, foot, size[2], reach, circles, lying)
        else:
            _, spots = place_spots(smap, place, size, reach, circles, arms)
        if rule.toward == "rim":  # farthest from the centre first; on a tie the nearer an arm
            near = [min((math.hypot(x - mx, y - my) for mx, my, _ in reach), default=0.0) for x, y in spots]
            ranked = sorted(
                range(len(spots)),
                key=lambda k: (-round(math.hypot(spots[k][0] - cx, spots[k][1] - cy), 6), round(near[k], 6), k),
            )
            spots = [spots[k] for k in ranked]
        lists.append(spots)
    return lists


def _search(
    lists: Sequence[Sequence[Spot]],
    sizes: Sequence[Size],
    shapes: Sequence[Footprint],
    rule: PackingRule,
    budget: int,
    holds: Holds | None,
) -> list[Spot] | None:
    """The first arrangement of the things on their ``lists`` of spots (:func:`arrange`)."""
    boxed = rule.footprint == "box"
    radii = [foot.radius if boxed else radius_of(size) for size, foot in zip(sizes, shapes, strict=True)]
    order = sorted(range(len(sizes)), key=lambda n: -radii[n]) if rule.order == "largest" else list(range(len(sizes)))
    chosen: dict[int, Spot] = {}
    left = [budget]
    known: dict[tuple[int, int, int, int], bool] = {}  # box footprints apart, by the grid offset between them

    def apart(n: int, at: Spot, m: int, other: Spot) -> bool:
        if math.hypot(at[0] - other[0], at[1] - other[1]) >= radii[n] + radii[m] + RELAY_CLEARANCE:
            return True
        if not boxed:
            return False
        key = (n, m, round((at[0] - other[0]) / RELAY_STEP), round((at[1] - other[1]) / RELAY_STEP))
        if key not in known:
            known[key] = gap(shapes[n].corners(*at), shapes[m].corners(*other)) >= RELAY_CLEARANCE
        return known[key]

    def place_from(depth: int) -> bool:
        if depth == len(order):
            return True
        n = order[depth]
        for at in lists[n]:
            left[0] -= len(chosen)
            if left[0] < 0:
                raise Undecided()
            if all(apart(n, at, m, other) for m, other in chosen.items()) and (holds is None or holds(n, at)):
                chosen[n] = at
                if place_from(depth + 1):
                    return True
                del chosen[n]
        return False

    return [chosen[n] for n in range(len(sizes))] if place_from(0) else None


SET_DOWN_SLACK = 0.02
"""How far a thing may come to rest from the spot it is set down at while the later things still fit: a
spot is taken as leaving room when they fit beside its footprint grown by this much (a set-down is
accurate to a centimetre or so), else, when no spot does, beside the footprint itself."""

SPOT_BUDGET = 20_000
"""The comparisons :func:`arrange` may make for one spot asked whether it leaves room (PACK_BUDGET is
for one whole place); a spot undecided within it is taken as leaving none."""


def _set_down_spots(
    smap: SemanticMap,
    place: Thing,
    size: Size,
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    later: Sequence[Size] = (),
    rule: PackingRule = PackingRule(),
    foot: Footprint | None = None,
    later_feet: Sequence[Footprint] | None = None,
    lying: Sequence[Lying] = (),
    holds: Holds | None = None,
    able: Sequence[Mount] | None = None,
    later_able: Sequence[Sequence[Mount] | None] | None = None,
    later_by: Sequence[Sequence[Mount]] | None = None,
    wider_by: Sequence[Sequence[Mount]] | None = None,
    own: Callable[[Spot], bool] | None = None,
) -> tuple[Region, list[Spot], int | None]:
    """The surface and spots of :func:`place_spots` (:func:`box_spots` for the rule's ``box`` footprints:
    ``foot``, ``later_feet``, else boxes along x) for an object set down on ``place``, when the plan puts
    the objects of ``later`` (sizes) there after it: first those that leave room for them all (some
    arrangement of theirs, :func:`arrange`, fits beside it, with SET_DOWN_SLACK, each where ``holds``
    says an arm can set it down), nearest the centre first as for one thing alone, up to RELAY_TRIES of
    them (as many as the carry asks the arm about), then the rest. As the spots are ordered when nothing
    comes after it or no spot leaves room (the run goes on, and the later carry says what is in its way).
    ``able`` (this thing's) and ``later_able`` (each later thing's): the arms that can set it down
    (:func:`place_spots`' ``able``, :func:`able_mounts`; None: every arm of the map); ``later_by``: each
    later thing's arms whose reach its spots are in (else ``mounts``), and ``wider_by`` those asked when no
    spot leaves room within them (the arms free at its carry: it may go to another arm); ``own``: whether
    the arm that sets this one down can let it go over a spot (None: any it reaches), asked of each spot
    found leaving room: one it cannot is not taken as leaving room (the carry would pass it over and set the
    thing down at the first it can, as for one thing alone).
    With them, how many of its first spots leave room (0 when none does; None when nothing comes after it
    or it has no spot), which :func:`carry_spots` reads; :func:`set_down_spots` gives the first two."""
    boxed = rule.footprint == "box"
    mine = foot if foot is not None else Footprint.lying(size, 0.0)
    if boxed:
        surface, spots = box_spots(smap, place, mine, size[2], mounts, others, lying)
    else:
        circles = [*others, *((x, y, each.radius) for x, y, each in lying)]
        surface, spots = place_spots(smap, place, size, mounts, circles, able)
    if not later or not spots:
        return surface, spots, None
    mine_asked: dict[Spot, bool] = {}  # the carrying arm's answer at a spot, asked once

    def letting_go(at: Spot) -> bool:
        if at not in mine_asked:
            mine_asked[at] = own is None or own(at)
        return mine_asked[at]

    asked: dict[tuple[int, Spot], bool] = {}  # an arm's answer for a later thing at a spot, asked once

    def held(n: int, at: Spot) -> bool:
        if (n, at) not in asked:
            asked[n, at] = holds is None or holds(n, at)
        return asked[n, at]

    shapes = list(later_feet) if later_feet is not None else [Footprint.lying(each, 0.0) for each in later]
    clear: dict[tuple[int, int, int, float], bool] = {}  # a later thing clear of this one, by their grid offset

    def beside(n: int, at: Spot, spot: Spot, slack: float) -> bool:
        if math.hypot(at[0] - spot[0], at[1] - spot[1]) >= shapes[n].radius + mine.radius + slack + RELAY_CLEARANCE:
            return True
        key = (n, round((at[0] - spot[0]) / RELAY_STEP), round((at[1] - spot[1]) / RELAY_STEP), slack)
        if key not in clear:
            clear[key] = clear_of(shapes[n], *at, [], [(*spot, mine.grown(slack))])
        return clear[key]

    tiers = [later_by, *([wider_by] if wider_by is not None and wider_by != later_by else [])]
    for by, slack in itertools.product(tiers, (SET_DOWN_SLACK, 0.0)):
        alone = _spot_lists(smap, place, later, mounts, others, rule, shapes, lying, later_able, by)  # without it
        keeping: list[Spot] = []
        for x, y in spots:
            if boxed:
                lists = [[at for at in each if beside(n, at, (x, y), slack)] for n, each in enumerate(alone)]
            else:
                reach = radius_of(size) + slack + RELAY_CLEARANCE
                lists = [
                    [at for at in each if math.hypot(at[0] - x, at[1] - y) >= radius_of(s) + reach]
                    for each, s in zip(alone, later, strict=True)
                ]
            try:
                if (
                    all(lists)
                    and _search(lists, later, shapes, rule, SPOT_BUDGET, held) is not None
                    and letting_go((x, y))
                ):
                    keeping.append((x, y))
            except Undecided:
                continue
            if len(keeping) == RELAY_TRIES:
                break
        if keeping:
            return surface, [*keeping, *(spot for spot in spots if spot not in keeping)], len(keeping)
    return surface, spots, 0


def _surface_and_spots(
    found: Callable[_P, tuple[Region, list[Spot], int | None]],
) -> Callable[_P, tuple[Region, list[Spot]]]:
    """``found`` (:func:`_set_down_spots`) giving the surface and spots alone, its parameters its own: the
    public form, which says nothing of how many spots leave room, without a copy of its sixteen parameters."""

    @functools.wraps(found)
    def spots(*args: _P.args, **kwargs: _P.kwargs) -> tuple[Region, list[Spot]]:
        surface, each, _ = found(*args, **kwargs)
        return surface, each

    spots.__name__ = spots.__qualname__ = "set_down_spots"
    return spots


set_down_spots = _surface_and_spots(_set_down_spots)


def puts_down(
    plan: Plan,
    smap: SemanticMap,
    values: Mapping[str, Any],
    known: Mapping[int, Mapping[str, Any]] | None = None,
) -> list[PutDown]:
    """The steps of ``plan`` that set an object down on a place of the map, in the plan's order: a carry
    (:data:`CARRYING`) given one place, of the object the robot's latest taking step before it works on
    (the task's ``values``, through the steps that compute them). The place is what ``known`` (the
    executor's inputs of a step, by index) says, else the task's value; a carry whose place or object is
    not known before the run (a later step's output) is left out."""
    steps = {step.index: step for step in plan.steps}
    holding: dict[str, str] = {}  # by robot: the object its latest taking step works on
    found: list[PutDown] = []
    for step in plan.steps:
        device = step.device or ""
        if step.action in TAKING:
            taken = _taken(step, steps, smap, values)
            if taken is not None:
                holding[device] = taken
            else:
                holding.pop(device, None)
            continue
        if step.action != CARRYING or device not in holding:
            continue
        places = [iri for iri in _given_iris(step, values, known) if iri in smap.regions or iri in smap.furniture]
        if len(places) == 1:
            found.append(PutDown(step.index, device, places[0], holding.pop(device)))
    return found


def _taken(step: PlanStep, steps: Mapping[int, PlanStep], smap: SemanticMap, values: Mapping[str, Any]) -> str | None:
    """The one object of the map a taking step works on (the task's values, through the steps that compute
    them), else None."""
    given = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
    iris = [str(v["@id"]) for v in given if isinstance(v, dict) and str(v.get("@id")) in smap.objects]
    return iris[0] if len(iris) == 1 else None


class AtCarry(NamedTuple):
    """A robot's arms at one of its carries (:func:`arms_free`): ``free``, those that can set the thing
    down, and ``busy``, what each other one holds then (arm IRI: object IRI)."""

    free: list[Arm]
    busy: dict[str, str]


APPROACHING = PREFIXES["act"] + "ApproachToObject"
"""The taking step whose hold lasts until a carry sets the thing down (loading the platform ends its own)."""


def arms_free(
    plan: Plan,
    smap: SemanticMap,
    values: Mapping[str, Any],
    where: Mapping[str, tuple[float, float, float]] | None = None,
    held: Mapping[str, str] | None = None,
    after: int | None = None,
    known: Mapping[int, Mapping[str, Any]] | None = None,
) -> dict[int, AtCarry]:
    """For each carry of ``plan`` that sets an object down on a place (:func:`puts_down`; by its step's
    index), the arms of its robot that can set it down then (:class:`AtCarry`): those that hold nothing
    else at that point of the plan. A carry sets down what the robot's latest ApproachToObject took (as
    :func:`puts_down` has it), else, with no take since its last carry, what its one busy arm holds; until
    then that arm holds it. So a thing an arm holds now (``held``: arm IRI to object IRI) and the plan does
    not carry keeps that arm busy throughout, and a thing the plan takes and carries nowhere (the cup a task
    takes and keeps while it puts the pen away) from its take on. Which arm takes a thing is the run's
    choice (``who_takes``); here the one it asks first (``arm_choice.reaching``): of the robot's free arms
    whose mount is within their reach of the thing (where ``where`` puts it: x, y, radius; else the map),
    the nearest, on a tie (ARM_TIE) the first by side, as which arm acted last is not known here. A take
    no free arm reaches is foreseen by no arm. ``after``: the running step's index; the steps up to it are
    not walked (``held`` is the world as it is then)."""
    downs = {down.step: down for down in puts_down(plan, smap, values, known)}
    steps = {step.index: step for step in plan.steps}
    holding = dict(held or {})  # arm IRI: the object it holds
    latest: dict[str, str] = {}  # by robot: the arm of its latest take that no carry has followed yet
    found: dict[int, AtCarry] = {}
    walked = [step.index for step in plan.steps]
    if after is not None and after in walked:
        walked = walked[walked.index(after) + 1 :]
    for index in walked:
        step = steps[index]
        device = step.device or ""
        arms = sorted((arm for arm in smap.arms.values() if arm.robot == device), key=lambda arm: arm.side)
        if step.action == APPROACHING:
            taken = _taken(step, steps, smap, values)
            arm = _taker(arms, holding, _at(taken, where, smap)) if taken is not None else None
            if arm is not None and taken is not None:
                holding[arm.iri] = taken
                latest[device] = arm.iri
            else:
                latest.pop(device, None)
            continue
        if step.action != CARRYING:
            continue
        carrying = latest.pop(device, None)
        if carrying is None:  # no take before it: it carries what the robot's one busy arm holds
            busy = [arm.iri for arm in arms if arm.iri in holding]
            carrying = busy[0] if len(busy) == 1 else None
        if index in downs:
            thing = downs[index].obj
            free = [arm for arm in arms if holding.get(arm.iri, thing) == thing]
            found[index] = AtCarry(free, {arm.iri: holding[arm.iri] for arm in arms if arm not in free})
        if carrying is not None:
            holding.pop(carrying, None)  # set down there
    return found


def _at(
    iri: str | None, where: Mapping[str, tuple[float, float, float]] | None, smap: SemanticMap
) -> tuple[float, float] | None:
    if iri is None:
        return None
    if where is not None and iri in where:
        return where[iri][0], where[iri][1]
    obj = smap.objects.get(iri)
    return (obj.start.x, obj.start.y) if obj is not None else None


def _taker(arms: Sequence[Arm], holding: Mapping[str, str], at: tuple[float, float] | None) -> Arm | None:
    """The arm the run asks first to take a thing at ``at``: the free one nearest it within its reach."""
    if at is None:
        return None
    options = [
        (distance, arm)
        for arm in arms
        if arm.iri not in holding and (distance := math.hypot(at[0] - arm.mount[0], at[1] - arm.mount[1])) <= arm.reach
    ]
    if not options:
        return None
    best = min(distance for distance, _ in options)
    return min((arm for distance, arm in options if distance - best <= ARM_TIE), key=lambda arm: arm.side)


def _given_iris(step: PlanStep, values: Mapping[str, Any], known: Mapping[int, Mapping[str, Any]] | None) -> list[str]:
    if known is not None and step.index in known:
        given = list(known[step.index].values())
    else:
        given = [values.get(b.source.name) for b in step.inputs if b.source.step is None]
    return [str(v["@id"]) for v in given if isinstance(v, dict) and "@id" in v]


def packed_with(
    plan: Plan | None,
    step: PlanStep | None,
    smap: SemanticMap,
    place: str,
    values: Mapping[str, Any],
    known: Mapping[int, Mapping[str, Any]] | None = None,
) -> tuple[list[str], list[str]]:
    """The objects (IRIs) the plan's carries by the robot of ``step`` (a carry) set down on ``place`` before
    it and after it, each in the plan's order; none when the plan or the step is not known."""
    earlier, later = _packed(plan, step, smap, place, values, known)
    return [down.obj for down in earlier], [down.obj for down in later]


def _packed(
    plan: Plan | None,
    step: PlanStep | None,
    smap: SemanticMap,
    place: str,
    values: Mapping[str, Any],
    known: Mapping[int, Mapping[str, Any]] | None = None,
) -> tuple[list[PutDown], list[PutDown]]:
    """:func:`packed_with`'s put-downs themselves."""
    if plan is None or step is None:
        return [], []
    order = [each.index for each in plan.steps]
    if step.index not in order:
        return [], []
    at = order.index(step.index)
    before, after = set(order[:at]), set(order[at + 1 :])
    mine = [
        down
        for down in puts_down(plan, smap, values, known)
        if down.place == place and down.device == (step.device or "")
    ]
    return [down for down in mine if down.step in before], [down for down in mine if down.step in after]


def later_sizes(
    plan: Plan | None,
    step: PlanStep | None,
    smap: SemanticMap,
    place: str,
    values: Mapping[str, Any],
    known: Mapping[int, Mapping[str, Any]] | None = None,
) -> list[Size]:
    """The sizes of the objects the plan's carries after ``step`` (the running one) set down on ``place``
    by the same robot, in the plan's order; none when the plan or the step is not known."""
    return [smap.objects[iri].size for iri in packed_with(plan, step, smap, place, values, known)[1]]


def carry_spots(
    ctx: SimContext, place: Thing, carried: str, side: ArmSide, step: PlanStep | None, rule: PackingRule = PackingRule()
) -> tuple[Region, list[Spot]]:
    """Where the carry of ``carried`` (a name) at ``step`` by the arm ``side`` aims on ``place``, best first:
    for one thing alone :func:`place_spots`' order, as before; when the plan's carries by the same robot
    put others there before or after it, :func:`set_down_spots` with the rule's footprints (the map's, the
    things on the place where they are believed to be) and each later thing's spots asked whether an arm
    can hold it there (:func:`arm_choice.cannot_set_down`). Asked by the carry (``services.carry``) and by
    the choice of approach before it (:func:`arm_choice.hold_end`), so both aim at the same spot.

    A spot leaves room only where this arm can let the thing go over it (:func:`arm_choice.let_go_held`,
    else :func:`arm_choice.cannot_set_down`).
    Where it has no such spot and another arm, free now, has one, none are given for this arm: the carry
    passes the thing to that arm (``services.carry``), as where this arm reaches no spot at all. Before, the
    spots that left room came first whether or not this arm could set the thing down there, and the carry
    took the first it could, which left none (docs/execution.md, "Room on a top: which arms count")."""
    surface, spots, kept = _carry_spots(ctx, place, carried, side, step, rule)
    if kept is None or kept or not spots:
        return surface, spots
    world = ctx.world
    for other in sorted(world.arm_specs):
        if other is side or world.arm(other).held is not None:
            continue
        if _carry_spots(ctx, place, carried, other, step, rule)[2]:
            log.info(
                "the %s arm has no spot of %s leaving room; the %s has: %s is passed",
                side.value,
                place.iri,
                other.value,
                carried,
            )
            return surface, []
    return surface, spots


def _carry_spots(
    ctx: SimContext, place: Thing, carried: str, side: ArmSide, step: PlanStep | None, rule: PackingRule
) -> tuple[Region, list[Spot], int | None]:
    """:func:`carry_spots` for the arm ``side`` alone, and how many of its first spots leave room for what
    the plan puts there after it (0 when none does; None when nothing comes after it or the packing is
    undecided)."""
    world, smap = ctx.world, ctx.map
    obj = world.objects.get(carried)
    size = obj.size if obj is not None else (0.0, 0.0, 0.0)
    mounts = [reach_of(world.arm_specs[side])]
    others = other_objects(world, ctx.belief, carried)
    earlier, downs = _packed(ctx.plan, step, smap, place.iri, ctx.given, ctx.known)
    able = able_mounts(world, carried)  # an arm holding something else leaves this one its spots
    if obj is None or step is None or ctx.plan is None or not (earlier or downs):
        return (*place_spots(smap, place, size, mounts, others, able), None)
    coming = [smap.objects[down.obj] for down in downs]
    # a later thing's arms: those free at its carry, what the plan takes and keeps until then counted
    # (arms_free; the world's arms as they are now, what is carried now set down before it)
    found = other_objects(world, ctx.belief)
    where = {each.iri: spot for each, spot in zip(world.objects.values(), found, strict=True)}
    free = arms_free(ctx.plan, smap, ctx.given, where, held_now(world, carried), step.index, ctx.known)
    later_arms = [free[down.step].free if down.step in free else [] for down in downs]
    later_able = [[reach_of(arm) for arm in arms] for arms in later_arms]
    # within the reach of the arm that sets this one down where it is free then, as before; else of those that are
    later_by = [
        mounts if any(arm.side == side.value for arm in arms) else list(reach)
        for arms, reach in zip(later_arms, later_able, strict=True)
    ]
    surface, _ = support_of(smap, place)

    made: list[Spot] = []  # a spot whose carry the arm's planning would make: the later ones are asked less

    def own(at: Spot) -> bool:  # whether this arm can let it go over the spot (and carry it there)
        held = let_go_held(ctx, side, carried, surface, at, planned=not made)
        if not (not cannot_set_down(ctx, obj, surface, at, {side}) if held is None else held):
            return False
        made.append(at)
        return True

    holds = _HoldAsked(ctx, coming, surface, [{ArmSide(arm.side) for arm in arms} for arms in later_arms])
    sizes = [each.size for each in coming]
    circles = replace(rule, footprint="circle")
    if rule.footprint == "circle" or (
        rule.footprint == "auto"
        and _circles_hold(smap, place, size, sizes, mounts, others, [able, *later_able], [mounts, *later_by])
    ):
        return _set_down_spots(
            smap,
            place,
            size,
            mounts,
            others,
            sizes,
            circles,
            holds=holds,
            able=able,
            later_able=later_able,
            later_by=later_by,
            wider_by=later_able,
            own=own,
        )
    rule = replace(rule, footprint="box")
    names = [name for name in world.objects if name != carried]  # in the order of ``others``
    lying = [(x, y, footprint_of(world.objects[name])) for name, (x, y, _) in zip(names, others, strict=True)]
    feet = [footprint_of(each) for each in coming]
    try:
        return _set_down_spots(
            smap,
            place,
            size,
            mounts,
            [],
            sizes,
            rule,
            footprint_of(obj),
            feet,
            lying,
            holds,
            later_by=later_by,
            wider_by=later_able,
            own=own,
        )
    except Undecided:  # more spots asked of the arms than HOLD_TRIES: as for one thing alone
        return (*place_spots(smap, place, size, mounts, others, able), None)


def _circles_hold(
    smap: SemanticMap,
    place: Thing,
    size: Size,
    later: Sequence[Size],
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    able: Sequence[Sequence[Mount] | None] | None = None,
    by: Sequence[Sequence[Mount]] | None = None,
) -> bool:
    """Whether circles hold the thing carried now and those the plan puts on ``place`` after it, beside
    what is there (the ``auto`` rule's first question; undecided counts as holding, as circles did);
    ``able`` and ``by``: each one's arms that can set it down, and whose reach its spots are in, as
    :func:`arrange`'s."""
    try:
        circles = PackingRule(footprint="circle")
        return arrange(smap, place, [size, *later], mounts, others, circles, able=able, by=by) is not None
    except Undecided:
        return True


HOLD_TRIES = 400
"""The most spots one packing asks the arms about (:func:`arm_choice.cannot_set_down`: inverse kinematics,
a few milliseconds each) before it gives up undecided."""


class _HoldAsked:
    """Whether an arm can set each thing of a packing down at a spot of ``surface`` (:data:`Holds`), each
    asked once, and why not; :class:`Undecided` past HOLD_TRIES questions."""

    def __init__(
        self,
        ctx: SimContext,
        objects: Sequence[MapObject],
        surface: Region,
        sides: Sequence[Collection[ArmSide]] | None = None,
    ) -> None:
        self.ctx, self.objects, self.surface = ctx, objects, surface
        self.sides = sides  # each thing's arms that can set it down then (None: every arm of the robot)
        self.answers: dict[tuple[int, Spot], str] = {}

    def __call__(self, n: int, at: Spot) -> bool:
        if (n, at) not in self.answers:
            if len(self.answers) >= HOLD_TRIES:
                raise Undecided()
            sides = self.sides[n] if self.sides is not None else None
            self.answers[n, at] = cannot_set_down(self.ctx, self.objects[n], self.surface, at, sides)
        return not self.answers[n, at]

    def refused(self) -> list[tuple[str, int, int, str]]:
        """For each thing asked about: its IRI, the spots refused, the spots asked, the first refusal."""
        said = []
        for n, obj in enumerate(self.objects):
            mine = [why for (m, _), why in self.answers.items() if m == n]
            no = [why for why in mine if why]
            if no:
                said.append((obj.iri, len(no), len(mine), no[0]))
        return said


def check_room(ctx: SimContext, plan: Plan, values: Mapping[str, Any], rule: PackingRule = PackingRule()) -> None:
    """Refuse (:class:`PlaceOverfilledError`, :func:`overfilled`) a plan that puts several objects on one
    place no arrangement of their footprints holds where an arm can set each down, the other objects where
    they are believed to be."""
    world = ctx.world
    found = other_objects(world, ctx.belief)
    where = {obj.iri: spot for obj, spot in zip(world.objects.values(), found, strict=True)}
    refused = overfilled(world.map, plan, values, where, rule, ctx, held_now(world))
    if refused is not None:
        raise refused


def overfilled(
    smap: SemanticMap,
    plan: Plan,
    values: Mapping[str, Any],
    where: Mapping[str, tuple[float, float, float]],
    rule: PackingRule = PackingRule(),
    ctx: SimContext | None = None,
    held: Mapping[str, str] | None = None,
) -> PlaceOverfilledError | None:
    """Why ``plan`` puts several objects on one place when no arrangement of their footprints (the rule's:
    the map's boxes, turned as it says they lie, or circles) on its spots holds them all (:func:`arrange`),
    with the objects of ``where`` (IRI: x, y, footprint radius) that it does not carry where they are, each
    by the arms of the robot that sets them down that are free at its carry (:func:`arms_free`: not holding,
    then, what they hold now, ``held``: arm IRI to object IRI, or what the plan took and keeps); given
    ``ctx``, each where one of those arms can hold it (:func:`arm_choice.cannot_set_down`). None when each
    such place holds them, or when the search is undecided. A place that has no spot for one of them alone
    is left to the check of each step (``run_checks.PlanChecks._check_spot``), which says why. The ``auto``
    rule refuses what neither circles nor boxes hold (with the boxes' words)."""
    if rule.footprint == "auto":
        if overfilled(smap, plan, values, where, replace(rule, footprint="circle"), ctx, held) is None:
            return None
        return overfilled(smap, plan, values, where, replace(rule, footprint="box"), ctx, held)
    free = arms_free(plan, smap, values, where, held)
    by_place: dict[tuple[str, str], dict[str, AtCarry]] = {}
    for down in puts_down(plan, smap, values):
        arms_of = by_place.setdefault((down.place, down.device), {})
        arms_of.setdefault(down.obj, free.get(down.step, AtCarry([], {})))  # at its first carry there
    boxed = rule.footprint == "box"
    for (iri, _), carried in by_place.items():
        if len(carried) < 2:
            continue
        objects = list(carried)
        by = [[reach_of(arm) for arm in at.free] for at in carried.values()]
        mounts = list(dict.fromkeys(reach for reach in itertools.chain(*by)))
        place = smap.things[iri]
        rest = [(other, spot) for other, spot in where.items() if other not in objects]
        sizes = [smap.objects[obj].size for obj in objects]
        feet = [footprint_of(smap.objects[obj]) for obj in objects]
        if boxed:  # the things on it by their boxes, those of the map turned as it says
            others = [spot for other, spot in rest if other not in smap.objects]
            lying = [(x, y, footprint_of(smap.objects[other])) for other, (x, y, _) in rest if other in smap.objects]
        else:
            others, lying = [spot for _, spot in rest], []
        around = [spot for _, spot in rest]
        if not all(place_spots(smap, place, size, arms, around, arms)[1] for size, arms in zip(sizes, by, strict=True)):
            continue  # one alone has no spot: the step's own check says why
        surface = region_of(place, iri in smap.furniture)
        sides = [{ArmSide(arm.side) for arm in at.free} for at in carried.values()]
        holds = _HoldAsked(ctx, [smap.objects[obj] for obj in objects], surface, sides) if ctx is not None else None
        try:
            if arrange(smap, place, sizes, mounts, others, rule, PACK_BUDGET, feet, lying, holds, by, by) is not None:
                continue
        except Undecided:
            log.info("room check: whether %s holds %s is undecided; the run goes on", iri, ", ".join(objects))
            continue
        return PlaceOverfilledError(
            iri,
            [(obj, size) for obj, size in zip(objects, sizes, strict=True)],
            [(other, x, y, r) for other, (x, y, r) in rest if surface.contains_xy(x, y)],
            (surface.xmax - surface.xmin, surface.ymax - surface.ymin),
            reached_area(surface, mounts),
            rule.footprint,
            holds.refused() if holds is not None else [],
            list(dict.fromkeys((smap.arms[arm].side, obj) for at in carried.values() for arm, obj in at.busy.items())),
        )
    return None


def reached_area(surface: Region, mounts: Sequence[Mount]) -> float:
    """About how much of a surface is within reach of a mount (RELAY_MARGIN inside it), in square metres:
    the cells of a RELAY_STEP grid whose centre is."""
    nx = max(round((surface.xmax - surface.xmin) / RELAY_STEP), 1)
    ny = max(round((surface.ymax - surface.ymin) / RELAY_STEP), 1)
    dx, dy = (surface.xmax - surface.xmin) / nx, (surface.ymax - surface.ymin) / ny
    cells = sum(
        any(
            math.hypot(surface.xmin + (i + 0.5) * dx - mx, surface.ymin + (j + 0.5) * dy - my) <= reach - RELAY_MARGIN
            for mx, my, reach in mounts
        )
        for i in range(nx)
        for j in range(ny)
    )
    return cells * dx * dy
