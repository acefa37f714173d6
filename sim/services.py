"""The simulated skill behind each advertised service name (:data:`SKILLS`).

One work function per service (``LocateMobileRobot``, ``ApproachToObject``...): it decodes its inputs,
runs the skill of :mod:`sim.skills` on the device the advertisement names, and encodes its outputs, so
a component in another process could stand in for any of them.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import NoDockingPoseError, docked_place
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import Thing, local_name
from cbrs.sim import skills
from cbrs.sim.arm_choice import (
    carry_check,
    free_arm,
    grasp_pose_for,
    holdable_spot,
    note_choice,
    way_round,
    who_loads,
    who_takes,
)
from cbrs.sim.arms import ArmSide
from cbrs.sim.context import SimContext, SkillFailed, Work, check_outcome, robot_camera
from cbrs.sim.errors import SimulationError
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.grasping import ObjectModel, compute_grasp_pose
from cbrs.sim.grounding import docking_pose, manipulation_of, meant_person, model_of, place_of, thing_iri, thing_region
from cbrs.sim.hold_choice import Candidates, refuse_moves, seen_extent
from cbrs.sim.mapping import OccupancyGrid, build_occupancy_grid
from cbrs.sim.packing import carry_spots
from cbrs.sim.perceived import SEARCH_RADIUS
from cbrs.sim.perception import (
    ObjectEstimate,
    PersonEstimate,
    RobotPoseEstimate,
    locate_robot,
    recognise_object,
    track_person,
)
from cbrs.sim.place_spots import able_mounts, other_objects, place_spots, reach_of, spot_region
from cbrs.sim.planning import PlannedPath, first_obstacle, plan_path
from cbrs.sim.relations import region_of
from cbrs.sim.relay import check_passing, relay_object, relay_spot, resting_at, set_down_for
from cbrs.sim.room_quantities import measure
from cbrs.sim.transit import floor_to
from cbrs.sim.values import (
    APPROACH_POSITION,
    OBJECT_LOCATION,
    ColourFeature,
    GraspPlan,
    ObjectFeature,
    decode,
    designator,
    from_json,
    to_json,
)

HOME = PREFIXES["home"]


def infer_object_property(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    return {"colourFeature": to_json(ColourFeature(model_of(ctx, inputs["objectType"]).colour))}


def query_manipulation_property(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    return {"manipulationProperty": to_json(manipulation_of(ctx, inputs["objectType"]))}


def compute_grasp(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    known = manipulation_of(ctx, inputs["manipulationProperty"])
    return {"graspPose": to_json(GraspPlan(known.object, known.model))}


def _recognise(ctx: SimContext, camera: str, colour: str) -> ObjectEstimate:
    """The object of ``colour`` in the camera's image. Where several things of the home share the
    colour, it is the one the task names (else the one thing of that colour), looked for where it is
    believed to be: another thing of its colour is not it."""
    check_outcome(skills.clear_view(ctx.world))  # the camera between the arms: fold them first
    frame = ctx.world.camera(camera).capture()
    alike = sorted(name for name, obj in ctx.world.objects.items() if obj.colour == colour)
    meant = [name for name in alike if ctx.world.objects[name].iri in ctx.designated] if len(alike) > 1 else alike
    ctx.looked_for.update(ctx.world.objects[name].iri for name in (meant if len(meant) == 1 else alike))
    if len(meant) != 1:
        return recognise_object(frame, colour)  # one thing of its colour in view, else ambiguous
    name = meant[0]
    believed = ctx.belief.position(name) if ctx.belief is not None else None
    start = ctx.world.objects[name].start
    near = (believed[0], believed[1]) if believed is not None else (start.x, start.y)
    try:
        return recognise_object(frame, colour, near=near, radius=SEARCH_RADIUS)
    except SimulationError:
        if len(alike) > 1:
            raise
        return recognise_object(frame, colour)  # its colour is its own: wherever it is now


def recognise_by_colour(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    colour = decode(inputs["colourFeature"], ColourFeature).colour
    return {"objectPosition": to_json(_recognise(ctx, device, colour))}


def find_object_on_table(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """FindCupOnTable, for whatever object its input names: by the object's colour, with the robot's camera."""
    camera = robot_camera(ctx, device)
    if "cup" in inputs:
        colour = model_of(ctx, inputs["cup"]).colour
    elif "colourFeature" in inputs:  # standing in for a recogniser: it was given the colour itself
        colour = decode(inputs["colourFeature"], ColourFeature).colour
    else:
        raise SkillFailed(f"FindCupOnTable needs the object (cup) or its colour; it was given {sorted(inputs)}")
    return {"cupPosition": to_json(_recognise(ctx, camera, colour))}


def approach(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    model = model_of(ctx, inputs["graspPose"])
    estimate = decode(inputs["objectPosition"], ObjectEstimate)
    choice = who_takes(ctx, estimate, model)
    note_choice(ctx, choice)
    ctx.arm = choice.arm
    ctx.grasp = grasp_pose_for(ctx, estimate, choice.arm, choice.model)
    ctx.seen, ctx.focus = estimate, model.name
    ctx.last_arm = ctx.arm
    check_outcome(skills.approach_object(ctx.world, ctx.arm, ctx.grasp))
    return {}


def pick_up(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    if ctx.grasp is None:
        raise SkillFailed("no object was approached")
    check_outcome(skills.pick_up_object(ctx.world, ctx.arm, ctx.grasp))
    return {}


def carry(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """CarryObject to the target place by the arm holding the object, over the spot of the place nearest
    its centre that the arm reaches and can hold the object over (:func:`place_spots`): a table only
    part of which is in reach is worked at that part. When no spot is in that arm's reach and the other
    arm reaches one, the object is first passed to the other arm. When no free arm has one, the refusal
    names the objects that crowd the spots of the arms that could take the step, and each arm that reaches
    a spot but holds something else, and what (before, the objects were blamed for an arm that was busy)."""
    world = ctx.world
    place = place_of(ctx, inputs["targetPlace"], "the target place")
    ctx.region = region_of(place, place.iri in ctx.map.furniture)
    held = world.arm(ctx.arm).held
    carried = (world.name_of(held) if held is not None else None) or ctx.object or ""
    size = world.objects[carried].size if carried in world.objects else (0.0, 0.0, 0.0)
    others = other_objects(world, ctx.belief, carried)

    def spots(side: ArmSide) -> tuple[Region, list[tuple[float, float]]]:  # room kept for what comes after
        return carry_spots(ctx, place, carried, side, ctx.step)

    surface, mine = spots(ctx.arm)
    spot = holdable_spot(ctx, ctx.arm, surface, mine)
    if spot is None and ctx.grasp is not None:
        giver, model = ctx.arm, ctx.grasp.model
        cx, cy, _ = surface.center
        options = []
        for side in sorted(world.arm_specs):
            theirs = spots(side)[1] if side is not giver and world.arm(side).held is None else []
            if theirs:
                options.append((math.hypot(theirs[0][0] - cx, theirs[0][1] - cy), side, theirs[0]))
        if not options:
            spec = world.arm_specs[giver]
            able = able_mounts(world, carried)
            busy: list[str] = []  # arms that would have a spot but hold something else
            crowded: list[ArmSide] = []  # arms that can take the step and would have a spot but for the objects
            for side in sorted(world.arm_specs):
                reach = reach_of(world.arm_specs[side])
                held_there = world.arm(side).held
                holding = world.name_of(held_there) if held_there is not None else None
                if holding is not None and holding != carried:
                    if place_spots(ctx.map, place, size, [reach], [], [reach])[1]:
                        busy.append(f"the {side.value} arm, which reaches it, holds the {holding}")
                elif place_spots(ctx.map, place, size, [reach], [], able)[1]:
                    crowded.append(side)
            if crowded or busy:
                said = []
                if crowded:
                    names = [name for name in world.objects if name != carried]  # in the order of ``others``
                    on_it = [n for n, (x, y, _) in zip(names, others, strict=True) if surface.contains_xy(x, y)]
                    arms = " and ".join(side.value for side in crowded) + (
                        " arms reach" if len(crowded) > 1 else " arm reaches"
                    )
                    blockers = " and ".join(f"the {name}" for name in on_it) if on_it else "the objects"
                    said.append(
                        f"the {arms} it, but {blockers} on it {'leaves' if len(on_it) == 1 else 'leave'} no spot free"
                    )
                raise SkillFailed(
                    f"no spot of {place.name} is clear for the {model.name} (around ({cx:.2f}, {cy:.2f})): "
                    + "; ".join([*said, *busy])
                )
            other = "no other free arm reaches one" if len(world.arm_specs) > 1 else "the robot has no other arm"
            raise SkillFailed(
                f"no arm reaches a spot of {place.name} to set the {model.name} down on (around ({cx:.2f}, "
                f"{cy:.2f})): the {giver.value} arm holding it reaches {spec.reach:.2f} m from ({spec.mount[0]:.2f}, "
                f"{spec.mount[1]:.2f}), and {other} to pass it to"
            )
        _, taker, (sx, sy) = min(options)
        target = spot_region(surface, sx, sy)
        gx, gy, gz = ctx.grasp.position  # where it was taken from: its surface, lying as it was seen there
        seen = ctx.seen
        taken = ObjectEstimate(
            gx,
            gy,
            gz - model.grasp_height + model.height / 2.0,
            seen.yaw if seen is not None else None,
            seen.size if seen is not None else (0.0, 0.0, 0.0),
            model.colour,
            "hand",
            world.time,
            0,
        )
        # The taker takes it anew: by an approach it can set it down over the spot by (the first, with
        # one approach: whether it can is its carry's to find, as before).
        checks = [
            lambda held: skills.can_grip(held, world.arm(taker).hand),
            lambda held: skills.can_set_down(world, taken, taker, held, target),
        ]
        placing = Candidates.of(model, *(checks if len(model.preference) > 1 else []))
        if not placing.models:
            raise SkillFailed(f"the {taker.value} arm reaches {place.name}, but {placing.refusal()}")
        # Both arms' moves of the pass are dry-run before the giver sets the object down (it holds it now);
        # a spot whose moves are refused is passed over for the next (relay_spot).
        passing = f"passing the {model.name} from the {giver.value} arm to the {taker.value} for {place.name}"
        before = "the pass moved anything"

        def holds(spot: Region, _: ObjectModel, taken_by: ObjectModel) -> str:
            # and where either carry comes within CARRY_CLEARANCE of an appliance (relay_spot passes it over)
            why, near = carry_check(ctx, giver, spot)
            refuse_moves(why, model, giver, passing, spot, before)
            there = resting_at(spot, model, taken, world.time)
            # the giver will have folded home by the time the taker moves
            why, onward = carry_check(ctx, taker, target, (there, taken_by), folded=(giver,))
            refuse_moves(why, taken_by, taker, passing, target, before)
            return near or onward

        relay, _, taken_by = relay_spot(ctx, taken, Candidates([model]), placing, giver, taker, holds)
        found = set_down_for(ctx, device, model, giver, taker, relay, None)
        taker_spec = world.arm_specs[taker]
        note_choice(
            ctx,
            placing.choice(taker, taken_by, f"carrying the {model.name} to {place.name}", "no spot to take it by it"),
        )
        grasp = compute_grasp_pose(
            taken_by,
            found.position,
            found.yaw,
            taker_spec.mount,
            taker_spec.yaw,
            seen_extent(found),
            world.arm(taker).hand,
            found.size[2],
        )
        for move in (skills.approach_object, skills.pick_up_object):
            check_passing(move(world, taker, grasp), model, giver, taker)
        ctx.arm, ctx.grasp, ctx.seen, ctx.last_arm = taker, grasp, found, taker
    elif spot is None:
        raise SkillFailed(f"the {ctx.arm.value} arm reaches no spot of {place.name} to set the {carried} down on")
    else:
        target = spot_region(surface, *spot)
    ctx.spot = target
    grasped = world.arm(ctx.arm).held_grasp
    hand = world.arm(ctx.arm).ee_pose().position
    floor = None if grasped is None else floor_to(ctx, grasped.model, ctx.arm, hand, target)
    around = None if grasped is None else way_round(ctx, ctx.arm, grasped.model)
    check_outcome(skills.carry_object(world, ctx.arm, target, floor=floor, around=around))
    return {}


def put_down(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    if ctx.region is None:
        raise SkillFailed("nothing is being carried to a place")
    check_outcome(skills.put_down_object(ctx.world, ctx.arm, ctx.spot or ctx.region))
    return {}


def fill_from_tap(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """FillCupFromTap: the container its input names, from the tap its input names, by the free arm."""
    container = model_of(ctx, inputs["cup"]).name
    lever = thing_region(place_of(ctx, inputs["tap"], "the tap"))
    cx, cy, _ = (lever.xmin + lever.xmax) / 2, (lever.ymin + lever.ymax) / 2, 0.0
    side = free_arm(ctx, cx, cy, "the tap")
    ctx.last_arm = side
    check_outcome(skills.fill_cup_from_tap(ctx.world, side, lever, container))
    return {}


def hand_over(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """HandOverOntoPlatform by an arm that reaches both the object and the parked base's platform; when
    one arm reaches the object and only the other the platform, the first sets the object down where
    both reach (:func:`relay_object`) and the second loads it, each by the first of the object's approaches
    that works for its own hold (:func:`who_loads`)."""
    estimate = decode(inputs["objectPosition"], ObjectEstimate)
    model = model_of(ctx, inputs["graspPose"])
    base = ctx.world.base_pose()  # the base parks against the place's docking mark, which the robot knows
    loading = who_loads(ctx, estimate, model, base)
    side = loading.loader.arm
    if loading.giver is not None and loading.spot is not None:
        note_choice(ctx, loading.giver)
        estimate = relay_object(ctx, device, estimate, loading.giver.model, loading.giver.arm, side, loading.spot)
    note_choice(ctx, loading.loader)
    ctx.last_arm, ctx.focus = side, model.name
    reach = ctx.world.arm_specs[side].reach
    check_outcome(skills.hand_over_onto_platform(ctx.world, estimate, base, side, loading.loader.model, reach))
    return {}


def infer_object_place(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """Where the object is kept, from the belief state (else the semantic map), and where to park to reach
    it. Given a place rather than an object (a desk the task names as where to go), the place is where
    it is: its own docking pose, and no object feature to look for."""
    iri = thing_iri(inputs["object"], "the object")
    here = ctx.map.things.get(iri)
    if iri not in ctx.map.objects and here is not None and here.dock is not None:
        dock = docking_pose(here)
        return {
            "objectPlace": designator(here.iri, HOME + "ObjectPlace"),
            "objectLocation": to_json(dock, OBJECT_LOCATION),
            "approachPosition": to_json(dock, APPROACH_POSITION),
        }
    model = model_of(ctx, inputs["object"])
    try:
        place = kept_place(ctx, iri)
    except NoDockingPoseError as error:  # said by name: the support and the docking pose it lacks
        raise SkillFailed(str(error)) from None
    if place is None:
        raise SkillFailed(
            f"the knowledge base does not say where the {model.name} is kept: neither the world graph nor the "
            "map puts it on (home:isLocatedOn) a thing of the map with an extent"
        )
    dock = docking_pose(place)
    return {
        "objectPlace": designator(place.iri, HOME + "ObjectPlace"),
        "objectLocation": to_json(dock, OBJECT_LOCATION),
        "approachPosition": to_json(dock, APPROACH_POSITION),
        "objectFeature": to_json(ObjectFeature(model.colour)),
    }


def kept_place(ctx: SimContext, iri: str) -> Thing | None:
    """The thing the object ``iri`` is kept on that the mobile base can park at (a docking pose): where the
    world graph believes it is, else where the map puts it. :class:`kb.home_check.NoDockingPoseError` when
    it is on furniture and none has a docking pose; None when it is on nothing of the map. What
    :func:`infer_object_place` answers with, and what a check before the run can ask."""
    believed = [o for _, p, o in _facts(ctx.kb, iri) if p in (HOME + "isLocatedOn", HOME + "isLocated")]
    known = ctx.map.facts.get(iri, {}).get(HOME + "isLocatedOn", [])
    return docked_place(ctx.map, iri, [*believed, *known])


def _facts(kb: KnowledgeBase, thing: str) -> list[tuple[str, str, str]]:
    rows = kb.select("world_facts", {"thing": thing})
    return [(r["thing"].value, r["relation"].value, r["other"].value) for r in rows]


def _grid(ctx: SimContext) -> OccupancyGrid:
    """The run's occupancy grid, measured once."""
    if ctx.grid is None:  # seen through the base it is for; the other bases of a home of several stand in it
        world = ctx.world
        ignore = (world.mobile.name,) if world.mobile is not None else ()
        ctx.grid = build_occupancy_grid(world, inflation_radius=world.grid_inflation, ignore=ignore)
    return ctx.grid


