"""Several things the plan puts on one place: where each is set down so that the rest still fit, and the
refusal before the run of a place that cannot hold them all.

A carry used to set its object down at the place's spot nearest the centre (:func:`place_spots`), so a
small eraser put first in the middle of a 40 x 40 cm shelf left no spot for the 14 cm pen the plan put
there next, and the run failed after the first thing had moved (docs/tasks.md, "A sixth round"). The
footprints (the circles :func:`place_spots` keeps apart) are packed on the place's spots by a small
exact search (:func:`arrange`): a carry sets its object down at the spot nearest the centre, as for one
thing alone, among those that leave room for the things the plan puts there after it, and the checks
before the run refuse a place on which no arrangement holds them all.
docs/simulation.md, "Several things onto one place", gives the reasoning.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap, Thing, local_name
from cbrs.sim.arm_choice import TAKING
from cbrs.sim.geometry import Region
from cbrs.sim.grounding import task_inputs_of
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.place_spots import RELAY_CLEARANCE, RELAY_EDGE, RELAY_MARGIN, RELAY_STEP, other_objects, place_spots
from cbrs.sim.relations import region_of
from cbrs.sim.relay import RELAY_TRIES
from cbrs.sim.world import HomeWorld

log = logging.getLogger("cbrs.sim")

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

    def __post_init__(self) -> None:
        if self.order not in ("largest", "plan") or self.toward not in ("rim", "centre"):
            raise ValueError(
                f"a packing rule orders 'largest' or 'plan' and goes toward 'rim' or 'centre', not {self.order!r}"
                f" and {self.toward!r}"
            )


@dataclass(frozen=True)
class PutDown:
    """A step of a plan that sets an object down on a place (IRIs), by the robot ``device``."""

    step: int
    device: str
    place: str
    obj: str


class PlaceOverfilledError(KnowledgeBaseError):
    """The plan puts more on a place than it holds: each object has a spot there alone, but no arrangement
    of their footprints (with what is on it already, the set-down's clearance and edge) holds them all.
    The run is refused before anything moves. ``objects``: (IRI, size) of those the plan puts there;
    ``already``: (IRI, x, y, radius) of those on it now; ``top``: its width and depth; ``reached``: the
    part of its top the arms reach, and ``free``: what the objects on it leave of that, in square metres."""

    http_status = 422

    def __init__(
        self,
        place: str,
        objects: Sequence[tuple[str, Size]],
        already: Sequence[tuple[str, float, float, float]],
        top: tuple[float, float],
        reached: float,
    ) -> None:
        self.place = place
        self.objects = tuple(objects)
        self.already = tuple(already)
        self.top = top
        self.reached = reached
        self.free = max(reached - sum(math.pi * r * r for *_, r in self.already), 0.0)
        each = ", ".join(
            f"the {local_name(iri)} ({100 * size[0]:.1f} x {100 * size[1]:.1f} cm, {200 * radius_of(size):.1f} cm"
            " across)"
            for iri, size in self.objects
        )
        on_it = (
            ", and "
            + " and ".join(f"the {local_name(iri)} at ({x:.2f}, {y:.2f})" for iri, x, y, _ in self.already)
            + f" on it already {'leaves' if len(self.already) == 1 else 'leave'} {self.free:.3f} m2 free"
            if self.already
            else ", nothing on it now"
        )
        need = sum(math.pi * (radius_of(s) + RELAY_CLEARANCE / 2) ** 2 for _, s in self.objects)
        super().__init__(
            f"the plan puts {each} on the {local_name(place)}, which cannot hold them together: of its"
            f" {100 * top[0]:.0f} x {100 * top[1]:.0f} cm top ({top[0] * top[1]:.3f} m2) the arms reach"
            f" {reached:.3f} m2{on_it}; their footprints, {100 * RELAY_CLEARANCE:.0f} cm apart and"
            f" {100 * RELAY_EDGE:.0f} cm inside its edge, need about {need:.3f} m2, and no arrangement of them on"
            f" its spots (a {100 * RELAY_STEP:.0f} cm grid) holds them all, though each alone has one; put fewer"
            " things there, clear it first, or make it larger (home:minX, home:maxX, home:minY, home:maxY)"
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


def arrange(
    smap: SemanticMap,
    place: Thing,
    sizes: Sequence[Size],
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    rule: PackingRule = PackingRule(),
    budget: int = PACK_BUDGET,
) -> list[Spot] | None:
    """As :func:`pack`, but None only when no arrangement of the spots holds them all; :class:`Undecided`
    when ``budget`` comparisons did not decide. A footprint's spots do not depend on the others' but for
    their distance, so each list is asked of :func:`place_spots` once and the search compares centres."""
    surface = region_of(place, place.iri in smap.furniture)
    cx, cy, _ = surface.center
    lists: list[list[Spot]] = []
    for size in sizes:
        _, spots = place_spots(smap, place, size, mounts, others)
        if rule.toward == "rim":  # farthest from the centre first; on a tie the nearer an arm
            near = [min((math.hypot(x - mx, y - my) for mx, my, _ in mounts), default=0.0) for x, y in spots]
            ranked = sorted(
                range(len(spots)),
                key=lambda k: (-round(math.hypot(spots[k][0] - cx, spots[k][1] - cy), 6), round(near[k], 6), k),
            )
            spots = [spots[k] for k in ranked]
        if not spots:
            return None
        lists.append(spots)
    radii = [radius_of(size) for size in sizes]
    order = sorted(range(len(sizes)), key=lambda n: -radii[n]) if rule.order == "largest" else list(range(len(sizes)))
    chosen: dict[int, Spot] = {}
    left = [budget]

    def place_from(depth: int) -> bool:
        if depth == len(order):
            return True
        n = order[depth]
        for x, y in lists[n]:
            left[0] -= len(chosen)
            if left[0] < 0:
                raise Undecided()
            if all(
                math.hypot(x - ox, y - oy) >= radii[n] + radii[m] + RELAY_CLEARANCE for m, (ox, oy) in chosen.items()
            ):
                chosen[n] = (x, y)
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


def set_down_spots(
    smap: SemanticMap,
    place: Thing,
    size: Size,
    mounts: Sequence[Mount],
    others: Sequence[tuple[float, float, float]],
    later: Sequence[Size] = (),
    rule: PackingRule = PackingRule(),
) -> tuple[Region, list[Spot]]:
    """The surface and spots of :func:`place_spots` for an object set down on ``place``, when the plan puts
    the objects of ``later`` (sizes) there after it: first those that leave room for them all (some
    arrangement of theirs, :func:`arrange`, fits beside it, with SET_DOWN_SLACK), nearest the centre first
    as for one thing alone, up to RELAY_TRIES of them (as many as the carry asks the arm about), then the
    rest. As :func:`place_spots` orders them when nothing comes after it or no spot leaves room (the run
    goes on, and the later carry says what is in its way)."""
    surface, spots = place_spots(smap, place, size, mounts, others)
    if not later or not spots:
        return surface, spots
    radius = radius_of(size)
    for slack in (SET_DOWN_SLACK, 0.0):
        keeping: list[Spot] = []
        for x, y in spots:
            try:
                grown = [*others, (x, y, radius + slack)]
                if arrange(smap, place, later, mounts, grown, rule, SPOT_BUDGET) is not None:
                    keeping.append((x, y))
            except Undecided:
                continue
            if len(keeping) == RELAY_TRIES:
                break
        if keeping:
            return surface, [*keeping, *(spot for spot in spots if spot not in keeping)]
    return surface, spots


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
            given = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
            iris = [str(v["@id"]) for v in given if isinstance(v, dict) and str(v.get("@id")) in smap.objects]
            if len(iris) == 1:
                holding[device] = iris[0]
            else:
                holding.pop(device, None)
            continue
        if step.action != CARRYING or device not in holding:
            continue
        places = [iri for iri in _given_iris(step, values, known) if iri in smap.regions or iri in smap.furniture]
        if len(places) == 1:
            found.append(PutDown(step.index, device, places[0], holding.pop(device)))
    return found


def _given_iris(step: PlanStep, values: Mapping[str, Any], known: Mapping[int, Mapping[str, Any]] | None) -> list[str]:
    if known is not None and step.index in known:
        given = list(known[step.index].values())
    else:
        given = [values.get(b.source.name) for b in step.inputs if b.source.step is None]
    return [str(v["@id"]) for v in given if isinstance(v, dict) and "@id" in v]


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
    if plan is None or step is None:
        return []
    order = [each.index for each in plan.steps]
    if step.index not in order:
        return []
    after = set(order[order.index(step.index) + 1 :])
    return [
        smap.objects[down.obj].size
        for down in puts_down(plan, smap, values, known)
        if down.step in after and down.place == place and down.device == (step.device or "")
    ]


def check_room(world: HomeWorld, belief: PerceivedWorld, plan: Plan, values: Mapping[str, Any]) -> None:
    """Refuse (:class:`PlaceOverfilledError`, :func:`overfilled`) a plan that puts several objects on one
    place no arrangement of their footprints holds, the other objects where they are believed to be."""
    found = other_objects(world, belief)
    where = {obj.iri: spot for obj, spot in zip(world.objects.values(), found, strict=True)}
    refused = overfilled(world.map, plan, values, where)
    if refused is not None:
        raise refused


def overfilled(
    smap: SemanticMap, plan: Plan, values: Mapping[str, Any], where: Mapping[str, tuple[float, float, float]]
) -> PlaceOverfilledError | None:
    """Why ``plan`` puts several objects on one place when no arrangement of their footprints on its spots
    holds them all (:func:`arrange`), with the objects of ``where`` (IRI: x, y, footprint radius) that it
    does not carry where they are, and by the arms of the robot that sets them down; None when each such
    place holds them, or when the search is undecided. A place that has no spot for one of them alone is
    left to the check of each step (``run_checks.PlanChecks._check_spot``), which says why."""
    by_place: dict[tuple[str, str], list[str]] = {}
    for down in puts_down(plan, smap, values):
        objects = by_place.setdefault((down.place, down.device), [])
        if down.obj not in objects:
            objects.append(down.obj)
    for (iri, device), objects in by_place.items():
        if len(objects) < 2:
            continue
        mounts = [(arm.mount[0], arm.mount[1], arm.reach) for arm in smap.arms.values() if arm.robot == device]
        place = smap.things[iri]
        rest = [(other, spot) for other, spot in where.items() if other not in objects]
        others = [spot for _, spot in rest]
        sizes = [smap.objects[obj].size for obj in objects]
        if not all(place_spots(smap, place, size, mounts, others)[1] for size in sizes):
            continue  # one alone has no spot: the step's own check says why
        try:
            if arrange(smap, place, sizes, mounts, others) is not None:
                continue
        except Undecided:
            log.info("room check: whether %s holds %s is undecided; the run goes on", iri, ", ".join(objects))
            continue
        surface = region_of(place, iri in smap.furniture)
        return PlaceOverfilledError(
            iri,
            [(obj, size) for obj, size in zip(objects, sizes, strict=True)],
            [(other, x, y, r) for other, (x, y, r) in rest if surface.contains_xy(x, y)],
            (surface.xmax - surface.xmin, surface.ymax - surface.ymin),
            reached_area(surface, mounts),
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
