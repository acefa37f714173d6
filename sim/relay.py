"""Passing an object between the arms, or setting it down to take it anew (a re-grasp).

When the arm that reaches an object cannot take it where it goes, it sets it down on a relay spot of
the surface it rests on where the other arm (or itself, by another approach) can take it; the spot is
chosen so that both holds' end poses pass the inverse kinematics and both holds' moves pass the arms'
planning, before anything moves.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterator, Sequence
from typing import TypeVar

from cbrs.sim import skills
from cbrs.sim.arms import CARRY_CLEARANCE, ArmSide
from cbrs.sim.context import SimContext, SkillFailed, check_outcome, robot_camera
from cbrs.sim.errors import GraspMisfitError, MovesRefusedError, SimulationError
from cbrs.sim.geometry import Region, Vec3
from cbrs.sim.grasping import ObjectModel, compute_grasp_pose
from cbrs.sim.hold_choice import Candidates, seen_extent
from cbrs.sim.perception import ObjectEstimate, recognise_object
from cbrs.sim.place_spots import (
    RELAY_CLEARANCE,
    RELAY_EDGE,
    RELAY_MARGIN,
    RELAY_STEP,
    distance_to_extent,
    fixtures_on,
    other_objects,
)
from cbrs.sim.transit import floor_to
from cbrs.sim.world import HomeWorld

RELAY_MOVES_TRIES = 3
"""How many spots whose end poses serve a pass or a re-grasp may have its holds' moves refused by the
arms' planning (a dry run, 0.1-0.8 s a spot), nearest the mounts first, before the pass looks farther
(RELAY_SPREAD)."""


RELAY_SPREAD = 0.15
"""Once RELAY_MOVES_TRIES spots are refused, the pass asks only spots at least this far from every spot
refused (up to RELAY_SPREAD_TRIES more refusals), then is refused with the first refusal. The spots 2 cm
apart nearest the mounts put the arms in nearly the same postures, refused for the same thing. Measured
with the 7 cm wine bottle passed from the right arm to the left (PutWineOnCupboard, seed 0), along the
table's front (y 3.07): the right arm's back-off runs into the Kinect's mast from x 7.73-7.79, its
straight line leaves its reach from 7.65-7.71, its carry is refused from 7.81-7.95; west of 7.63 and
east of 7.97 the spots serve. Nearest first, the first that serves was the 25th; after three refused
beside the torso, spread 9-20 cm apart it is the 5th; 3-7 cm apart none is within three more."""


RELAY_SPREAD_TRIES = 3
"""How many spots spread RELAY_SPREAD apart may be refused after the first RELAY_MOVES_TRIES."""


RELAY_TRIES = 40
"""How many spots, nearest the mounts first, are asked of the inverse kinematics (each asks take a few
milliseconds) before passing is given up."""


CLEAR_TRIES = 8
"""How many spots whose holds' moves serve but come within CARRY_CLEARANCE of an appliance (a tap's
lever) a pass, or an arm's choice of where it takes an object, passes over for the next before it takes
the first of them, as before the clearance was asked: each is a dry run of a take and a carry (50-100 ms)."""


S = TypeVar("S")

log = logging.getLogger("cbrs.sim")


def appliance_distance(world: HomeWorld) -> Callable[[tuple[float, float]], float]:
    """How far a point of the floor plan is from the nearest appliance a carry keeps CARRY_CLEARANCE from
    (each dispenser's body, tap's lever and spout, their extents as the map gives them); inf with none."""
    boxes = [
        (part.box.min_x, part.box.max_x, part.box.min_y, part.box.max_y)
        for dispenser in world.dispensers
        for part in (dispenser.body, dispenser.lever, dispenser.spout)
    ]
    return lambda point: min((distance_to_extent(box, point) for box in boxes), default=math.inf)


def clear_asked(
    spots: Sequence[S],
    near: Sequence[tuple[float, float]],
    at: Callable[[S], tuple[float, float]],
    away: Callable[[tuple[float, float]], float],
    since: int = 0,
) -> Iterator[S]:
    """Of ``spots`` (in the order a carry prefers them), the order they are asked in for a carry's clearance:
    the first RELAY_TRIES, as before, until a spot's dry run comes within CARRY_CLEARANCE of an appliance
    (``near``: where, which grows as they are asked); from then on first each spot, of all of them, farther
    from the appliances (``away``, :func:`appliance_distance`) than every spot in ``near`` (the first such
    in ``spots``' order), and when none is left, the rest of the first RELAY_TRIES in their order. The spots
    are ordered nearest the place's centre, 2 cm apart, and the carries to the neighbours of one that passes
    by an appliance pass by it too: the ninth round's table top, whose centre is behind the dispenser, had
    its first 40 spots in the arms' reach in front of it, each carry within 1 cm of the tap's lever, and
    BookOntoTheTable's carry to the first of them met the lever at seed 2. A spot nearer the appliance than
    one whose carry came near is the least likely to keep clear, and is asked last. ``at``: a spot's
    (x, y); ``since``: the index of the first spot to ask (those before it were asked already)."""
    asked = [index < since for index in range(len(spots))]
    while True:
        pick = None
        if near:
            bar = max(away(where) for where in near)
            pick = next((index for index, spot in enumerate(spots) if not asked[index] and away(at(spot)) > bar), None)
        if pick is None:
            pick = next((index for index in range(min(len(spots), RELAY_TRIES)) if not asked[index]), None)
        if pick is None:
            return
        asked[pick] = True
        yield spots[pick]


def relay_object(
    ctx: SimContext,
    device: str,
    estimate: ObjectEstimate,
    model: ObjectModel,
    giver: ArmSide,
    taker: ArmSide,
    spot: Region,
) -> ObjectEstimate:
    """Pass an object from the arm that reaches it to the other arm: the first puts it down on ``spot``,
    on the same surface, where both reach, and the object is found again there."""
    world = ctx.world
    spec, hand = world.arm_specs[giver], world.arm(giver).hand
    seen = seen_extent(estimate)
    grasp = compute_grasp_pose(
        model, estimate.position, estimate.yaw, spec.mount, spec.yaw, seen, hand, estimate.size[2]
    )
    ctx.last_arm = giver
    for move in (skills.approach_object, skills.pick_up_object):
        check_passing(move(world, giver, grasp), model, giver, taker)
    return set_down_for(ctx, device, model, giver, taker, spot, estimate.yaw)


def check_passing(outcome: skills.Outcome, model: ObjectModel, giver: ArmSide, taker: ArmSide) -> None:
    if not outcome.succeeded:
        what = (
            f"setting the {model.name} down for the {giver.value} arm to take it anew"
            if giver is taker
            else f"passing the {model.name} from the {giver.value} arm to the {taker.value}"
        )
        raise SkillFailed(f"{what}: {outcome.skill}: {outcome.reason}")


def set_down_for(
    ctx: SimContext, device: str, model: ObjectModel, giver: ArmSide, taker: ArmSide, spot: Region, yaw: float | None
) -> ObjectEstimate:
    """The giver, holding the object, sets it down on ``spot`` for the taker; where it is then (by the
    robot's camera near where the hand let it go, else where the hand let it go)."""
    world = ctx.world
    floor = floor_to(ctx, model, giver, world.arm(giver).ee_pose().position, spot)
    check_passing(skills.carry_object(world, giver, spot, floor=floor), model, giver, taker)
    check_passing(skills.put_down_object(world, giver, spot), model, giver, taker)
    released = world.arm(giver).released
    where = released[1] if released is not None else spot.center
    try:
        camera = robot_camera(ctx, device)
        check_outcome(skills.clear_view(world))
        return recognise_object(world.camera(camera).capture(), model.colour, near=(where[0], where[1]), radius=0.1)
    except (SkillFailed, SimulationError):
        size = world.objects[model.name].size
        return ObjectEstimate(where[0], where[1], where[2], yaw, size, model.colour, "hand", world.time, 0)


def relay_spot(
    ctx: SimContext,
    estimate: ObjectEstimate,
    giving: Candidates,
    taking: Candidates,
    giver: ArmSide,
    taker: ArmSide,
    moves: Callable[[Region, ObjectModel, ObjectModel], str | None] | None = None,
) -> tuple[Region, ObjectModel, ObjectModel]:
    """Where on the surface the object rests on both arms reach it, clear of the other objects and of
    the fixtures standing on it (a dispenser), and by which approach each hand holds it there: of the
    spots nearest both mounts, the first where the giver's hand can hold the object as it sets it down
    and the taker's hand can take it, each by the first of its candidate approaches that it can hold
    there (asked of the inverse kinematics: a side grasp close to the mount has none), and, given
    ``moves``, whose holds' moves the arms' planning would make (a dry run raising
    :class:`MovesRefusedError`): a spot so refused is passed over for the next, as a refused approach is
    for the next approach, up to RELAY_MOVES_TRIES of them, and then up to RELAY_SPREAD_TRIES more, each
    RELAY_SPREAD from every spot refused (:func:`_asked`); then the first refusal. ``moves`` returns where
    the holds' moves would come within CARRY_CLEARANCE of an appliance (``arm_choice.carry_check``; empty
    or None: they keep clear): such a spot is passed over for the next whose moves keep clear, up to
    CLEAR_TRIES of them; when none does, the first of them, as before, and the log says so."""
    smap, world = ctx.map, ctx.world
    model = giving.models[0]
    x, y, z = estimate.position
    surface = z - model.height / 2.0
    supports = [
        smap.things[iri]
        for iri in sorted(smap.furniture)
        if iri in smap.things
        and smap.things[iri].box.contains_xy(x, y)
        and abs(smap.things[iri].box.max_z - surface) <= 0.03
    ]
    if not supports:
        raise SkillFailed(f"the {model.name} rests on nothing the map knows: no surface to pass it on")
    top = supports[0].box
    size = world.objects[model.name].size
    radius = math.hypot(size[0], size[1]) / 2.0
    others = other_objects(world, ctx.belief, model.name)
    fixtures = fixtures_on(smap, supports[0], surface, 0.3)
    arms = [world.arm_specs[giver], world.arm_specs[taker]]
    spots: list[tuple[float, float, float, float]] = []
    inset = radius + RELAY_EDGE
    for i in range(int((top.max_x - top.min_x - 2 * inset) / RELAY_STEP) + 1):
        cx = top.min_x + inset + i * RELAY_STEP
        for j in range(int((top.max_y - top.min_y - 2 * inset) / RELAY_STEP) + 1):
            cy = top.min_y + inset + j * RELAY_STEP
            distances = [math.hypot(cx - a.mount[0], cy - a.mount[1]) for a in arms]
            if any(d > a.reach - RELAY_MARGIN for d, a in zip(distances, arms, strict=True)):
                continue
            if any(math.hypot(cx - ox_, cy - oy) < radius + r + RELAY_CLEARANCE for ox_, oy, r in others):
                continue
            if any(distance_to_extent(box, (cx, cy)) < radius + RELAY_CLEARANCE for box in fixtures):
                continue
            here = math.hypot(cx - x, cy - y)  # a re-grasp moves it as little as the approaches allow
            spots.append((here, max(distances), cx, cy) if giver is taker else (max(distances), here, cx, cy))

    def held_by(side: ArmSide, candidates: Candidates, centre: Vec3) -> ObjectModel | None:
        spec = world.arm_specs[side]
        for held in candidates.models:
            try:
                hand = compute_grasp_pose(
                    held, centre, estimate.yaw, spec.mount, spec.yaw, seen_extent(estimate), world.arm(side).hand
                )
            except GraspMisfitError:
                continue  # the hand cannot hold it so, wherever it is
            # the giver sets the object down and folds home before the taker's hand comes: asked with the
            # giver where it is now, holding the object over the spot, no spot had room for the taker's hand
            folded = (giver,) if side is taker and taker is not giver else ()
            arm = world.arm(side)
            if arm.can_hold(hand.position, hand.orientation, folded=folded) and arm.can_hold(
                hand.pregrasp, hand.orientation, folded=folded
            ):
                return held
        return None

    refused: list[MovesRefusedError] = []
    refused_at: list[tuple[float, float]] = []  # where the holds' moves were refused
    near: list[tuple[Region, ObjectModel, ObjectModel, str]] = []  # served, not keeping clear
    for cx, cy in _asked([(cx, cy) for *_, cx, cy in sorted(spots)], refused_at):
        centre = (cx, cy, surface + model.height / 2.0)
        given = held_by(giver, giving, centre)
        taken = held_by(taker, taking, centre) if given is not None else None
        if given is not None and taken is not None:
            half = RELAY_STEP * 2
            region = Region(
                f"{supports[0].name}Relay", cx - half, cx + half, cy - half, cy + half, top.max_z, top.max_z + 0.3
            )
            try:
                brushed = moves(region, given, taken) if moves is not None else None
            except MovesRefusedError as why:
                refused.append(why)
                refused_at.append((cx, cy))
                if len(refused) >= RELAY_MOVES_TRIES + RELAY_SPREAD_TRIES or (
                    len(refused) >= RELAY_MOVES_TRIES and near
                ):
                    break
                continue
            if not brushed:
                return region, given, taken
            near.append((region, given, taken, brushed))
            if len(near) >= CLEAR_TRIES:
                break
    if near:
        region, given, taken, brushed = near[0]
        cx, cy, _ = region.center
        log.info(
            "passing the %s: the holds at none of the %d relay spots asked keep %.0f cm clear of the appliances; "
            "it is set down at (%.2f, %.2f), the first whose holds serve, as before: %s",
            model.name,
            len(near),
            CARRY_CLEARANCE * 100,
            cx,
            cy,
            brushed,
        )
        return region, given, taken
    if refused:
        raise refused[0]
    if giver is taker:
        down = " or ".join(held.grasp.value for held in giving.models)
        anew = " or ".join(held.grasp.value for held in taking.models)
        raise SkillFailed(
            f"there is no spot on {supports[0].name} where the {giver.value} arm can set the {model.name} down by "
            f"its {down} grasp and take it anew by its {anew} grasp"
        )
    kinds = " or ".join(dict.fromkeys(held.grasp.value for held in [*giving.models, *taking.models]))
    raise SkillFailed(
        f"there is no spot on {supports[0].name} where both the {giver.value} and the {taker.value} arm can hold "
        f"the {model.name} by its {kinds} grasp, to pass it from one to the other"
    )


def _asked(spots: list[tuple[float, float]], refused_at: list[tuple[float, float]]) -> Iterator[tuple[float, float]]:
    """Of ``spots`` (nearest the mounts first), the ones a pass asks in turn: the first RELAY_TRIES, until
    RELAY_MOVES_TRIES of them have been refused (``refused_at``, which grows as they are asked); from
    then on, of the rest, those at least RELAY_SPREAD from every spot refused."""
    for index, spot in enumerate(spots):
        if len(refused_at) >= RELAY_MOVES_TRIES:
            yield from (
                other for other in spots[index:] if all(math.dist(other, at) >= RELAY_SPREAD for at in refused_at)
            )
            return
        if index >= RELAY_TRIES:
            return
        yield spot


def resting_at(spot: Region, model: ObjectModel, seen: ObjectEstimate, now: float) -> ObjectEstimate:
    """Where an object set down on ``spot`` is expected to be, lying as it was ``seen``: what a dry run of
    taking it from there asks about before it is there."""
    cx, cy, _ = spot.center
    return ObjectEstimate(cx, cy, spot.zmin + model.height / 2.0, seen.yaw, seen.size, model.colour, "map", now, 0)