def provide_grid_map(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    return {"map": to_json(_grid(ctx))}


def _drivable(ctx: SimContext, waypoints: list[tuple[float, float]]) -> None:
    """Refuse, before the base moves, a path whose legs cross an obstacle of the run's measured grid: the
    path may come from a planner in another process that ignores the map (planning.first_obstacle)."""
    hit = first_obstacle(_grid(ctx), waypoints)
    if hit is not None:
        raise SkillFailed(
            f"the path crosses an obstacle of the home's occupancy grid at ({hit[0]:.2f}, {hit[1]:.2f}), "
            f"between waypoints {_leg(waypoints, hit)}: not driven (its planner must keep to the grid's free cells)"
        )


def _leg(waypoints: list[tuple[float, float]], hit: tuple[float, float]) -> str:
    """Which leg ``hit`` lies on, as 'i and i+1' (counted from 0)."""
    for index, (a, b) in enumerate(itertools.pairwise(waypoints)):
        cross = (b[0] - a[0]) * (hit[1] - a[1]) - (b[1] - a[1]) * (hit[0] - a[0])
        inside = min(a[0], b[0]) - 1e-6 <= hit[0] <= max(a[0], b[0]) + 1e-6
        if abs(cross) < 1e-6 * max(1.0, math.dist(a, b)) and inside:
            return f"{index} and {index + 1}"
    return "?"


def locate(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    value = inputs.get("markerColour")
    colours = ctx.map.marker_colours(thing_iri(value, "the marker colour")) if value is not None else None
    if colours is None:
        colours = ctx.world.robot.marker_colours
    if colours is None:
        raise SkillFailed("the semantic map gives no marker colours to look for")
    try:
        marker = replace(ctx.world.marker_model, front=colours[0], rear=colours[1])
    except ValueError as error:
        raise SkillFailed(str(error)) from None
    return {"robotLocation": to_json(locate_robot(ctx.world.camera(device).capture(), marker))}


def track(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    value = inputs.get("person")
    person = ctx.map.people.get(thing_iri(value, "the person")) if value is not None else meant_person(ctx)
    if person is None or not person.colour:
        raise SkillFailed("the semantic map gives no colour to find the person by (home:colourName)")
    shirt = person.colour
    ctx.looked_for.add(person.iri)
    return {"personPosition": to_json(track_person(ctx.world.camera(device).capture(), shirt))}


def _xy(value: Any) -> tuple[float, float]:
    """Where on the floor a position of any kind is (a robot's, a person's, an approach pose, an object's)."""
    found = from_json(value)
    if isinstance(found, (Pose2D, RobotPoseEstimate, PersonEstimate, ObjectEstimate)):
        return (found.x, found.y)
    raise SkillFailed(f"not a position on the floor: {value!r}")


def planner(algorithm: str) -> Work:
    def work(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
        grid = decode(inputs["map"], OccupancyGrid)
        return {"path": to_json(plan_path(grid, _xy(inputs["start"]), _xy(inputs["goal"]), algorithm))}

    return work


def navigate_to_place(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    place = place_of(ctx, inputs["objectPlace"], "the place")
    path, dock = decode(inputs["path"], PlannedPath), docking_pose(place)
    _drivable(ctx, [*path.waypoints[:-1], dock.xy])  # the skill drives to the dock, not the path's last cell
    check_outcome(skills.navigate_to_place(ctx.world, path, dock))
    return {}


def navigate_to_person(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    path = decode(inputs["path"], PlannedPath)
    _drivable(ctx, list(path.waypoints))
    estimate = decode(inputs["personPosition"], PersonEstimate)
    check_outcome(skills.navigate_to_person(ctx.world, path, estimate, meant_person(ctx).name))
    return {}


def deliver(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    value = inputs.get("receiver")
    receiver = local_name(thing_iri(value, "the receiver")) if value is not None else meant_person(ctx).name
    check_outcome(skills.deliver_object(ctx.world, receiver))
    return {}


SKILLS: dict[str, Work] = {
    "InferObjectProperty": infer_object_property,
    "QueryManipulationProperty": query_manipulation_property,
    "ComputeGraspPose": compute_grasp,
    "RecogniseObjectByColour": recognise_by_colour,
    "FindCupOnTable": find_object_on_table,
    "ApproachToObject": approach,
    "PickUpObject": pick_up,
    "CarryObject": carry,
    "PutDownObject": put_down,
    "FillCupFromTap": fill_from_tap,
    "HandOverOntoPlatform": hand_over,
    "InferObjectPlace": infer_object_place,
    "ProvideGridMap": provide_grid_map,
    "LocateMobileRobot": locate,
    "TrackPerson": track,
    "PlanPathAStar": planner("astar"),
    "PlanPathDijkstra": planner("dijkstra"),
    "NavigateToPlace": navigate_to_place,
    "NavigateToPerson": navigate_to_person,
    "DeliverObject": deliver,
    "MeasureIlluminance": measure,
    "MeasureTemperature": measure,
    "MeasureHumidity": measure,
}
"""The simulated skill behind each service name; the device comes from the advertisement."""


WITH_PERSON = (track, navigate_to_person, deliver)
"""The skills that look for, go to or hand something to a person: the home must say which one."""


WITH_BASE = (hand_over, locate, navigate_to_place, navigate_to_person, deliver)
"""The skills that work the mobile base: drive it, load its platform, find its marker. A home with no base
has no implementation of them (``sim.run_checks.without_base``)."""


MOVING = (pick_up, carry, put_down, fill_from_tap, hand_over, deliver)
"""The skills that may move an object they are given: where a step after one looks for it is not known
before the run."""
