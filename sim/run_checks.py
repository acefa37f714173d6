"""The checks before a run: a plan the home cannot carry out is refused before anything moves.

By the map and where things are believed to be: a step that needs a person the home cannot tell, an
arm step given a thing no arm reaches (an object's grasp point counted in three dimensions; a place with
no clear spot for the object) or an object no hand can grip, a camera that would not see what it looks
for, an object no arm can load onto the platform. Otherwise the base drives
off and the step fails later. Each refusal is a typed error naming what was wrong.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from cbrs.actions.base_choice import base_groups
from cbrs.actions.base_choice import map_bases as map_bases  # the store's bases: cbrs.tasks and the tests read it here
from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.hands import Hand
from cbrs.kb.model import Advertisement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.person_choice import person_for
from cbrs.kb.semantic_map import MapObject, NotGraspableError, Person, Thing, local_name
from cbrs.kb.store import Term
from cbrs.kb.turned_fit import fits_some_turn
from cbrs.sim import predicates as pred
from cbrs.sim import sight, skills
from cbrs.sim.arm_choice import TAKING, check_take, lying_estimate, who_loads
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.errors import GraspTooDeepError, GraspTooThinError, GraspTooWideError, MovesRefusedError
from cbrs.sim.geometry import Pose2D
from cbrs.sim.grasping import GraspKind, ObjectModel, check_side_depth, held_height
from cbrs.sim.grounding import docking_pose, people_given, task_inputs_of
from cbrs.sim.packing import AtCarry, arms_free, check_room
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.place_spots import (
    RELAY_CLEARANCE,
    RELAY_EDGE,
    RELAY_MARGIN,
    distance_to_extent,
    held_now,
    other_objects,
    place_spots,
    resting_surface,
    spot_inset,
    support_of,
)
from cbrs.sim.services import (
    MOVING,
    SKILLS,
    WITH_BASE,
    WITH_PERSON,
    find_object_on_table,
    infer_object_place,
    kept_place,
    locate,
    navigate_to_person,
    navigate_to_place,
    recognise_by_colour,
    track,
)
from cbrs.sim.values import Manipulation
from cbrs.sim.world import HomeWorld

HOME = PREFIXES["home"]

log = logging.getLogger("cbrs.sim")

LOADING_SLACK = 0.01
"""The plan's loading check refuses an object only if no arm could load it this far from where it is
believed to be either (the cameras' estimates of one object differ by millimetres to a centimetre)."""


class CannotLoadError(KnowledgeBaseError):
    """A step would hand an object the task gives over onto the mobile base's platform, and no arm can
    (the object out of every arm's reach, the docking pose behind the arms, a grasp no arm can hold over
    the platform): the run is refused before anything moves."""

    http_status = 422

    def __init__(self, component: str, thing: str, reason: str) -> None:
        self.component = component
        self.thing = thing
        self.reason = reason
        super().__init__(f"{local_name(component)} cannot load the {local_name(thing)} onto the platform: {reason}")


class OutOfReachError(KnowledgeBaseError):
    """A thing a task gives to a robot's arms is beyond the reach of every one of them, by the map: the
    run is refused before anything moves. ``arms`` holds (arm IRI, mount x, y, reach, distance): for an
    object the distance from the mount to its grasp point ``height`` m up (a sphere of the reach about
    the mount), for a place on the floor plan (``height`` None)."""

    http_status = 422

    def __init__(
        self,
        robot: str,
        thing: str,
        where: tuple[float, float],
        arms: list[tuple[str, float, float, float, float]],
        why: str = "",
        height: float | None = None,
    ) -> None:
        self.robot = robot
        self.thing = thing
        self.where = where
        self.arms = tuple(arms)
        self.why = why
        """For a place part of which is in reach: why none of it will do (empty otherwise)."""
        self.height = height
        each = "; ".join(
            f"{local_name(arm)} reaches {reach:.2f} m from ({x:.2f}, {y:.2f}), {distance:.2f} m away"
            for arm, x, y, reach, distance in self.arms
        )
        up = "" if height is None else f", its grasp point {height:.2f} m up"
        lower = "" if height is None else ", or onto a lower surface"
        said = "; ".join(part for part in (each, why) if part)
        super().__init__(
            f"no arm of {local_name(robot)} reaches the {local_name(thing)} at ({where[0]:.2f}, {where[1]:.2f}){up}: "
            f"{said}; move it within reach in the map (home:x, home:y{lower}) or give the arms more home:reach"
        )


class CannotGripError(KnowledgeBaseError):
    """An object a task gives to a robot's arms fits no hand of the robot that reaches it, by any approach its
    class allows, wherever it is and however it lies (:func:`grip_refusal`): the run is refused before
    anything moves. ``refusals`` holds (arm IRI, approach, why); ``limits`` which of a hand's values limit
    each (the keys of :data:`GRIP_LIMITS`), for the advice."""

    http_status = 422

    def __init__(
        self, robot: str, thing: str, refusals: list[tuple[str, str, str]], limits: Sequence[str] = ()
    ) -> None:
        self.robot = robot
        self.thing = thing
        self.refusals = tuple(refusals)
        self.limits = tuple(dict.fromkeys(limits))
        said: dict[tuple[str, str], list[str]] = {}  # one reason once, with the arms it holds for
        for arm, approach, why in self.refusals:
            said.setdefault((approach, why), []).append(local_name(arm))
        each = "; ".join(
            f"by its {approach} grasp ({', '.join(arms)}): {why}" for (approach, why), arms in said.items()
        )
        advice = "; ".join(GRIP_LIMITS[limit] for limit in self.limits if limit in GRIP_LIMITS)
        verb = "lift" if self.limits == ("heavy",) else "grip"
        super().__init__(
            f"no hand of {local_name(robot)} can {verb} the {local_name(thing)}: {each}; a hand's {advice}"
        )


GRIP_LIMITS = {
    "thin": (
        "home:fingertipClearance and home:fingertipDepth say how far above the surface its fingertips stay "
        "and how far below the grasp point they reach"
    ),
    "wide": "home:jawOpening says how far its jaws open, home:jawClearance how far each must clear the object",
    "deep": (
        "home:fingerLength says how long its fingers are (tilted down by home:sideGraspPitch in a side grasp), "
        "home:sideHoldFraction how much of the object's depth they must hold"
    ),
    "palm": "home:palmDepth says how far its palm is above the fingers' grasp point",
    "heavy": (
        "home:payloadKg says how much it lifts (3 kg, the Panda's, where none is stated); the object's "
        "home:massKg is in kilograms"
    ),
}
"""The hand's values that limit a grip, by the kind of misfit, as :class:`CannotGripError` advises them:
the value that refused it first (the jaws' opening for an object too wide), then the policy beside it."""


def grip_refusal(model: ObjectModel, hand: Hand) -> tuple[str, str] | None:
    """Why ``hand`` cannot hold the object by ``model``'s approach wherever it is and however it lies, and
    the kind of misfit (a key of :data:`GRIP_LIMITS`); None when it can. The step's own decisions, in its
    words: too thin for a top grasp to hold above its surface (:func:`held_height`); wider at its narrowest
    (a cylinder's diameter, a box's narrower side: the least the jaws pass whichever way they close) than
    the hand's widest, or a top grasp whose palm meets the object's top (:func:`skills.can_grip`); a side
    grasp deeper than the fingers hold (:func:`check_side_depth`) however the object is turned to the jaws
    that pass it (a box across either side). The short fingers' cup was refused so by ApproachToObject
    after a re-plan, the check before the run knowing only the jaws and the thickness."""
    try:
        held_height(model, hand)
    except GraspTooThinError as thin:
        return str(thin), "thin"
    if model.width > hand.widest + 1e-9:
        wide = GraspTooWideError(model.name, model.grasp.value, model.width, hand.jaw_opening, hand.jaw_clearance)
        return str(wide), "wide"
    palm = skills.can_grip(model, hand)  # the jaws pass it: a top grasp's palm on its top is what is left
    if palm:
        return palm, "palm" if model.top_clearance(hand) < 0.0 else "wide"
    if model.grasp is not GraspKind.SIDE:
        return None
    deep: GraspTooDeepError | None = None
    for across, depth in _side_lies(model, hand):
        if across > hand.widest + 1e-9:
            continue
        try:
            check_side_depth(model, depth, hand)
        except GraspTooDeepError as error:
            deep = deep or error
            continue
        return None
    return (str(deep), "deep") if deep is not None else None


def _side_lies(model: ObjectModel, hand: Hand) -> list[tuple[float, float]]:
    """(width across the jaws, depth along the approach) of the object turned to a side grasp each way that
    may pass both (the step's ``ObjectModel.across`` each way): a box turned by t from lying with its
    side ``a`` across the jaws is a cos t + b sin t across and a sin t + b cos t deep, so the turns at
    which either meets its limit (the hand's widest; the deepest its fingers hold) bound the ranges of
    turns that pass it, and a turn that passes both is among them or the square lies. Narrowest across
    first. A cylinder is its diameter either way."""
    if model.footprint is None:
        return [(model.width, model.width)]
    a, b = sorted(model.footprint)
    radius = math.hypot(a, b)
    held = hand.side_span / hand.side_hold if hand.side_hold > 0.0 else math.inf
    turns = [0.0, math.pi / 2.0]
    for limit, phase in ((hand.widest, math.atan2(b, a)), (held, math.atan2(a, b))):
        if limit < radius:
            spread = math.acos(limit / radius)
            turns += [t for t in (phase - spread, phase + spread) if 0.0 < t < math.pi / 2.0]
    return [(a * math.cos(t) + b * math.sin(t), a * math.sin(t) + b * math.cos(t)) for t in sorted(turns)]


class PlaceCrowdedError(KnowledgeBaseError):
    """A place an arm step is given has spots its arms reach, but the objects on it leave none clear for
    the object at hand: the run is refused before anything moves. ``blockers`` holds (object IRI, x, y)."""

    http_status = 422

    def __init__(
        self,
        place: str,
        what: str,
        blockers: list[tuple[str, float, float]],
        clearance: float,
        later: Collection[str] = (),
    ) -> None:
        self.place = place
        self.blockers = tuple(blockers)
        each = ", ".join(f"the {local_name(iri)} at ({x:.2f}, {y:.2f})" for iri, x, y in self.blockers)
        text = (
            f"no spot of the {local_name(place)} holds {what} {clearance:.2f} m clear of the other objects, though"
            f" its arms reach it: {each} {'leaves' if len(self.blockers) == 1 else 'leave'} no room; move"
            f" {'it' if len(self.blockers) == 1 else 'them'} in the map (home:x, home:y) or make the place larger"
        )
        moving = [local_name(iri) for iri, _, _ in self.blockers if iri in later]
        if moving:
            text += (
                f"; the task moves the {' and the '.join(moving)} too, but only after: where two things are to "
                "take each other's places, one must first go to a third place (a task of its own, or a sub-action "
                "ordered before, act:PartialOrderingStrict)"
            )
        super().__init__(text)


FLOOR_MISMATCH = pred.RESTING_TOLERANCE / 2
"""How far a region's bottom may be from what a thing set down in it rests on (m): half the tolerance the
put-down's own test allows a thing's bottom (``predicates.RESTING_TOLERANCE``), the other half left to the
physics (a thing settles a few millimetres into a top, or a hair above it). A drawer's floor 1 cm above the
table (the twenty-second round) was at the tolerance's edge and failed after the put-down."""


class PlaceFloatsError(KnowledgeBaseError):
    """A region an arm step is given to set a thing down in has its bottom (``home:minZ``, where things in
    it rest) above or below what a thing set down there comes to rest on (:func:`place_spots.resting_surface`:
    a piece of furniture's top, or the floor): the thing would rest where the region is not, and the run
    would fail after the put-down ("did not come to rest in"). Refused before anything moves."""

    http_status = 422

    def __init__(self, place: str, bottom: float, support: str | None, top: float, tolerance: float) -> None:
        self.place = place
        self.bottom = bottom
        self.support = support
        self.top = top
        on = f"the top of the {local_name(support)}" if support else "the floor"
        gap = (bottom - top) * 100
        super().__init__(
            f"the {local_name(place)}'s bottom (home:minZ {bottom:g} m), where a thing set down in it must rest, is "
            f"{abs(gap):.1f} cm {'above' if gap > 0 else 'below'} {on} ({top:g} m), which is what a thing set "
            f"down there rests on: nothing of a region is built (a box's or a drawer's floor is not), and a "
            f"region's bottom must be within {tolerance * 100:g} cm of it; give the region home:minZ "
            f"{top:g}, or describe the box as furniture with its own extent (its home:maxZ the height things "
            f"rest at)"
        )


@dataclass(frozen=True)
class Moved:
    """The objects (IRIs) a plan's steps take in hand before (``before``) and after (``after``) the step
    whose place is checked (:meth:`PlanChecks._check_spot`)."""

    before: tuple[str, ...]
    after: tuple[str, ...]


class PlaceMovesError(KnowledgeBaseError):
    """A step would set a thing down onto a place the task gives that is a movable object of the map (a
    shape, a size and a pose: a tray), not furniture or a region with an extent: the simulated home builds
    each thing of the map as one or the other, a carry aims at a place's extent, and the check took the
    place for an object to grip ("no hand ... can grip the Tray1", the twentieth round). The run is refused
    before anything moves, saying what a place things are put onto must be."""

    http_status = 422

    def __init__(self, component: str, place: str, given_as: str) -> None:
        self.component = component
        self.place = place
        super().__init__(
            f"{local_name(component)} would set a thing down onto the {local_name(place)} (the task's "
            f"{given_as}), which the map describes as a movable object (home:shapeKind, home:sizeX .. home:sizeZ, "
            "home:x, home:y): nothing is put onto a thing that moves, a place things are put onto is furniture "
            "or a region with an extent (home:minX .. home:maxZ; docs/tasks.md, 'Put something onto furniture'); "
            "to have things put onto it, describe it so instead (its class under home:Furniture and "
            "home:ObjectPlace, its extent where it stands), as the ninth round's storage box"
        )


class PlaceTooSmallError(KnowledgeBaseError):
    """A place an arm step is given stands on a top too small for the object at hand as the carry sets it
    down: by the circle about its footprint (it comes to rest turned as it lay in the hand, which the
    carry does not turn), RELAY_EDGE inside the top's edge. The run is refused before anything moves,
    saying so, and whether the object would fit turned (:func:`kb.turned_fit.fits_some_turn`), which the
    map's check accepts for where an object stands at the start but a set-down cannot do."""

    http_status = 422

    def __init__(
        self, place: str, what: str, size: tuple[float, float, float], top: tuple[float, float], support: str
    ) -> None:
        self.place = place
        self.size = size
        self.top = top
        across = math.hypot(size[0], size[1])
        turned = (
            "; it would fit turned, which the simulation does not do" if fits_some_turn(size[0], size[1], top) else ""
        )
        on = "" if support == place else f" (on the {local_name(support)})"
        super().__init__(
            f"the {local_name(place)}{on} is {top[0]:.2f} x {top[1]:.2f} m, too small to set {what} "
            f"({size[0]:g} x {size[1]:g} m) down on: a carry sets a thing down turned as it lies in the hand, "
            f"never turned to fit, so it keeps the circle about its footprint ({across:.2f} m across) "
            f"{RELAY_EDGE:.2f} m inside the edge of the top, which needs {across + 2 * RELAY_EDGE:.2f} m each "
            f"way{turned}; choose a larger place"
        )


class PlanChecks:
    """The checks :meth:`SimEnvironment.given` makes of a plan before anything moves, by the map and where
    things are believed to be: every person a step needs can be told, every thing an arm step is given is
    in reach (and a place has a spot clear for the object), every camera that looks for something sees
    it, and the object a step loads onto the platform can be loaded."""

    def __init__(
        self,
        world: HomeWorld,
        kb: KnowledgeBase,
        belief: PerceivedWorld,
        context: SimContext,
        is_a: Callable[[str, str], bool],
        advertisements: Mapping[str, Advertisement] | None = None,
    ) -> None:
        self.world = world
        self.kb = kb
        self.belief = belief
        self.context = context
        self.is_a = is_a
        """Whether a class is another or a subclass of it (``SimEnvironment.is_a``, which keeps the table)."""
        self.advertisements = advertisements
        """Every advertisement by IRI, as the environment read it to make its components; None: read at the
        check."""

    def check(self, plan: Plan, values: Mapping[str, Any]) -> None:
        """Refuse ``plan`` with the first check's typed error (:class:`kb.person_choice.PersonError`,
        :class:`PlaceMovesError`, :class:`OutOfReachError`, :class:`PlaceCrowdedError`, :class:`PlaceTooSmallError`,
        :class:`arm_choice.CannotCarryError`,
        :class:`sight.OutOfViewError`,
        :class:`CannotLoadError`, :class:`kb.home_check.NoDockingPoseError`, :class:`sight.BaseOutOfViewError`,
        :class:`WhichBaseError`);
        nothing when every check passes. In a home of several bases, the world drives the one the plan works
        from here on (:func:`base_for`)."""
        ads = self.advertisements  # the environment's read: 20-30 ms each on the bundled store
        if ads is None:
            ads = {ad.iri: ad for ad in self.kb.advertisements()}
        base = base_for(self.world, plan, ads, values)  # a home of several bases: the one the plan works
        if base is not None:
            self.world.drive(base)
        meant = self._people_of(plan, values, ads)  # a step needing a person the home cannot give (nobody, who?)
        self._check_reach(plan, values)
        check_room(self.context, plan, values)  # several objects onto one place: room for all
        self._check_carry(plan, values)
        self._check_sight(plan, values, ads, meant)
        self._check_loading(plan, values)
        self._check_docks(plan, values, ads)
        self._check_localising(plan, values, ads)

    def _check_loading(self, plan: Plan, values: Mapping[str, Any]) -> None:
        """Refuse a plan that hands an object the task gives over onto the base's platform when no arm
        can load it there (by the map: the object where it is believed to be, the base at the docking
        pose of what it stands on; the same decision the hand-over makes), before the base drives off."""
        for step, obj, support in self._given_objects(plan, values, "HandingOverOntoPlatform"):
            if support.dock is None:
                continue
            estimate, model, dock = (
                lying_estimate(self.world, self.belief, obj),
                Manipulation.of(obj).model,
                docking_pose(support),
            )
            try:
                who_loads(self.context, estimate, model, dock)
            except (SkillFailed, MovesRefusedError) as refused:
                if not self._loads_nearby(estimate, model, dock):
                    advice = self._other_approach(estimate, model, dock)
                    raise CannotLoadError(step.component, obj.iri, str(refused) + advice) from None

    def _other_approach(self, estimate: ObjectEstimate, model: ObjectModel, dock: Pose2D) -> str:
        """What would load an object no arm loads by the approaches its class allows: an approach it does
        not allow by which one would (the eleventh round's coaster, "side" alone, loaded from the top), said
        as the class's home:graspApproach that adds it; empty when none would."""
        allowed = model.preference
        for kind in GraspKind:
            if kind in allowed:
                continue
            try:
                who_loads(self.context, estimate, replace(model, grasp=kind, approaches=()), dock)
            except (SkillFailed, MovesRefusedError):
                continue
            approaches = " ".join(k.value for k in (*allowed, kind))
            return (
                f"; allowed its {kind.value} grasp too, an arm would load it: give its class home:graspApproach "
                f'"{approaches}" (the approaches it may be taken by, best first)'
            )
        return ""

    def _check_carry(self, plan: Plan, values: Mapping[str, Any]) -> None:
        """Refuse a plan whose arm would take an object the task gives to carry it where the object held
        would meet an appliance on the way, by every arm and approach the step would choose from
        (:func:`arm_choice.check_take`: :class:`arm_choice.CannotCarryError`), before anything moves."""
        for step, obj, _support in self._given_objects(plan, values, "ApproachToObject"):
            check_take(
                self.context, step, obj.iri, lying_estimate(self.world, self.belief, obj), Manipulation.of(obj).model
            )

    def _given_objects(
        self, plan: Plan, values: Mapping[str, Any], action: str
    ) -> Iterator[tuple[PlanStep, MapObject, Thing]]:
        """(step, object, what it stands on) for each object of the map the task gives a step of ``action``
        (a local name of the act: namespace), directly or through the steps before it."""
        steps = {step.index: step for step in plan.steps}
        smap = self.world.map
        for step in plan.steps:
            if step.action != PREFIXES["act"] + action:
                continue
            for name in sorted(task_inputs_of(step, steps)):
                value = values.get(name)
                obj = smap.objects.get(str(value["@id"])) if isinstance(value, dict) and "@id" in value else None
                support = smap.things.get(obj.support or "") if obj is not None else None
                if obj is not None and support is not None:
                    yield step, obj, support

    def _check_docks(self, plan: Plan, values: Mapping[str, Any], ads: Mapping[str, Advertisement]) -> None:
        """Refuse a plan that sends the base to fetch an object standing only on furniture with no docking
        pose (:func:`services.kept_place`), before anything moves: the run went as far as the step that
        asks where the object is kept, and failed there."""
        steps = {step.index: step for step in plan.steps}
        for step in plan.steps:
            ad = ads.get(step.component)
            if ad is None or SKILLS.get(ad.service_name or "") is not infer_object_place:
                continue
            for name in sorted(task_inputs_of(step, steps)):
                value = values.get(name)
                if isinstance(value, dict) and str(value.get("@id")) in self.world.map.objects:
                    kept_place(self.context, str(value["@id"]))

    def _check_localising(self, plan: Plan, values: Mapping[str, Any], ads: Mapping[str, Advertisement]) -> None:
        """Refuse a plan that parks the base at a place (NavigateToPlace, at its docking pose) and then locates
        it by its marker, and the camera of no locator of the home sees the marker there
        (``sight.marker_centres``): the base drove off, was lost at the place and the next drive failed with
        "marker not visible" (the twentieth round's desk in the bedroom, which no bundled camera sees). Every
        locator counts, not only the step's candidates: the plan picks them by where the base is now (their
        effective areas), and the run fails over or re-plans to one that covers the place once the base is
        there. A drive to a person, or a locator of unknown camera (in another process), leaves where the
        base is to the run."""
        steps = {step.index: step for step in plan.steps}
        blockers = sight.occluders(self.world.map)
        locators = [ad for ad in ads.values() if SKILLS.get(ad.service_name or "") is locate]
        parked: tuple[Thing, Pose2D] | None = None
        for step in plan.steps:
            ad = ads.get(step.component)
            work = SKILLS.get(ad.service_name or "") if ad is not None else None
            if work is navigate_to_place:
                parked = self._parked_at(step, steps, values)
            elif work is navigate_to_person or (ad is not None and ad.bridge_port is not None):
                parked = None
            elif work is locate and parked is not None:
                cameras = [self._camera_of(each, (locate,)) for each in locators]
                if not all(cameras):
                    parked = None  # a camera the simulation does not have may see it
                    continue
                place, pose = parked
                centres = sight.marker_centres(self.world.marker_model, pose)
                why = [
                    (name, sight.unseen(self.world.cameras[name], centres, blockers))
                    for name in dict.fromkeys(cameras)
                    if name
                ]
                if all(reason for _, reason in why):
                    raise sight.BaseOutOfViewError(step.component, place.iri, pose, why)

    def _parked_at(
        self, step: PlanStep, steps: Mapping[int, PlanStep], values: Mapping[str, Any]
    ) -> tuple[Thing, Pose2D] | None:
        """The place a NavigateToPlace step parks the base at, and its docking pose: the place the task gives
        the step, or the one an object the task gives is kept on (``services.kept_place``, what
        InferObjectPlace answers); None when the map does not say."""
        smap = self.world.map
        for name in sorted(task_inputs_of(step, steps)):
            value = values.get(name)
            iri = str(value["@id"]) if isinstance(value, dict) and "@id" in value else ""
            thing = smap.things.get(iri)
            if thing is None and iri in smap.objects:
                try:
                    thing = kept_place(self.context, iri)
                except KnowledgeBaseError:
                    thing = None
            if thing is not None and thing.dock is not None:
                return thing, docking_pose(thing)
        return None

    def _loads_nearby(self, estimate: ObjectEstimate, model: ObjectModel, dock: Pose2D) -> bool:
        """Whether some arm could load the object were it LOADING_SLACK away from where it is believed to be
        (in x or y): the hand-over decides again from the camera's estimate, and a refusal at the believed
        centre alone is no refusal of the task. The pen at the edge of the right arm's planning, refused at
        (8.1015, 3.3317) before the run, was loaded from the Kinect's (8.0973, 3.3273) 6 mm away (the
        perturbation benchmark's world seed 19)."""
        for dx, dy in ((LOADING_SLACK, 0.0), (-LOADING_SLACK, 0.0), (0.0, LOADING_SLACK), (0.0, -LOADING_SLACK)):
            moved = replace(estimate, x=estimate.x + dx, y=estimate.y + dy)
            try:
                who_loads(self.context, moved, model, dock)
            except (SkillFailed, MovesRefusedError):
                continue
            log.info("loading check: the %s loads %+.3f, %+.3f m from where it is believed to be", model.name, dx, dy)
            return True
        return False

    def _people_of(self, plan: Plan, values: Mapping[str, Any], ads: Mapping[str, Advertisement]) -> dict[str, Person]:
        """The person each step of ``plan`` that needs one means, by component: a step whose skill tracks,
        goes to or hands something to a person, or that takes a ``home:Person`` input. A
        :class:`kb.person_choice.PersonError` (none in the map, several and the task names not one, or one the
        tracker cannot tell from another) names the first step that needs one."""
        designated = [str(v["@id"]) for v in values.values() if isinstance(v, dict) and "@id" in v]
        meant: dict[str, Person] = {}
        for step in plan.steps:
            ad = ads.get(step.component)
            person_input = any(b.concept and self.is_a(b.concept, HOME + "Person") for b in step.bindings)
            if not person_input and (ad is None or SKILLS.get(ad.service_name or "") not in WITH_PERSON):
                continue
            given = people_given(self.world.map, plan, step, values)
            meant[step.component] = person_for(self.world.map, step.component, given or designated)
        return meant

    def _check_sight(
        self, plan: Plan, values: Mapping[str, Any], ads: Mapping[str, Advertisement], meant: Mapping[str, Person]
    ) -> None:
        """Refuse a plan whose recognition step would look for an object the task gives (or whose tracking
        step for the person it gives) with a camera that cannot see it whole where it is believed to be (by
        the map: ``sight.unseen``), nor could the camera of any component that may stand in for the step's:
        else the base drives off and the step fails when it looks. An object an earlier step may have moved
        is not checked (it may be elsewhere by then), nor a step a component of unknown camera may do (one
        in another process). The person is outlined wherever the seed may put them (``sight.person_outline``),
        and a camera sees nothing through the map's solid boxes (``sight.occluders``)."""
        smap = self.world.map
        steps = {step.index: step for step in plan.steps}
        handled: set[str] = set()
        blockers = sight.occluders(smap)  # walls, furniture, appliances, robots' bodies hide what is behind them
        for step in plan.steps:
            given = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
            iris = [str(value["@id"]) for value in given if isinstance(value, dict) and "@id" in value]
            objects = [smap.objects[iri] for iri in iris if iri in smap.objects and iri not in handled]
            cameras = [self._camera_of(ads.get(candidate)) for candidate in step.candidates]
            if cameras[0] is None:
                ad = ads.get(step.component)
                if ad is None or ad.bridge_port is not None or SKILLS.get(ad.service_name or "") in MOVING:
                    handled.update(obj.iri for obj in objects)
                continue
            if not all(cameras):
                continue  # a camera the simulation does not have may see it
            ad = ads.get(step.component)
            if ad is not None and SKILLS.get(ad.service_name or "") is track:  # the person, by their shirt
                people = [meant[step.component]] if step.component in meant else []
                spread = self.world.spread.person  # where the seed may have put them
                looked_for = [(who.iri, sight.person_centre(who), sight.person_outline(who, spread)) for who in people]
                objects = []
            else:
                looked_for = []
            for obj in objects:
                support = smap.things.get(obj.support or "")
                rest = support.box.max_z if support is not None else 0.0
                centre = self.belief.position(obj.name) or (obj.start.x, obj.start.y, rest + obj.size[2] / 2)
                looked_for.append((obj.iri, centre, sight.object_outline(obj, centre)))
            for iri, centre, outline in looked_for:
                why = [
                    (name, sight.unseen(self.world.cameras[name], outline, blockers))
                    for name in dict.fromkeys(cameras)
                    if name
                ]
                if all(reason for _, reason in why):
                    raise sight.OutOfViewError(step.component, iri, centre, why)

    def _camera_of(
        self, ad: Advertisement | None, looking: tuple[Any, ...] = (recognise_by_colour, find_object_on_table, track)
    ) -> str | None:
        """The camera of the world a component of one of the ``looking`` skills (by default, the recognisers
        and the tracker) looks with; None for a component that is none, "" for one whose camera the
        simulation does not have (a component in another process)."""
        work = SKILLS.get(ad.service_name or "") if ad is not None else None
        if ad is None or work not in looking:
            return None
        device = looked_with(self.kb, ad)
        return device if device and device in self.world.cameras else ""

    def _check_reach(self, plan: Plan, values: Mapping[str, Any]) -> None:
        """Refuse a plan whose arm steps work on a thing the task gives that no arm of their robot
        reaches (by the map's mounts and reaches, and where the thing is believed to be: an object's grasp
        point within the reach of a mount in three dimensions, a mug on a shelf 65 cm above the mounts
        being out of reach though near on the floor plan), or an object no hand of theirs can grip
        (:class:`CannotGripError`), before any step runs: otherwise the base drives off and the failure
        comes later, from a camera that cannot see it or an arm that cannot reach it."""
        smap = self.world.map
        arms: dict[str, list[Any]] = {}
        for arm in smap.arms.values():
            arms.setdefault(arm.robot, []).append(arm)
        steps = {step.index: step for step in plan.steps}
        at_hand: dict[str, list[str]] = {}  # by robot: the objects its latest arm step given one works on
        free: dict[int, AtCarry] | None = None  # the arms free at each carry onto a place, asked once when needed
        taken = self._taken(plan, values, steps)
        for step in plan.steps:
            robot_arms = arms.get(step.device or "")
            # a robot of the map with no arm (its arms taken off) that a step would have take a thing in hand
            armless = not robot_arms and step.action in TAKING and (step.device or "") in smap.bodies
            if not robot_arms and not armless:
                continue
            robot_arms = robot_arms or []
            self._check_place_stands(step, values)
            given = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
            iris = [str(value["@id"]) for value in given if isinstance(value, dict) and "@id" in value]
            objects = [iri for iri in iris if iri in smap.objects]
            for iri in objects:  # an arm would take it: its class must say how (a decoration need not)
                if not smap.objects[iri].grasp_approaches:
                    raise NotGraspableError(iri, smap.objects[iri].types)
            if objects:
                at_hand[step.device or ""] = objects
            for iri in iris:
                box = self._reach_extent(iri)
                if box is None:
                    continue
                height = self._grasp_height(iri)
                reaches = [(arm, self._distance(box, height, arm.mount)) for arm in robot_arms]
                report = [(arm.iri, arm.mount[0], arm.mount[1], arm.reach, d) for arm, d in reaches]
                where = ((box[0] + box[1]) / 2, (box[2] + box[3]) / 2)
                if not any(distance <= arm.reach for arm, distance in reaches):
                    none = f"{local_name(step.device or '')} has no arm (home:hasArm)" if armless else ""
                    raise OutOfReachError(step.device or "", iri, where, report, none, height=height)
                if iri in objects:  # in reach: a hand of an arm that reaches it must fit it too
                    self._check_grip(step.device or "", iri, [arm for arm, d in reaches if d <= arm.reach])
                if iri in smap.regions or iri in smap.furniture:
                    if free is None:
                        found = other_objects(self.world, self.belief)
                        lying = {obj.iri: at for obj, at in zip(self.world.objects.values(), found, strict=True)}
                        free = arms_free(plan, smap, values, lying, held_now(self.world))
                    moved = Moved(
                        tuple(obj for index, obj in taken if index < step.index),
                        tuple(obj for index, obj in taken if index > step.index),
                    )
                    carried = at_hand.get(step.device or "", [])
                    self._check_spot(step, iri, carried, report, free.get(step.index), moved)

    def _taken(self, plan: Plan, values: Mapping[str, Any], steps: Mapping[int, PlanStep]) -> list[tuple[int, str]]:
        """The objects of the map the plan's steps take in hand (an approach to an object, a hand-over onto
        the platform), as (step index, object IRI): a thing an earlier step takes no longer stands where it
        stood when a later step sets another down (:class:`Moved`)."""
        found = []
        for step in plan.steps:
            if step.action not in TAKING:
                continue
            given = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
            iris = [str(value["@id"]) for value in given if isinstance(value, dict) and "@id" in value]
            found += [(step.index, iri) for iri in iris if iri in self.world.map.objects]
        return found

    def _check_place_stands(self, step: PlanStep, values: Mapping[str, Any]) -> None:
        """Refuse a step given, as a place (an input of a class at or below ``home:Place``: a carry's
        target), a movable object of the map (:class:`PlaceMovesError`)."""
        for binding in step.inputs:
            if binding.source.step is not None or not binding.concept or not self.is_a(binding.concept, HOME + "Place"):
                continue
            value = values.get(binding.source.name)
            iri = str(value["@id"]) if isinstance(value, dict) and "@id" in value else ""
            if iri in self.world.map.objects:
                raise PlaceMovesError(step.component, iri, binding.source.name)

    @staticmethod
    def _distance(
        box: tuple[float, float, float, float], height: float | None, mount: tuple[float, float, float]
    ) -> float:
        """How far from ``mount`` a hand must reach: to the extent ``box`` on the floor plan, and with a
        ``height`` (an object's grasp point) up or down to it too (an arm reaches as far every way)."""
        across = distance_to_extent(box, mount)
        return across if height is None else math.hypot(across, height - mount[2])

    def _grasp_height(self, iri: str) -> float | None:
        """How high a hand takes an object of the map: its grasp point (its class's grasp height above its
        bottom), where it is believed to be, else resting on its support; None for anything else (a
        place keeps the floor plan: a hand reaches over part of it)."""
        smap = self.world.map
        obj = smap.objects.get(iri)
        support = smap.things.get(obj.support or "") if obj is not None else None
        if obj is None:
            return None
        believed = self.belief.position(obj.name)
        if believed is not None:
            bottom = believed[2] - obj.size[2] / 2
        elif support is not None:
            bottom = support.box.max_z
        else:
            return None
        return bottom + obj.grasp_height

    def _check_grip(self, robot: str, iri: str, arms: list[Any]) -> None:
        """Refuse an object no hand of ``arms`` (those that reach it: a hand that grips it out of reach
        takes nothing, and the narrow left hand's cup passed here on the right arm's Panda hand, to be
        refused by the approach after a re-plan) can grip by any approach its class allows, wherever it
        is and however it lies (:func:`grip_refusal`)."""
        obj = self.world.map.objects[iri]
        model = ObjectModel.of(obj)
        refusals: list[tuple[str, str, str]] = []
        limits: list[str] = []
        hands = [self.world.map.hands.get(arm.iri) for arm in arms]
        if hands and all(hand is not None and obj.mass > hand.payload + 1e-9 for hand in hands):
            for arm, hand in zip(arms, hands, strict=True):
                assert hand is not None
                for kind in model.preference:
                    heavy = f"it weighs {obj.mass:g} kg (home:massKg), and the hand lifts {hand.payload:g} kg"
                    refusals.append((arm.iri, kind.value, heavy))
            raise CannotGripError(robot, iri, refusals, ["heavy"])
        for kind in model.preference:
            for arm in arms:
                hand = self.world.map.hands.get(arm.iri)
                if hand is None:
                    return  # a hand the map does not describe: the run's own to find
                refused = grip_refusal(model.by(kind), hand)
                if refused is None:
                    return
                refusals.append((arm.iri, kind.value, refused[0]))
                limits.append(refused[1])
        raise CannotGripError(robot, iri, refusals, limits)

    def _check_spot(
        self,
        step: PlanStep,
        iri: str,
        carried: list[str],
        report: list[tuple[str, float, float, float, float]],
        at_carry: AtCarry | None = None,
        moved: Moved | None = None,
    ) -> None:
        """Refuse a place an arm step is given, part of which the robot's arms reach, when no spot of it
        will do (:func:`place_spots`, by the map) for the object at hand: the one the step is given,
        else the one the robot's latest arm step given one worked on (a carry's object comes from the
        approach and pick-up before it); the largest, if there are several. The carry would aim at a
        spot it then lacks. A top too small for the object's circle and the edge is refused as such
        (:class:`PlaceTooSmallError`: the set-down does not turn a thing to fit), not as out of reach. At a
        carry that sets a thing down there (``at_carry``, :func:`packing.arms_free`) only the arms free then
        count, as the check of the room on a place counts them (docs/execution.md, "Room on a top: which
        arms count"): a spot only an arm holding something else reaches will not do. Before, every arm of
        the robot counted. A thing an earlier step of the plan takes (``moved.before``) is not counted where
        it stood (the cup a task moves out of the way before the pen goes where it was); where it will be
        set down is the carry's choice at the run, by what it sees then."""
        smap = self.world.map
        if iri in smap.regions and iri not in smap.furniture:
            under, level = resting_surface(smap, smap.things[iri])
            bottom = smap.things[iri].box.min_z
            if abs(bottom - level) > FLOOR_MISMATCH:
                raise PlaceFloatsError(iri, bottom, under.iri if under else None, level, FLOOR_MISMATCH)
        moved = moved or Moved((), ())
        objects = [smap.objects[other] for other in carried]
        size = max(
            (obj.size for obj in objects), key=lambda size: math.hypot(size[0], size[1]), default=(0.0, 0.0, 0.0)
        )
        names = [obj.name for obj in objects]
        name = names[0] if len(names) == 1 else ""
        mounts = [(x, y, reach) for _, x, y, reach, _ in report]
        gone = [smap.objects[iri].name for iri in moved.before if iri not in carried]
        others = other_objects(self.world, self.belief, *names, *gone)
        able = None  # every arm of the robot, but at a carry those free then
        if at_carry is not None and at_carry.busy:
            free = {arm.iri for arm in at_carry.free}
            able = [(x, y, reach) for arm, x, y, reach, _ in report if arm in free]
            if (
                not place_spots(smap, smap.things[iri], size, able, others, able)[1]
                and (place_spots(smap, smap.things[iri], size, mounts, others)[1])
            ):
                box = smap.things[iri].box
                holding = " and ".join(
                    f"the {smap.arms[arm].side} arm holds the {local_name(obj)}" for arm, obj in at_carry.busy.items()
                )
                thing = f"the {name}" if name else "an object"
                why = f"the arms that reach a spot of it for {thing} hold other things then ({holding})"
                where = ((box.min_x + box.max_x) / 2, (box.min_y + box.max_y) / 2)
                raise OutOfReachError(step.device or "", iri, where, report, why)
            mounts = able
        _, spots = place_spots(smap, smap.things[iri], size, mounts, others, able)
        if not spots:
            box = smap.things[iri].box
            what = f"the {name}" if name else "an object"
            _, support = support_of(smap, smap.things[iri])
            top = (support.box.max_x - support.box.min_x, support.box.max_y - support.box.min_y)
            if math.hypot(size[0], size[1]) + 2 * RELAY_EDGE > min(top) + 1e-9:
                raise PlaceTooSmallError(iri, what, size, top, support.iri)
            blockers = self._blockers(iri, size, mounts, [*names, *gone], others)
            if blockers:
                raise PlaceCrowdedError(iri, what, blockers, RELAY_CLEARANCE, moved.after)
            why = (
                f"no spot of it is {RELAY_MARGIN:.2f} m inside an arm's reach with {what}'s centre "
                f"{spot_inset() * 1000:.0f} mm inside the place and clear of the edge of the surface, the other "
                "objects and the fixtures on it"
            )
            where = ((box.min_x + box.max_x) / 2, (box.min_y + box.max_y) / 2)
            raise OutOfReachError(step.device or "", iri, where, report, why)

    def _blockers(
        self,
        place: str,
        size: tuple[float, float, float],
        mounts: list[tuple[float, float, float]],
        carried: list[str],
        others: list[tuple[float, float, float]],
    ) -> list[tuple[str, float, float]]:
        """The objects without which a place would have a spot for the object at hand, one left out at a
        time (else all together); empty when it has none even then (out of reach, too small, fixtures)."""
        smap = self.world.map
        thing = smap.things[place]
        if not place_spots(smap, thing, size, mounts, [])[1]:
            return []
        names = [name for name in self.world.objects if name not in carried]  # in the order of ``others``
        single = [
            n for n in range(len(names)) if place_spots(smap, thing, size, mounts, others[:n] + others[n + 1 :])[1]
        ]
        chosen = single or list(range(len(names)))
        return [(self.world.objects[names[n]].iri, others[n][0], others[n][1]) for n in chosen]

    def _reach_extent(self, iri: str) -> tuple[float, float, float, float] | None:
        """Where a thing of the map is for an arm, as (min x, max x, min y, max y): an object at the point
        where it is believed to be (else its start), a place, a piece of furniture or a tap lever its
        extent (an arm reaches it if it reaches part of it); None for a room, a person or what has no place."""
        smap = self.world.map
        obj = smap.objects.get(iri)
        if obj is not None:
            believed = self.belief.position(obj.name)
            x, y = (believed[0], believed[1]) if believed is not None else (obj.start.x, obj.start.y)
            return (x, x, y, y)
        thing = smap.things.get(iri)
        if thing is None or iri in smap.rooms:
            return None
        box = thing.box
        return (box.min_x, box.max_x, box.min_y, box.max_y)


_LOOKING = (locate, track, recognise_by_colour)
"""The skills that look with the component's own device."""


def own_camera(ad: Advertisement) -> str | None:
    """The camera a simulated component must find among the world's to be implemented at all: its device,
    for a skill that looks with its own (locating, tracking, recognising by colour); None for any other
    (a table-top finder looks with its robot's, a component in another process with its own). Without
    it the simulation has no implementation of the component (``sim.components.implementations``), and
    a run plans without it."""
    if ad.bridge_port is not None or SKILLS.get(ad.service_name or "") not in _LOOKING:
        return None
    return ad.device_name or ""


def map_cameras(kb: KnowledgeBase, facts: Sequence[Mapping[str, Term]] | None = None) -> set[str]:
    """The names of the cameras the world will have, from the store alone: each thing the map gives a field
    of view is a camera (``SemanticMap.cameras``), and the world builds one for each and no other.
    ``facts``: the rows of ``map_facts`` when the caller has read them already."""
    rows = kb.select("map_facts") if facts is None else facts
    return {local_name(row["thing"].value) for row in rows if row["property"].value == HOME + "fieldOfView"}


def looked_with(kb: KnowledgeBase, ad: Advertisement) -> str | None:
    """The name of the camera a simulated component looks with: its own (:func:`own_camera`), or for a
    table-top finder the first camera the store says is mounted on its robot ("" if none is); None for a
    component that looks with no camera of the home (another skill, or a component in another process)."""
    own = own_camera(ad)
    if own is not None or ad.bridge_port is not None or SKILLS.get(ad.service_name or "") is not find_object_on_table:
        return own
    rows = kb.select("mounted_cameras", {"robot": PREFIXES["svc"] + (ad.device_name or "")})
    return next((local_name(row["device"].value) for row in rows), "")


def unplaced_cameras(
    kb: KnowledgeBase, advertisements: Iterable[Advertisement], cameras: Collection[str]
) -> dict[str, tuple[str, str, bool]]:
    """The components of ``advertisements`` that look with a camera the world does not have (``cameras``:
    the names of those it has; before it is built, those the map places, ``SemanticMap.cameras``, of
    which it builds one each), by component: (the camera's name, why, whether a run plans without the
    component: :func:`own_camera`). A table-top finder whose robot carries no camera of the world is
    planned, and its step fails when it looks."""
    found: dict[str, tuple[str, str, bool]] = {}
    for ad in advertisements:
        name = looked_with(kb, ad)
        if name is None or name in cameras:
            continue
        if own_camera(ad) is not None:
            found[ad.iri] = (name, _unplaced(name), True)
        else:
            robot = ad.device_name or ""
            why = (
                f"it looks with {name}, the camera mounted on {robot}, which the map does not place (a camera needs"
                " home:x, home:y, home:z and home:fieldOfView in graph:map)"
                if name
                else f"it looks with the camera mounted on {robot}, and none is (home:mountedOn {robot})"
            )
            found[ad.iri] = (name, why, False)
    return found


def without_camera(advertisements: Iterable[Advertisement], cameras: Collection[str]) -> dict[str, str]:
    """The components of ``advertisements`` a run plans without for want of their own camera among
    ``cameras`` (:func:`own_camera`; those :func:`unplaced_cameras` marks so), each with why: the
    simulation has no implementation of them."""
    return {
        ad.iri: _unplaced(camera)
        for ad in advertisements
        if (camera := own_camera(ad)) is not None and camera not in cameras
    }


def without_base(advertisements: Iterable[Advertisement], bases: Collection[str]) -> dict[str, str]:
    """The simulated components of ``advertisements`` that work the mobile base (``services.WITH_BASE``: drive
    it, load its platform, find its marker), each with why, when the home has no base (``bases``, their IRIs
    or names, is empty): the simulation has no implementation of them, and a run plans without them
    (docs/simulation.md, "A home with no mobile base"). None when it has one or several (a run drives the one
    its plan works: :func:`base_for`)."""
    if bases:
        return {}
    return {
        ad.iri: _NO_BASE
        for ad in advertisements
        if ad.bridge_port is None and SKILLS.get(ad.service_name or "") in WITH_BASE
    }


_NO_BASE = "it works the mobile base (drives it, loads its platform or finds its marker), and graph:map has none"


class WhichBaseError(KnowledgeBaseError):
    """In a home of several mobile bases, a plan's steps that work a base name two of them (``named``: base
    IRI -> the components naming it), or none (``unnamed``: the components that name none): the simulation
    drives one base a run, the one the plan works, and cannot tell which. Refused before anything moves."""

    def __init__(self, bases: Sequence[str], named: Mapping[str, Sequence[str]], unnamed: Sequence[str]) -> None:
        self.bases, self.named, self.unnamed = tuple(bases), dict(named), tuple(unnamed)
        home = f"the home has {len(self.bases)} mobile bases ({', '.join(local_name(b) for b in self.bases)})"
        if len(self.named) > 1:
            each = "; ".join(
                f"{', '.join(local_name(c) for c in components)} work {local_name(base)}"
                for base, components in sorted(self.named.items())
            )
            said = f"the plan works two of them ({each}), and a run drives one: compose it with one base's components"
        else:
            said = (
                f"the plan's {', '.join(local_name(c) for c in self.unnamed)} name none of them (a base's own "
                "component, or the marker colours of a base as its input, would)"
            )
        super().__init__(f"{home}: {said}")


def base_for(world: HomeWorld, plan: Plan, ads: Mapping[str, Advertisement], values: Mapping[str, Any]) -> str | None:
    """The body name of the base ``plan`` works, in a home of several (None in a home of one or none, or for
    a plan that works no base): the device of a step that drives one (NavigateToPlace_P3DX01's P3DX01), or the
    base whose marker colours a locator's input names; a hand-over onto a platform names none and takes that
    base. :class:`WhichBaseError` when the steps name two, or none (docs/simulation.md, "A home with no
    mobile base")."""
    if len(world.mobiles) < 2:
        return None
    by_iri = {robot.iri: name for name, robot in world.mobiles.items()}
    steps = {step.index: step for step in plan.steps}
    named: dict[str, list[str]] = {}
    unnamed: list[str] = []
    for step in plan.steps:
        ad = ads.get(step.component)
        if ad is None or ad.bridge_port is not None or SKILLS.get(ad.service_name or "") not in WITH_BASE:
            continue
        device = ad.device or PREFIXES["svc"] + (ad.device_name or "")  # cbrs:device, else by its name
        bases = [device] if device in by_iri else _marked(world, step, steps, values)
        if bases:
            for base in bases:
                named.setdefault(base, []).append(step.component)
        else:
            unnamed.append(step.component)
    if len(named) == 1:
        return by_iri[next(iter(named))]
    if named or unnamed:
        raise WhichBaseError(sorted(by_iri), named, unnamed)
    return None


def base_components(world: HomeWorld, kb: KnowledgeBase) -> dict[str, frozenset[str]]:
    """In a home of several mobile bases, each base's own components (``actions.base_choice.base_groups``:
    the advertisements whose device is that base, simulated or remote): a run composes with one base's and
    without the others' (``actions.runner``, docs/simulation.md, "A home with no mobile base"). Empty in a
    home of one base or none, where nothing is left out (the store's advertisements are not read)."""
    if len(world.mobiles) < 2:
        return {}
    return base_groups(kb, [robot.iri for robot in world.mobiles.values()])


def _marked(world: HomeWorld, step: PlanStep, steps: Mapping[int, PlanStep], values: Mapping[str, Any]) -> list[str]:
    """The bases (IRIs) whose marker shows the colours a task's input to ``step`` names."""
    found = []
    for name in sorted(task_inputs_of(step, steps)):
        value = values.get(name)
        iri = str(value["@id"]) if isinstance(value, dict) and "@id" in value else ""
        colours = world.map.marker_colours(iri) if iri else None
        if colours is not None:
            found += [robot.iri for robot in world.mobiles.values() if robot.marker_colours == colours]
    return sorted(set(found))


def _unplaced(camera: str) -> str:
    return (
        f"it looks with {camera or 'no camera'}, which the map does not place (a camera needs home:x, home:y,"
        " home:z and home:fieldOfView in graph:map)"
    )
