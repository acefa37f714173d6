"""Which arm takes an object, which loads it onto the platform, and by which approach.

Of the free arms that reach the object, nearest first, the first that can take it and also let it go
where its hold ends (a later carry's place) takes it; else the first that can take it, to pass it on.
Loading the platform is asked the same way: one arm that reaches both, else a re-grasp, else a pass
from an arm that reaches the object to one that reaches the platform. Each is asked without moving
(inverse kinematics and dry runs of the arms' planning), by the skill and by the check before a run.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import logging
import math
from collections.abc import Callable, Collection, Iterator, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from cbrs.actions.plan import PlanStep
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapObject, Thing, local_name
from cbrs.sim import skills
from cbrs.sim.arms import CARRY_CLEARANCE, ArmSide
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.errors import GraspMisfitError, MovesRefusedError, SimulationError
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.grasping import GraspKind, GraspPose, ObjectModel, compute_grasp_pose
from cbrs.sim.hold_choice import Candidates, GraspChoice, first_clear, refuse_moves, seen_extent
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.place_spots import RELAY_MARGIN, spot_region
from cbrs.sim.relay import CLEAR_TRIES, RELAY_TRIES, appliance_distance, clear_asked, relay_spot, resting_at
from cbrs.sim.transit import band_advice, floor_cause, floor_needs, floor_to, transit_floor
from cbrs.sim.values import Manipulation
from cbrs.sim.world import HomeWorld

ACT = PREFIXES["act"]

log = logging.getLogger("cbrs.sim")

TAKING = frozenset({ACT + "ApproachToObject", ACT + "HandingOverOntoPlatform"})
"""The actions with which an arm takes an object: a hold starts."""


ARM_TIE = 0.01
"""Two arms whose mounts are within 1 cm as far from a target reach it equally well."""


def reaching(ctx: SimContext, x: float, y: float) -> list[ArmSide]:
    """The free arms whose mounts are within their reach of (x, y), best first: the nearest, and on a
    tie not the one that just acted."""
    options = []
    for side, spec in ctx.world.arm_specs.items():
        distance = math.hypot(x - spec.mount[0], y - spec.mount[1])
        if ctx.world.arm(side).held is None and distance <= spec.reach:
            options.append((distance, side))
    if not options:
        return []
    best = min(distance for distance, _ in options)
    tied = sorted(side for distance, side in options if distance - best <= ARM_TIE)
    fresh = [side for side in tied if side != ctx.last_arm]
    first = (fresh or tied)[0]
    return [first, *(side for _, side in sorted(options) if side != first)]


def free_arm(ctx: SimContext, x: float, y: float, what: str) -> ArmSide:
    """The free arm whose mount is nearest (x, y) and within its reach; on a tie, not the one that just acted."""
    arms = reaching(ctx, x, y)
    if not arms:
        raise SkillFailed(f"no free arm reaches {what} at ({x:.2f}, {y:.2f}){why_none(ctx, x, y)}")
    return arms[0]


def why_none(ctx: SimContext, x: float, y: float) -> str:
    """Why no free arm reaches (x, y), to follow a refusal: each arm's reach from its mount and how far away
    the point is, or what it holds; and, for a robot of one arm, that there is no other to pass a thing to
    (docs/simulation.md, "A robot with one arm")."""
    world = ctx.world
    if not world.arm_specs:
        return ": the robot has no arm (home:hasArm)"
    said = []
    for side, spec in world.arm_specs.items():
        distance = math.hypot(x - spec.mount[0], y - spec.mount[1])
        held = world.arm(side).held
        what = (
            f"holds the {world.name_of(held)}"
            if held is not None and distance <= spec.reach
            else f"reaches {spec.reach:.2f} m from ({spec.mount[0]:.2f}, {spec.mount[1]:.2f}), {distance:.2f} m away"
        )
        said.append(f"the {side.value} arm ({local_name(spec.iri)}) {what}")
    alone = "; it is the robot's one arm, and there is no other to pass a thing to" if len(said) == 1 else ""
    return f" ({', '.join(said)}{alone})"


def grasp_pose_for(ctx: SimContext, estimate: ObjectEstimate, side: ArmSide, held: ObjectModel) -> GraspPose:
    spec = ctx.world.arm_specs[side]
    hand = ctx.world.arm(side).hand
    seen = seen_extent(estimate)
    return compute_grasp_pose(held, estimate.position, estimate.yaw, spec.mount, spec.yaw, seen, hand, estimate.size[2])


TURN = math.pi / 2.0
"""How far a top grasp of a round object turns the fingers' closing when the usual way would touch a fixture
(:func:`turned`): along the way they closed, not across it, the other way the hand can close on it."""


def turned(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel, side: ArmSide) -> ObjectModel:
    """``model``, or, for a round object (no footprint: as wide whichever way) that ``side`` may take by a top
    grasp, the same turned TURN round (:attr:`ObjectModel.turn`) when the take's moves by that grasp as
    :func:`compute_grasp_pose` turns the hand would touch a fixture the arms' planning does not avoid (a tap's
    lever: :attr:`skills.DryRun.met`) and the turned take's the planning would make touching none. The flask
    2 cm south of the lever, taken with the fingers closing north-south, touched it with one; closing
    east-west, they pass it. The take's dry runs are asked only where the hand, its grasp point between
    the pre-grasp and the grasp pose, could come near a fixture by the map (:meth:`Arm.fixture_near`): a
    take meeting none is chosen as before, at no cost. The choice carries the turn to the moves."""
    if model.footprint is not None or model.turn or GraspKind.TOP not in model.preference:
        return model
    top = model.by(GraspKind.TOP)
    try:
        grasp = grasp_pose_for(ctx, estimate, side, top)
    except SimulationError:
        return model
    world = ctx.world
    if not world.arm(side).fixture_near(grasp.pregrasp, grasp.position):
        return model
    plain = skills.plan_carry(world, estimate, side, top)
    if not plain.met:
        return model
    other = dataclasses.replace(top, turn=TURN)
    again = skills.plan_carry(world, estimate, side, other)
    if again.refused:
        log.info("the %s, %s: turned, %s", model.name, plain.met, again.refused)
        return model
    log.info("the %s taken by its top grasp turned a quarter round: %s", model.name, plain.refused)
    return dataclasses.replace(model, turn=TURN)


def who_takes(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel) -> GraspChoice:
    """Which arm takes the object where it is, and by which approach: of the free arms that reach it,
    nearest first (:func:`reaching`), the first that can (:func:`taking_to`: its inverse kinematics and
    its planning's dry run of the moves) and can also let it go where the hold ends; else the first that
    can take it, to pass it on there. The nearest arm is not the only one asked: where its hand cannot
    get to the object (its joints' range, the dispenser in the way) or cannot set it down where it goes,
    the other arm may; nor where its carry there would not keep CARRY_CLEARANCE from the appliances
    (:func:`carry_clear`) and the other arm's would (else the first arm that can, as before). When none can,
    the nearest arm's refusal, as it is when it is the only one asked or every arm's is a misfit (a
    typed error: the object does not fit the hand so), else a SkillFailed starting with it and saying
    why each other arm could not either."""
    x, y, _ = estimate.position
    arms = reaching(ctx, x, y)
    if not arms:
        raise SkillFailed(f"no free arm reaches the {model.name} at ({x:.2f}, {y:.2f}){why_none(ctx, x, y)}")
    fits = _fitting(ctx, model, arms) if len(model.preference) > 1 else ""  # one approach: its typed misfit
    if fits:
        raise SkillFailed(fits)
    refused: list[tuple[ArmSide, Exception]] = []
    passing_on: GraspChoice | None = None  # the first arm that can take it but not let it go where it goes
    unclear: _Taking | None = None  # the first that can, its carry not keeping clear
    for side in arms:
        try:
            if len(model.preference) == 1:  # its one approach's misfit is its own typed error (GraspTooDeepError...)
                grasp_pose_for(ctx, estimate, side, model)
            taken = _taking_to(ctx, estimate, model, side)  # one approach too: its moves are dry-run
        except (SkillFailed, SimulationError) as why:
            refused.append((side, why))
            continue
        if taken.served and not taken.unclear:
            return taken.choice
        if taken.served:
            unclear = unclear or taken
        else:
            passing_on = passing_on or taken.choice
    if unclear is not None:
        log.info("%s, though its carry keeps no spot's clearance, as before: %s", unclear.choice, unclear.unclear)
        return unclear.choice
    if passing_on is not None:
        return passing_on  # the carry passes it to the arm that reaches where it goes
    first = refused[0][1]
    if len(refused) == 1 or all(isinstance(why, GraspMisfitError) for _, why in refused):
        raise first
    others = "; ".join(f"nor could the {side.value} arm take it: {why}" for side, why in refused[1:])
    raise SkillFailed(f"{first}; {others}")


class CannotCarryError(KnowledgeBaseError):
    """A step would take an object the task gives to carry it to a place, and the step's own choice of arm and
    approach (:func:`who_takes`, asked before the run where the object is believed to be) refuses every way
    because the object held would meet an appliance on it (:func:`check_take`): the run is refused before
    anything moves, not after a re-plan. ``reason`` is the choice's refusal, its advice included."""

    http_status = 422

    def __init__(self, component: str, thing: str, reason: str) -> None:
        self.component = component
        self.thing = thing
        self.reason = reason
        super().__init__(f"{local_name(component)} cannot take the {local_name(thing)} where it goes: {reason}")


def check_take(ctx: SimContext, step: PlanStep, thing: str, estimate: ObjectEstimate, model: ObjectModel) -> None:
    """Refuse, before the run, ``step`` (an arm taking the object ``thing`` where ``estimate`` says it lies, by
    ``model``'s approaches) when the way of its hold to the place a later carry of the plan is given
    (:func:`hold_end`) would bring the object held within COLLISION_MARGIN of an appliance
    (:func:`skills.held_meeting`) for some arm and approach, and the step's own choice then refuses it
    (:func:`who_takes`: :class:`CannotCarryError` with its words). The first question is the map's alone
    (the hands' bands, where things are, the appliances; no planning), so a plan whose carry meets no
    appliance costs no dry run here; the second is the step's decision, dry runs of the arms' planning as the
    step will make them, which tells an approach the hand cannot let go by over the place (inverse
    kinematics) from one it can. Before, the refusal came at the step, after the steps before it had run, and
    the run failed after one re-plan that could change nothing."""
    saved = ctx.step, ctx.component, ctx.known
    ctx.step, ctx.component, ctx.known = step, step.component, {}
    try:
        if not _meets_appliance(ctx, estimate, model):
            return
        try:
            who_takes(ctx, estimate, model)
        except (SkillFailed, MovesRefusedError) as refused:
            raise CannotCarryError(step.component, thing, str(refused)) from None
    finally:
        ctx.step, ctx.component, ctx.known = saved


def _meets_appliance(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel) -> bool:
    """Whether, for some free arm that reaches the object, approach its hand can grip it by and spot of the
    hold's end the arm reaches (the first RELAY_TRIES, as the approach choice asks them), the object held
    would meet an appliance on the carry's way, at the floor the carry keeps (:func:`floor_to`), lifted as
    the pick-up leaves it: the map's answer, without the arms' planning."""
    x, y, _ = estimate.position
    fixtures = skills.appliances(ctx.world)
    if not fixtures:
        return False
    for side in reaching(ctx, x, y):
        end = hold_end(ctx, model.name, side)
        if end is None:
            continue
        _, surface, spots = end
        for kind in model.preference:
            held = model.by(kind)
            try:
                grasp = grasp_pose_for(ctx, estimate, side, held)
            except SimulationError:
                continue
            for at in spots[:RELAY_TRIES]:
                if _held_meets_at(ctx, side, grasp, spot_region(surface, *at), fixtures):
                    return True
    return False


def _held_meets_at(ctx: SimContext, side: ArmSide, grasp: GraspPose, spot: Region, fixtures: Sequence[Region]) -> bool:
    """Whether the object held by ``grasp``, lifted as the pick-up leaves it and carried over ``spot`` at the
    floor the carry keeps (:func:`floor_to`), would meet one of ``fixtures`` (:func:`skills.held_meeting`):
    the map's answer to what the carry's dry run refuses first (:func:`skills.plan_carry`), without it."""
    gx, gy, gz = grasp.position
    start = (gx, gy, gz + skills.LIFT_HEIGHT)
    cx, cy, _ = spot.center
    above = spot.zmin + skills.ABOVE_CLEARANCE
    floor = floor_to(ctx, grasp.model, side, start, spot)
    bottom = max(start[2] - grasp.bottom_offset, above, -math.inf if floor is None else floor)
    return skills.held_meeting(fixtures, grasp, start, (cx, cy, above + grasp.bottom_offset), bottom) is not None


def _fitting(ctx: SimContext, model: ObjectModel, sides: Sequence[ArmSide]) -> str:
    """Why the hand of none of ``sides`` can close on the object by any of its approaches, wherever it is
    (:func:`skills.can_grip`: wider than the jaws open, a top grasp deeper than the palm allows); empty
    when one can. Said once, not once for each arm and each way of passing it between them."""
    why = ""
    for side in sides:
        gripping = Candidates.of(model, functools.partial(skills.can_grip, hand=ctx.world.arm(side).hand))
        if gripping.models:
            return ""
        why = why or gripping.refusal()
    return why


def taking(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel, side: ArmSide) -> GraspChoice:
    """The approach ``side`` takes the object by (:func:`taking_to`)."""
    return taking_to(ctx, estimate, model, side)[0]


class _Taking(NamedTuple):
    """How an arm takes an object (:func:`taking_to`): by which approach, whether it can let it go where the
    hold ends, and why no spot's take and carry there keeps CARRY_CLEARANCE (empty: one does, or nothing
    is known of where it goes)."""

    choice: GraspChoice
    served: bool
    unclear: str = ""


def taking_to(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel, side: ArmSide) -> tuple[GraspChoice, bool]:
    """The approach ``side`` takes the object by, and whether it can also let it go where the hold ends
    (True too where that is not known here), of several: the first it can take it by where it is and
    let it go by where the hold ends, when that is known here (:func:`hold_end`: a later carry of the
    plan to a place the task gives), else the first it can take it by. Letting go is asked as the carry
    will (:func:`holdable_spot`): over the spots of the place this arm reaches, nearest the centre first,
    the first whose take and carry keep CARRY_CLEARANCE from the appliances (:func:`carry_clear`, up to
    CLEAR_TRIES spots an approach), by the first approach that has one; when none has, the first spot the
    hand can let it go over, as before. An
    arm that can let it go there by no approach takes it by the first it can, as where it is not known:
    the carry passes it to the other arm. Of the approaches that pass those checks (the inverse
    kinematics' of the end poses), the first whose moves the arm's planning would make (:func:`first_clear`)
    is taken; when none would, :class:`MovesRefusedError` before anything moves."""
    taken = _taking_to(ctx, estimate, model, side)
    return taken.choice, taken.served


def _taking_to(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel, side: ArmSide) -> _Taking:
    world, name = ctx.world, model.name
    model = turned(ctx, estimate, model, side)

    def take(held: ObjectModel) -> str:
        return skills.can_take(world, estimate, side, held)

    taking = Candidates.of(model, take)
    if not taking.models:
        raise SkillFailed(taking.refusal())
    end = hold_end(ctx, name, side)
    if end is None:
        moves = functools.partial(skills.can_carry, world, estimate, side)
        return _Taking(first_clear(taking, side, f"taking the {name}", moves), True)
    place, surface, spots = end
    first: dict[GraspKind, Region] = {}  # the spot the carry will aim at, by each approach that lets go there
    after: dict[GraspKind, int] = {}  # the index in ``spots`` of the next spot to ask for its clearance

    def letting_go(held: ObjectModel) -> str:
        tried = spots[:RELAY_TRIES]
        for index, at in enumerate(tried):
            spot = spot_region(surface, *at)
            if not skills.can_set_down(world, estimate, side, held, spot):
                first[held.grasp], after[held.grasp] = spot, index + 1
                return ""
        spots_of = "the one spot" if len(tried) == 1 else f"any of the {len(tried)} spots"
        where = f"{spots_of} of {place.name} it reaches" if tried else f"{place.name} (no spot in reach)"
        return f"the {side.value} arm cannot hold the {name} by its {held.grasp.value} grasp over {where}"

    both = Candidates.of(model, take, letting_go)
    if both.models:
        purpose = f"taking the {name} to {place.name}"
        passed = list(both.ruled_out)
        refusals: dict[GraspKind, str] = {}  # of the carry to the first spot, when its clearance was asked
        for held in both.models:

            def others(
                since: int, near: Sequence[tuple[float, float]], held: ObjectModel = held
            ) -> Iterator[Region]:  # the next it can let go over and carry to without the object held meeting
                # an appliance, by the map (no dry run spent); farther from the appliances than any that came near first
                away = appliance_distance(world)
                regions = (spot_region(surface, *at) for at in clear_asked(spots, near, lambda at: at, away, since))
                fixtures = skills.appliances(world)
                try:
                    grasp = grasp_pose_for(ctx, estimate, side, held) if fixtures else None
                except SimulationError:
                    grasp = None
                return (
                    spot
                    for spot in regions
                    if not skills.can_set_down(world, estimate, side, held, spot)
                    and (grasp is None or not _held_meets_at(ctx, side, grasp, spot, fixtures))
                )

            found = _clear_spot(
                ctx, side, first[held.grasp], functools.partial(others, after[held.grasp]), (estimate, held)
            )
            first[held.grasp] = found.spot
            if not (found.refused or found.unclear):
                return _Taking(Candidates([held], passed).choice(side, held, purpose), True)
            refusals[held.grasp] = found.refused
            passed.append((held.grasp, found.unclear or found.refused))
        try:
            served = first_clear(both, side, purpose, lambda held: refusals[held.grasp], first)
        except MovesRefusedError as moves:
            advice = [floor_advice(ctx, side, first[held.grasp], estimate, held) for held in both.models]
            if not all(advice):  # an approach refused for another reason: the advice that fits every one
                raise
            said = "; ".join(dict.fromkeys(advice))
            raise MovesRefusedError(
                moves.name, moves.arm, moves.purpose, moves.refused, moves.ruled_out, advice=said
            ) from None
        unclear = "; ".join(why for _, why in passed[len(both.ruled_out) :])
        return _Taking(served, True, unclear)
    unplaced = "; ".join(why for _, why in both.ruled_out)
    passed_on = first_clear(  # to be passed on: the take's moves are dry-run, as where the hold's end is not known
        taking,
        side,
        f"taking the {name} (to {place.name}, to be passed on: {unplaced})",
        lambda held: skills.can_carry(world, estimate, side, held),
    )
    return _Taking(passed_on, False)


def hold_end(
    ctx: SimContext, name: str, side: ArmSide | None = None
) -> tuple[Thing, Region, list[tuple[float, float]]] | None:
    """Where the hold the running component starts ends, when the plan says: the place the first carry
    after the running step is given, before any other step of its robot takes an object; and that
    place's surface and spots for the arm ``side`` (else ``ctx.arm``) in the order the carry will aim at
    them (:func:`packing.carry_spots`: first those that leave room for what the plan puts there after it;
    before, :func:`place_spots`' order, whose first spot the carry need not take).
    The running step is the one the executor said it starts (``SimEnvironment.starting``), else the
    plan's one step of this component; the carry's place is what the executor knows of its inputs then
    (the task's value, or an earlier step's output), else the task's value. None when it is not known
    here (the place is a later step's output, or no carry follows)."""
    plan, iri, smap = ctx.plan, ctx.component, ctx.map
    if plan is None or iri is None:
        return None
    if ctx.step is not None and iri in ctx.step.candidates:
        mine = [position for position, step in enumerate(plan.steps) if step.index == ctx.step.index]
    else:
        mine = [position for position, step in enumerate(plan.steps) if iri in step.candidates]
    if len(mine) != 1:
        return None
    device = plan.steps[mine[0]].device
    for step in plan.steps[mine[0] + 1 :]:
        if step.device != device:
            continue
        if step.action in TAKING:
            return None  # another hold starts first
        if step.action != ACT + "CarryingWhileLocomoting":
            continue
        if step.index in ctx.known:
            values = list(ctx.known[step.index].values())
        else:
            values = [ctx.given.get(b.source.name) for b in step.inputs if b.source.step is None]
        iris = [str(value["@id"]) for value in values if isinstance(value, dict) and "@id" in value]
        places = [iri for iri in iris if iri in smap.regions or iri in smap.furniture]
        if len(places) != 1:
            return None
        from cbrs.sim.packing import carry_spots  # packing asks this module whether an arm holds a spot

        place = smap.things[places[0]]
        surface, spots = carry_spots(ctx, place, name, side or ctx.arm, step)
        return place, surface, spots
    return None


def lying_estimate(world: HomeWorld, belief: PerceivedWorld | None, obj: MapObject) -> ObjectEstimate:
    """Where the checks of a plan take an object to be: where it is believed to be, else where the map puts
    it on its support, lying as the map says (as perception gives it: the yaw of its long axis)."""
    believed = belief.position(obj.name) if belief is not None else None
    support = world.map.things.get(obj.support or "")
    top = support.box.max_z if support is not None else 0.0
    centre = believed or (obj.start.x, obj.start.y, top + obj.size[2] / 2)
    axis = obj.start.yaw + (math.pi / 2.0 if obj.size[1] > obj.size[0] else 0.0)
    return ObjectEstimate(centre[0], centre[1], centre[2], axis, obj.size, obj.colour, "map", 0.0, 0)


def cannot_set_down(
    ctx: SimContext,
    obj: MapObject,
    surface: Region,
    at: tuple[float, float],
    sides: Collection[ArmSide] | None = None,
) -> str:
    """Why no arm of the robot (of ``sides``: those free when it is set down) whose reach the spot ``at`` of
    ``surface`` is RELAY_MARGIN inside can hold ``obj`` over it to set it down, by any approach its hand can
    grip it by (empty: one can): what a carry asks of a spot before it aims there (:func:`skills.can_set_down`,
    its hand turned as it takes the object where it lies, believed or as the map says; the pass's taker asks
    the same with :func:`skills.can_grip`), and, where the hand there could come near a fixture by the map,
    whether some posture holds it there and backed off from there CARRY_CLEARANCE from the fixtures
    (:func:`skills.set_down_meets`): under a tap's spout the end poses' inverse kinematics let through spots
    the arm's planning has no way to. Asked of each spot a packing would give a later thing
    (:func:`packing.carry_spots`)."""
    world = ctx.world
    estimate, model = lying_estimate(world, ctx.belief, obj), Manipulation.of(obj).model
    spot = spot_region(surface, *at)
    refused: list[str] = []
    for side, spec in sorted(world.arm_specs.items()):
        if sides is not None and side not in sides:
            continue
        if math.hypot(at[0] - spec.mount[0], at[1] - spec.mount[1]) > spec.reach - RELAY_MARGIN:
            continue
        for kind in model.preference:
            held = model.by(kind)
            why = (
                skills.can_grip(held, world.arm(side).hand)
                or skills.can_set_down(world, estimate, side, held, spot)
                or skills.set_down_meets(world, estimate, side, held, spot)
            )
            if not why:
                return ""
            refused.append(why)
    if refused:
        return refused[0]
    free = "free " if sides is not None and len(sides) < len(world.arm_specs) else ""  # the others hold something
    return f"no {free}arm reaches ({at[0]:.2f}, {at[1]:.2f}) {RELAY_MARGIN:.2f} m inside its reach"


def let_go_held(
    ctx: SimContext, side: ArmSide, name: str, surface: Region, at: tuple[float, float], planned: bool = True
) -> bool | None:
    """Whether the arm ``side``, holding the object ``name`` now, can set it down at the spot ``at`` of
    ``surface``: its hand there turned as now (what :func:`holdable_spot` asks), and, with ``planned``, the
    carry there one the arm's planning would make, though it may come near an appliance (what
    :func:`holdable_spot` takes when no carry keeps clear). None when the arm does not hold it (then
    :func:`cannot_set_down` asks as it would take it where it lies). Asked of the spots a carry's packing
    takes as leaving room for what comes after (:func:`packing.carry_spots`)."""
    arm = ctx.world.arm(side)
    if arm.held is None or arm.held_grasp is None or ctx.world.name_of(arm.held) != name:
        return None
    grasp = arm.held_grasp
    at_z = surface.zmin + skills.PLACE_CLEARANCE + grasp.bottom_offset
    if not arm.can_hold((at[0], at[1], at_z), arm.ee_pose().orientation):
        return False
    if not planned:
        return True
    why, brushed = carry_check(ctx, side, spot_region(surface, *at))
    return why == brushed  # refused only for coming near, or not at all


def holdable_spot(
    ctx: SimContext, side: ArmSide, surface: Region, spots: Sequence[tuple[float, float]]
) -> tuple[float, float] | None:
    """Of ``spots`` (the first RELAY_TRIES) where the arm's hand, as it holds the object now, can let it go
    on the surface (asked of the inverse kinematics), the first whose carry keeps clear of the appliances
    (:func:`carry_clear`), else the first whose carry the arm's planning would make, though coming near
    (a carry the held object's check refuses, :func:`skills.held_meets`, is not taken while another is
    not), else the first; the first spot if it holds nothing. Before, the first spot the hand could hold
    was taken, and a jar carried at the height it was lifted off a rack to the table's spot beside the
    dispenser met the tap's lever and the spout and stopped 1.5-2 cm short."""
    arm = ctx.world.arm(side)
    grasp = arm.held_grasp
    if grasp is None:
        return spots[0] if spots else None
    orientation = arm.ee_pose().orientation
    first: tuple[float, float] | None = None
    unrefused: list[tuple[float, float]] = []  # those whose carry the planning makes, though near
    near: list[tuple[float, float]] = []  # where the carry came near an appliance: farther spots asked next
    for x, y in clear_asked(spots, near, lambda at: at, appliance_distance(ctx.world)):
        if arm.can_hold((x, y, surface.zmin + skills.PLACE_CLEARANCE + grasp.bottom_offset), orientation):
            why, brushed = carry_check(ctx, side, spot_region(surface, x, y))
            if not why:
                return (x, y)
            if brushed:
                near.append((x, y))
            if why == brushed:  # only near, not refused (a held carry's check gives near as refused too)
                unrefused.append((x, y))
            first = first or (x, y)
    # no straight carry keeps clear: the first whose carry keeps clear going round the fixture it came near
    # (skills.carry_object's ``around``, as the run's carry goes), up to CLEAR_TRIES of them
    for x, y in unrefused[:CLEAR_TRIES]:
        if not carry_check(ctx, side, spot_region(surface, x, y), around=True)[0]:
            return (x, y)
    # none does (a cup carried below the tap, which it aims at): the first the planning makes, else the
    # first, as before
    return unrefused[0] if unrefused else first


def carry_clear(
    ctx: SimContext, side: ArmSide, spot: Region, taking: tuple[ObjectEstimate, ObjectModel] | None = None
) -> str:
    """Why the carry of what ``side`` holds over ``spot`` and its way down would not keep CARRY_CLEARANCE
    from the appliances standing on the furniture, the taps' levers too (empty: it would), or would be
    refused by the arm's planning (:func:`carry_check`). The arms' planning does not avoid a lever, which
    a hand pushes to fill a cup, nor a fixed thing a hand comes less than STRIKE_DEPTH into; a carry
    means to touch neither."""
    refused, brushed = carry_check(ctx, side, spot, taking)
    return refused or brushed


def carry_check(
    ctx: SimContext,
    side: ArmSide,
    spot: Region,
    taking: tuple[ObjectEstimate, ObjectModel] | None = None,
    folded: Sequence[ArmSide] = (),
    around: bool = False,
) -> tuple[str, str]:
    """Why the arm's planning would refuse the carry over ``spot`` and its way down, and where those moves
    would come within CARRY_CLEARANCE of an appliance (each empty when not): a dry run with that clearance
    of the carry of what ``side`` holds, from its posture now (:func:`skills.plan_carry_held`), or, given
    ``taking`` (an object where it lies, the approach), of its take and carry from where it lies
    (:func:`skills.plan_carry`, the arms of ``folded`` home); the floor as the carry's (:func:`floor_to`).
    Told apart, so a choice can pass over the spot that does not keep clear and still take it, as before,
    when none does; but a held carry that comes that near is given as refused too, saying where: a pass's
    giver passes such a spot over (``services.carry``), and takes none of them when none keeps clear. With
    ``around``, the carry goes round a fixture its straight way comes near, where a way round keeps clear
    (:func:`way_round`), as the run's carry does."""
    world = ctx.world
    if taking is None:
        grasp = world.arm(side).held_grasp
        if grasp is None:
            return f"the {side.value} gripper holds nothing", ""
        held, start = grasp.model, world.arm(side).ee_pose().position
        bottom = start[2] - grasp.bottom_offset
        floor = floor_to(ctx, held, side, start, spot)
        rounding = way_round(ctx, side, held) if around else None
        planned = skills.plan_carry_held(world, side, spot, floor, CARRY_CLEARANCE, rounding)
    else:
        seen, held = taking
        start = seen.position
        bottom = seen.position[2] - seen.size[2] / 2.0 + skills.LIFT_HEIGHT  # lifted, as the take's dry run
        floor = floor_to(ctx, held, side, start, spot)
        planned = skills.plan_carry(
            world,
            seen,
            side,
            held,
            spot,
            floor=floor,
            folded=folded,
            clearance=CARRY_CLEARANCE,
            around=way_round(ctx, side, held) if around else None,
        )
    cx, cy, _ = spot.center
    refused = planned.refused
    if refused and floor is not None and floor >= max(bottom, spot.zmin + skills.ABOVE_CLEARANCE):
        # the floor sets how high the carry goes: say what it keeps over, as the store states it
        cause = floor_cause(ctx, held, side, (start[0], start[1]), (cx, cy))
        refused += f"; the carry keeps the {held.name}'s bottom at {floor:.3f} m or higher: {cause}"
    near = planned.brushed
    brushed = near and f"the {side.value} arm carrying the {held.name} to ({cx:.2f}, {cy:.2f}): {near}"
    if taking is None:  # a held carry that comes that near is refused too
        return refused or brushed, brushed
    return refused, brushed


def way_round(ctx: SimContext, side: ArmSide, held: ObjectModel) -> skills.Round:
    """What ``side``'s carry of ``held`` needs to go round a fixture (:class:`skills.Round`): the arm's mount,
    and the floor over the things standing by a way (:func:`transit_floor`, where each is believed to be)."""
    mount = ctx.world.arm_specs[side].mount
    return skills.Round((mount[0], mount[1]), lambda a, b: transit_floor(ctx, held, side, a, b))


def floor_advice(ctx: SimContext, side: ArmSide, spot: Region, seen: ObjectEstimate, held: ObjectModel) -> str:
    """What would let ``side`` take the object where it lies (``seen``) by ``held``'s approach and carry it
    over ``spot`` when the floor the carry keeps over the things by its way (:func:`floor_needs`) is what
    holds it up into an appliance (:func:`skills.held_meeting`); empty otherwise. From the refusal's own
    values: how low the object's bottom must stay to pass the appliance, what asks it higher (each thing by
    the way, and the arm's band kept over it, as the store states it), what of the band would do
    (:func:`band_advice`), the thing moved off the way, another approach. The generic "set it nearer the
    arm" fitted none of that: a lab's forearm band 6 cm below the grasp point, over a second cup, held the
    cup it carried up against the tap's spout."""
    world = ctx.world
    try:
        grasp = grasp_pose_for(ctx, seen, side, held)
    except SimulationError:
        return ""
    x, y, z = grasp.position
    start = (x, y, z + skills.LIFT_HEIGHT)  # lifted, as pick_up_object leaves it
    cx, cy, _ = spot.center
    above = spot.zmin + skills.ABOVE_CLEARANCE
    end = (cx, cy, above + grasp.bottom_offset)
    unfloored = max(start[2] - grasp.bottom_offset, above)
    needs = floor_needs(ctx, held, side, (x, y), (cx, cy))
    floor = max((need.height for need in needs), default=-math.inf)
    fixtures = skills.appliances(world)
    met = skills.held_meeting(fixtures, grasp, start, end, floor)
    if floor <= unfloored or met is None or skills.held_meeting(fixtures, grasp, start, end, unfloored) is not None:
        return ""  # the floor does not hold it up, it meets nothing there, or it would meet one without the floor
    low, high = unfloored, floor  # passes at ``low``, meets at ``high``: the highest bottom that passes, to 1 mm
    while high - low > 0.001:
        middle = (low + high) / 2.0
        low, high = (low, middle) if skills.held_meeting(fixtures, grasp, start, end, middle) else (middle, high)
    things: list[str] = []
    said: list[str] = []
    bands: list[str] = []
    for need in sorted(needs, key=lambda need: -need.height):
        if need.height <= low:
            break
        things.append(need.thing)
        band, what = need.band, need.why
        if band is not None:  # said in full in the refusal before
            what = f"the arm's band {band.near:.3f}-{band.far:.3f} m back over the {need.thing}"
            what += f" (its top at {need.top:.3f} m)"
        said.append(f"{what} holds it at {need.height:.3f} m")
        advised = band_advice(ctx, held, side, (x, y), (cx, cy), need, low)
        if advised:
            bands.append(advised)
    banded = f"with {', and '.join(bands)}, " if bands else ""
    moved = " and ".join(f"the {thing}" for thing in dict.fromkeys(things))
    return (
        f"to pass the {met[0].name} by its {held.grasp.value} grasp the {held.name}'s bottom must stay at {low:.3f} m"
        f" or lower, and {'; '.join(said)}: it would pass {banded}with {moved} moved off its way (home:x, home:y),"
        f" or by another approach (home:graspApproach)"
    )


class _Found(NamedTuple):
    """The spot a take's carry aims at (:func:`_clear_spot`), why the arm's planning would refuse the take
    and carry there (empty: it would make them) and why they would not keep CARRY_CLEARANCE from the
    appliances (empty: they would)."""

    spot: Region
    refused: str = ""
    unclear: str = ""


def _clear_spot(
    ctx: SimContext,
    side: ArmSide,
    first: Region,
    others: Callable[[Sequence[tuple[float, float]]], Iterator[Region]],
    taking: tuple[ObjectEstimate, ObjectModel],
) -> _Found:
    """Of ``first`` and then ``others`` (asked only when the take and carry to ``first`` come within
    CARRY_CLEARANCE of an appliance, or the arm's planning would refuse them), the first spot whose take
    and carry (:func:`carry_check`) the planning would make keeping that clearance, up to CLEAR_TRIES of
    them; else ``first`` when the planning would make them there, though not keeping clear, as before;
    else the first of the others where it would; else ``first`` with why the planning refuses them there.
    Where the take itself comes that near (an object below a tap's spout), no spot's can keep clear: the
    others are not asked. A refused ``first`` asks the others too: since the held object is checked
    against the appliances (:func:`skills.held_meets`), a jar carried to the table's spot beside the
    dispenser is refused there, not only noted, and the spots a little farther went unasked
    (JarOntoTheTable at seed 1 was refused before the run). ``others`` is given where the dry runs came
    near so far, and gives the spots farther from the appliances than those first (:func:`relay.clear_asked`):
    the neighbours of a spot whose carry passes by a tap's lever pass by it too (BookOntoTheTable at seed 2)."""
    refused, brushed = carry_check(ctx, side, first, taking)
    if not (refused or brushed):
        return _Found(first)
    seen, held = taking
    at_take = skills.plan_carry(ctx.world, seen, side, held, clearance=CARRY_CLEARANCE).brushed
    if at_take:
        return _Found(first, refused, refused or f"taking the {held.name}: {at_take}")
    unrefused: _Found | None = None if refused else _Found(first, "", brushed)
    near = [first.center[:2]] if brushed else []  # where the dry runs came near an appliance
    for spot in itertools.islice(others(near), CLEAR_TRIES - 1):
        refused_there, brushed_there = carry_check(ctx, side, spot, taking)
        if not (refused_there or brushed_there):
            return _Found(spot)
        if brushed_there:
            near.append(spot.center[:2])
        if not refused_there and unrefused is None:
            unrefused = _Found(spot, "", brushed_there)
    return unrefused or _Found(first, refused, refused)


def note_choice(ctx: SimContext, choice: GraspChoice) -> None:
    """Keep a choice among several approaches, readable (``SimEnvironment.context.choices``)."""
    if len(choice.model.preference) > 1:
        ctx.choices.append(choice)


@dataclass(frozen=True)
class Loading:
    """Who loads the platform, by which grasp, and who passes the object first, by which, and where."""

    loader: GraspChoice
    giver: GraspChoice | None = None
    spot: Region | None = None


def who_loads(ctx: SimContext, estimate: ObjectEstimate, model: ObjectModel, base: Pose2D) -> Loading:
    """Which arm loads the object onto the platform of the base parked at ``base`` and by which of its
    approaches, and, when another arm must first pass it, that arm, its approach and the spot where it
    sets the object down; SkillFailed saying why none can. Each arm holds it by the first approach, in
    its class's order, by which it can both take it and let it go where its hold ends (an arm that
    passes it sets it down, so the loader may take it anew by another approach). Asked without moving
    (inverse kinematics on the private copies): by the hand-over, and before a run, by the plan's check
    (:meth:`SimEnvironment.given`). With one approach only the letting go on the platform is asked of the
    end poses, as before approaches could be chosen. The moves of each hold are then dry-run, one approach
    alone too, as the approach choice's are (:func:`first_clear`, :func:`refuse_moves`): :class:`MovesRefusedError`
    when the arm's planning would refuse them.

    The arms are asked in turn, as the approach is (:func:`who_takes`): each arm that reaches both the
    object and the platform, nearest the object first (one hold, else a re-grasp), then each pass from an
    arm that reaches the object to another that reaches the platform. The first way that serves is
    taken; when none does, the first way's refusal, followed by why each other way did not serve."""
    x, y, _ = estimate.position
    takers = reaching(ctx, x, y)
    loaders = reaching(ctx, base.x, base.y)
    if not takers:
        raise SkillFailed(f"no free arm reaches the {model.name} at ({x:.2f}, {y:.2f}){why_none(ctx, x, y)}")
    if not loaders:
        raise SkillFailed(
            f"no free arm reaches the base's platform at ({base.x:.2f}, {base.y:.2f}): the docking pose is "
            f"beyond every arm's reach{why_none(ctx, base.x, base.y)}"
        )
    fits = _fitting(ctx, model, takers)
    if fits:
        raise SkillFailed(fits)
    ways = [(side, side) for side in takers if side in loaders]
    ways += [(giver, loader) for giver in takers for loader in loaders if giver is not loader]
    refused: list[tuple[ArmSide, ArmSide, Exception]] = []
    for giver, loader in ways:
        try:
            only = giver not in loaders and loader not in takers
            return _loading_by(ctx, estimate, model, base, giver, loader, only)
        except (SkillFailed, MovesRefusedError) as why:
            refused.append((giver, loader, why))
    first = refused[0][2]
    if len(refused) == 1:
        raise first
    others = "; ".join(
        f"nor by the {giver.value} arm alone: {why}"
        if giver is loader
        else f"nor passed from the {giver.value} arm to the {loader.value}: {why}"
        for giver, loader, why in refused[1:]
    )
    raise SkillFailed(f"{first}; {others}")


def _loading_by(
    ctx: SimContext,
    estimate: ObjectEstimate,
    model: ObjectModel,
    base: Pose2D,
    giver: ArmSide,
    loader: ArmSide,
    only: bool,
) -> Loading:
    """The loading of :func:`who_loads` one way: ``loader`` alone (``giver`` the same arm: one hold, else a
    re-grasp), or ``giver`` passing the object to ``loader`` (``only``: the giver does not reach the
    platform)."""
    world, choosing = ctx.world, len(model.preference) > 1
    both = [giver] if giver is loader else []
    purpose = f"loading the {model.name} onto the platform"
    platform = skills.platform_region(base, world.platform_height)
    # Letting go on the platform does not depend on where the loader takes the object from.
    checks = [lambda held: skills.can_load(world, estimate, base, loader, held)]
    whole: Candidates | None = None
    unserved = ""  # why no one hold serves from where the object is to the platform
    refused: MovesRefusedError | None = None
    if both:  # one hold, from where it is to the platform
        whole = Candidates.of(
            turned(ctx, estimate, model, loader),
            *([lambda held: skills.can_take(world, estimate, loader, held), *checks] if choosing else checks),
        )
        unserved = whole.refusal()
        if whole.models:  # the first whose moves the loader's planning would make, one alone too (first_clear)
            spots = {held.grasp: platform for held in whole.models}
            try:
                loads = first_clear(
                    whole, loader, purpose, lambda held: _loads(ctx, estimate, base, loader, held), spots
                )
            except MovesRefusedError as moves:
                if not choosing:
                    raise
                # the hold's moves refused by every approach whose end poses pass: a re-grasp may serve, as
                # where the end poses rule every approach out
                refused, unserved = (
                    moves,
                    "; ".join(why for _, _, why in moves.refused) + (f"; {unserved}" if unserved else ""),
                )
            else:
                return Loading(loads)
        if not choosing:
            raise SkillFailed(whole.refusal())
    # Two holds, the object set down between them where both reach: the arm that reaches it passes it to
    # the loader, or, when one arm reaches both but no approach serves it all the way, that arm sets it
    # down and takes it anew by an approach that loads (the re-grasp).
    gripping = [lambda held: skills.can_grip(held, world.arm(loader).hand)]
    loading = Candidates.of(model, *([*gripping, *checks] if choosing else checks))
    given_model = turned(ctx, estimate, model, giver)  # the giver takes it where it lies; the loader from the spot
    giving = (
        Candidates.of(given_model, lambda held: skills.can_take(world, estimate, giver, held)) if choosing else None
    )
    if whole is not None and not (loading.models and giving is not None and giving.models):
        if refused is not None:
            raise refused
        raise SkillFailed(whole.refusal())
    if not loading.models:
        if only:
            raise SkillFailed(
                f"only the {giver.value} arm reaches the {model.name} and only the {loader.value} arm the platform, "
                f"and {loading.refusal()}"
            )
        raise SkillFailed(f"the {loader.value} arm would load the {model.name}, but {loading.refusal()}")
    if giving is not None and not giving.models:
        if only:
            raise SkillFailed(f"only the {giver.value} arm reaches the {model.name}, and {giving.refusal()}")
        raise SkillFailed(f"the {giver.value} arm would pass the {model.name}, but {giving.refusal()}")
    giving = giving or Candidates([given_model])
    setting_down = (
        f"setting the {model.name} down to take it anew, no one approach serving from where it is to the "
        f"platform ({unserved})"
        if whole is not None
        else f"passing the {model.name} to the {loader.value} arm"
    )

    near = ""  # why the first spot whose holds serve does not keep CARRY_CLEARANCE from the appliances

    def holds(spot: Region, given_by: ObjectModel, taken_by: ObjectModel) -> str:
        # Both holds' moves are dry-run before the first moves: the giver's from where the object is to the
        # spot, the loader's from the spot to the platform (from its posture now; a re-grasping arm will
        # have folded home, where it starts a task); and where either comes within CARRY_CLEARANCE of an
        # appliance, which relay_spot passes the spot over for, taking the first such spot only when none
        # keeps clear: after it, a giver's carry that comes near leaves the loader's moves unasked.
        nonlocal near
        why, brushed = carry_check(ctx, giver, spot, (estimate, given_by))
        refuse_moves(why, given_by, giver, setting_down, spot)
        if brushed and near:
            return brushed
        there = resting_at(spot, model, estimate, world.time)
        loads = skills.plan_hand_over(world, there, base, loader, taken_by, CARRY_CLEARANCE)
        why, loading_brushed = loads.refused, loads.brushed
        refuse_moves(why, taken_by, loader, purpose, platform)
        here = brushed or (loading_brushed and f"the {loader.value} arm loading the {model.name}: {loading_brushed}")
        near = near or here
        return here

    try:
        spot, given_by, taken_by = relay_spot(ctx, estimate, giving, loading, giver, loader, holds)
    except SkillFailed as nowhere:
        if whole is None:
            raise
        if refused is not None:
            raise SkillFailed(f"{refused}; and {nowhere}") from None
        raise SkillFailed(f"{whole.refusal()}; and {nowhere}") from None
    given = giving.choice(giver, given_by, setting_down, "no spot to set it down by it")
    loaded = loading.choice(loader, taken_by, purpose, "no spot to take it by it")
    return Loading(loaded, given, spot)


def _loads(ctx: SimContext, estimate: ObjectEstimate, base: Pose2D, side: ArmSide, held: ObjectModel) -> str:
    """Why ``side``'s planning would refuse the hand-over's moves by ``held``'s approach (a dry run)."""
    return skills.can_hand_over(ctx.world, estimate, base, side, held)
