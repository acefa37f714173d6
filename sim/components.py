"""The simulation as an execution environment: components for the home's advertised services.

Each advertised component of ``ontologies/services.ttl`` that acts in the home has an implementation
here, built on the ``sim`` library: localisation from the ceiling camera image, recognition by colour
with the Kinect's depth, the map server, A* and Dijkstra on the grid, the arm and base skills. One
tick of a component runs one whole skill (the skill steps the physics itself), so an executor tick is
a unit of work, not of time; durations are reported in simulated seconds.

``SimEnvironment`` also gives the task's inputs (the world's cup, pen, person, regions), verifies the
statements a plan relies on against the simulated world, and observes the world for the belief
state (the world graph).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from actions.belief import WORLD, Observation
from actions.components import Component, Registry, Status
from actions.plan import Plan, PlanStep
from kb import KnowledgeBase, Requirement, Statement
from kb.namespaces import PREFIXES
from sim import predicates as pred
from sim import skills
from sim.arms import ArmSide
from sim.errors import SimulationError
from sim.geometry import Pose2D, Region
from sim.grasping import CUP, PEN, ObjectModel, compute_grasp_pose
from sim.layout import ARM_MOUNTS, BELOW_OF_TAP, DISPENSER, HANDOVER_POSE, TABLE, TAP_LEVER, room_of
from sim.mapping import OccupancyGrid, build_occupancy_grid
from sim.perception import (
    ObjectEstimate,
    PersonEstimate,
    RobotPoseEstimate,
    locate_robot,
    recognise_object,
    track_person,
)
from sim.planning import plan_path
from sim.world import HomeWorld

__all__ = ["MarkerColours", "Place", "SimContext", "SimEnvironment", "implementations"]

HOME = PREFIXES["home"]
SVC = PREFIXES["svc"]
MODELS = {"Cup": CUP, "Pen": PEN}
ARM_FOR = {"Cup": ArmSide.LEFT, "Pen": ArmSide.RIGHT}  # the cup's arm leaves the other for the tap
TAP_ARM = ArmSide.RIGHT
LOCALISATION_TOLERANCE = 0.10
"""A localisation is believed (isLocalisedIn holds) when it is within this distance (m) of the truth."""


@dataclass(frozen=True)
class MarkerColours:
    """The two colours of the marker a mobile robot carries (front and rear patch)."""

    front: str = "green"
    rear: str = "magenta"


@dataclass(frozen=True)
class Place:
    """A place where objects are kept, with the pose a mobile robot parks at to reach it."""

    name: str
    region: Region
    approach: Pose2D


@dataclass(frozen=True)
class GraspPlan:
    """What ComputeGraspPose gives: how to grasp this kind of object and with which arm; the grasp
    pose itself is fixed against the object's position when the arm approaches."""

    model: ObjectModel
    arm: ArmSide


PLACES = {WORLD + "KitchenTable": Place("KitchenTable", TABLE, HANDOVER_POSE)}

# The world's things: individual IRI -> (class, body name in the simulation or None)
THINGS: dict[str, tuple[str, str | None]] = {
    WORLD + "Cup": (HOME + "Cup", "Cup"),
    WORLD + "Pen": (HOME + "Pen", "Pen"),
    WORLD + "Person": (HOME + "Person", "Person"),
    SVC + "P3DX01": (HOME + "CarrierRobot", "P3DX01"),
    WORLD + "P3DX01Platform": (HOME + "RobotPlatform", None),
    SVC + "CytonDualArm01": (HOME + "DualArmRobot", None),
    WORLD + "KitchenTable": (HOME + "Table", None),
    WORLD + "BelowOfTap": (HOME + "BelowOfTap", None),
    WORLD + "Kitchen": (HOME + "Kitchen", None),
    WORLD + "LivingRoom": (HOME + "LivingRoom", None),
    WORLD + "Bedroom": (HOME + "Bedroom", None),
}

# What the task's inputs are in this world, by the parameter's class.
GIVEN_BY_TYPE: dict[str, Any] = {
    HOME + "Cup": CUP,
    HOME + "Pen": PEN,
    HOME + "Person": "Person",
    HOME + "ColourOfMarker": MarkerColours(),
    HOME + "MarkerColour": MarkerColours(),
    HOME + "BelowOfTap": BELOW_OF_TAP,
    HOME + "TableTop": TABLE,
    HOME + "Tap": TAP_LEVER,
    HOME + "WaterDispenser": DISPENSER,
}


@dataclass
class SimContext:
    """What sim components share: the world, the knowledge base, and what the arm is doing."""

    world: HomeWorld
    kb: KnowledgeBase
    grid: OccupancyGrid | None = None
    grasp: Any = None  # the grasp pose of the object the arm is working on
    arm: ArmSide = ArmSide.LEFT
    region: Region | None = None  # where the carried object goes


Work = Callable[[SimContext, Mapping[str, Any]], dict[str, Any]]


class SkillFailed(Exception):
    """A skill reported failure; the message is its reason."""


class SimComponent(Component):
    """A component whose invocation is one call of ``work`` on the shared context."""

    def __init__(self, iri: str, work: Work) -> None:
        super().__init__(iri)
        self._work = work
        self._inputs: Mapping[str, Any] = {}
        self._context: SimContext | None = None

    def initialise(self, context: Any) -> None:
        if not isinstance(context, SimContext):
            raise TypeError(f"{self.iri} needs a SimContext, got {type(context).__name__}")
        self._context = context

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self._inputs = inputs

    def update(self) -> Status:
        assert self._context is not None
        try:
            self.outputs = self._work(self._context, self._inputs)
        except (SimulationError, SkillFailed) as error:
            self.reason = str(error)
            return Status.FAILED
        return Status.SUCCEEDED


def _check(outcome: skills.Outcome) -> None:
    if not outcome.succeeded:
        raise SkillFailed(f"{outcome.skill}: {outcome.reason}")


# -- object knowledge and perception at the table -------------------------------------------------


def _model(value: Any) -> ObjectModel:
    if isinstance(value, ObjectModel):
        return value
    if isinstance(value, str) and value in MODELS:
        return MODELS[value]
    raise SkillFailed(f"no object model for {value!r}")


def infer_object_property(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    return {"colourFeature": _model(inputs["objectType"]).colour}


def query_manipulation_property(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    return {"manipulationProperty": _model(inputs["objectType"])}


def compute_grasp(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    model = _model(inputs["manipulationProperty"])
    return {"graspPose": GraspPlan(model, ARM_FOR.get(model.name, ArmSide.LEFT))}


def _recognise(ctx: SimContext, colour: str) -> ObjectEstimate:
    _check(skills.clear_view(ctx.world))  # the Kinect sits between the arms: fold them first
    return recognise_object(ctx.world.camera("Kinect01").capture(), colour)


def recognise_by_colour(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    return {"objectPosition": _recognise(ctx, str(inputs["colourFeature"]))}


def find_cup_on_table(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    return {"cupPosition": _recognise(ctx, _model(inputs["cup"]).colour)}


# -- the dual-arm robot ---------------------------------------------------------------------------


def approach(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    plan = inputs["graspPose"]
    estimate: ObjectEstimate = inputs["objectPosition"]
    if not isinstance(plan, GraspPlan):
        raise SkillFailed(f"expected a grasp plan, got {type(plan).__name__}")
    ctx.arm = plan.arm
    ctx.grasp = compute_grasp_pose(plan.model, estimate.position, estimate.yaw, ARM_MOUNTS[plan.arm.value])
    _check(skills.approach_object(ctx.world, ctx.arm, ctx.grasp))
    return {}


def pick_up(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    if ctx.grasp is None:
        raise SkillFailed("no object was approached")
    _check(skills.pick_up_object(ctx.world, ctx.arm, ctx.grasp))
    return {}


def carry(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    region = inputs["targetPlace"]
    if not isinstance(region, Region):
        raise SkillFailed(f"cannot carry to {region!r}: not a region of the home")
    ctx.region = region
    _check(skills.carry_object(ctx.world, ctx.arm, region))
    return {}


def put_down(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    if ctx.region is None:
        raise SkillFailed("nothing is being carried to a place")
    _check(skills.put_down_object(ctx.world, ctx.arm, ctx.region))
    return {}


def fill_cup(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    _check(skills.fill_cup_from_tap(ctx.world, TAP_ARM))
    return {}


def hand_over(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    pen: ObjectEstimate = inputs["objectPosition"]
    plan = inputs["graspPose"]
    side = plan.arm if isinstance(plan, GraspPlan) else ArmSide.RIGHT
    # The base parks against the table's docking mark, which the dual-arm robot knows.
    _check(skills.hand_over_onto_platform(ctx.world, pen, ctx.world.base_pose(), side))
    return {}


# -- the home server, the ceiling cameras and the mobile base -------------------------------------


def infer_object_place(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    """Where the object is kept, from the world graph (KnowRob style), and how to reach that place."""
    model = _model(inputs["object"])
    thing = WORLD + model.name
    places = [o for _, p, o in _facts(ctx.kb, thing) if p in (HOME + "isLocatedOn", HOME + "isLocated") and o in PLACES]
    if not places:
        raise SkillFailed(f"the knowledge base does not say where the {model.name} is")
    place = PLACES[places[0]]
    return {
        "objectPlace": place,
        "objectLocation": place.approach,
        "approachPosition": place.approach,
        "objectFeature": model.colour,
    }


def _facts(kb: KnowledgeBase, thing: str) -> list[tuple[str, str, str]]:
    rows = kb.select("world_facts", {"thing": thing})
    return [(r["thing"].value, r["relation"].value, r["other"].value) for r in rows]


def provide_grid_map(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    if ctx.grid is None:
        ctx.grid = build_occupancy_grid(ctx.world)
    return {"map": ctx.grid}


def locate(camera: str) -> Work:
    def work(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
        colours = inputs.get("markerColour", MarkerColours())
        if not isinstance(colours, MarkerColours):
            raise SkillFailed(f"not a marker colour: {colours!r}")
        return {"robotLocation": locate_robot(ctx.world.camera(camera).capture(), colours.front, colours.rear)}

    return work


def track(camera: str) -> Work:
    def work(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
        return {"personPosition": track_person(ctx.world.camera(camera).capture())}

    return work


def _xy(value: Any) -> tuple[float, float]:
    if isinstance(value, (Pose2D, RobotPoseEstimate, PersonEstimate)):
        return (value.x, value.y)
    raise SkillFailed(f"not a position on the floor: {value!r}")


def planner(algorithm: str) -> Work:
    def work(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
        grid = inputs["map"]
        if not isinstance(grid, OccupancyGrid):
            raise SkillFailed("the map is not an occupancy grid")
        return {"path": plan_path(grid, _xy(inputs["start"]), _xy(inputs["goal"]), algorithm)}

    return work


def navigate_to_place(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    place = inputs["objectPlace"]
    if not isinstance(place, Place):
        raise SkillFailed(f"not a place: {place!r}")
    _check(skills.navigate_to_place(ctx.world, inputs["path"], place.approach))
    return {}


def navigate_to_person(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    _check(skills.navigate_to_person(ctx.world, inputs["path"], inputs["personPosition"]))
    return {}


def deliver(ctx: SimContext, inputs: Mapping[str, Any]) -> dict[str, Any]:
    receiver = inputs.get("receiver", "Person")
    _check(skills.deliver_object(ctx.world, str(receiver)))
    return {}


IMPLEMENTATIONS: dict[str, Work] = {
    "InferObjectProperty_HomeServer01": infer_object_property,
    "QueryManipulationProperty_HomeServer01": query_manipulation_property,
    "ComputeGraspPose_CytonDualArm01": compute_grasp,
    "RecogniseObjectByColour_Kinect01": recognise_by_colour,
    "FindCupOnTable_CytonDualArm01": find_cup_on_table,
    "ApproachToObject_CytonDualArm01": approach,
    "PickUpObject_CytonDualArm01": pick_up,
    "CarryObject_CytonDualArm01": carry,
    "PutDownObject_CytonDualArm01": put_down,
    "FillCupFromTap_CytonDualArm01": fill_cup,
    "HandOverOntoPlatform_CytonDualArm01": hand_over,
    "InferObjectPlace_HomeServer01": infer_object_place,
    "ProvideGridMap_HomeServer01": provide_grid_map,
    "LocateMobileRobot_CeilingCamera01": locate("CeilingCamera01"),
    "LocateMobileRobot_CeilingCamera02": locate("CeilingCamera02"),
    "TrackPerson_CeilingCamera01": track("CeilingCamera01"),
    "PlanPathAStar_HomeServer01": planner("astar"),
    "PlanPathDijkstra_HomeServer01": planner("dijkstra"),
    "NavigateToPlace_P3DX01": navigate_to_place,
    "NavigateToPerson_P3DX01": navigate_to_person,
    "DeliverObject_P3DX01": deliver,
}


def implementations() -> Registry:
    """Every simulated component, by its service IRI."""
    registry = Registry()
    for name, work in IMPLEMENTATIONS.items():
        registry.add(SVC + name, _maker(work))
    return registry


def _maker(work: Work) -> Callable[[str], Component]:
    return lambda iri: SimComponent(iri, work)


# -- the environment ------------------------------------------------------------------------------


class SimEnvironment:
    """The pybullet home as an execution environment for ``actions.runner.run_task``."""

    def __init__(self, world: HomeWorld, kb: KnowledgeBase) -> None:
        self.world = world
        self.kb = kb
        self.registry = implementations()
        self.context = SimContext(world, kb)

    def clock(self) -> float:
        return self.world.time

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        """The world's thing for each input a requirement gives, chosen by the input's class."""
        values: dict[str, Any] = {}
        for step in plan.steps:
            for binding in step.inputs:
                source = binding.source
                if source.step is not None or source.name in values:
                    continue
                requirement = requirements.get(source.requirement or "")
                types = [p.type for p in requirement.inputs if p.name == source.name] if requirement else []
                for concept in types:
                    if concept in GIVEN_BY_TYPE:
                        values[source.name] = GIVEN_BY_TYPE[concept]
        return values

    def verify(self, step: PlanStep, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        """Check a (class-level) statement against the simulated world, for the things at hand."""
        world, predicate = self.world, statement.predicate.removeprefix(HOME)
        subject, obj = statement.subject.removeprefix(HOME), statement.object.removeprefix(HOME)
        model_name = self.context.grasp.model.name if self.context.grasp is not None else None
        if predicate == "isLocalisedIn":
            estimate = outputs.get("robotLocation")
            if not isinstance(estimate, RobotPoseEstimate):
                return False
            truth = world.base_pose()
            return math.hypot(estimate.x - truth.x, estimate.y - truth.y) <= LOCALISATION_TOLERANCE
        if predicate == "isNear" and obj == "Person":
            return pred.base_near_person(world)
        if predicate == "isNear" and subject == "Gripper":
            return model_name is not None and pred.gripper_near(world, self.context.arm, model_name)
        if predicate == "isNear":
            return pred.base_near(world, HANDOVER_POSE, heading=True)
        if predicate == "isGraspedBy":
            return model_name is not None and pred.is_grasped(world, model_name, self.context.arm)
        if predicate == "isAbove":
            region = self.context.region
            return model_name is not None and region is not None and pred.object_above_region(world, model_name, region)
        if predicate == "isLocated" and obj == "BelowOfTap":
            return pred.cup_below_tap(world)
        if predicate == "isLocated":
            region = self.context.region
            return model_name is not None and region is not None and pred.object_located_in(world, model_name, region)
        if predicate == "isLocatedOn" and obj == "RobotPlatform":
            return pred.pen_on_platform(world)
        if predicate == "isWith":
            return pred.pen_with_person(world)
        if predicate == "contains":
            return pred.cup_contains_water(world)
        if predicate == "isPerceivedBy":
            return bool(outputs)
        return None

    def observe(self) -> Observation:
        """Types, the relations that hold now among the world's things, and their positions."""
        world = self.world
        facts: set[tuple[str, str, str]] = set()

        def holds(condition: bool, s: str, p: str, o: str) -> None:
            if condition:
                facts.add((s, HOME + p, o))

        for name in ("Cup", "Pen"):
            on_table = pred.object_located_in(world, name, TABLE) and world.pen_holder != "Person"
            holds(
                on_table and not (name == "Cup" and pred.cup_below_tap(world)),
                WORLD + name,
                "isLocatedOn",
                WORLD + "KitchenTable",
            )
        holds(pred.cup_below_tap(world), WORLD + "Cup", "isLocated", WORLD + "BelowOfTap")
        holds(pred.cup_contains_water(world), WORLD + "Cup", "contains", HOME + "Water")
        holds(pred.pen_on_platform(world), WORLD + "Pen", "isLocatedOn", WORLD + "P3DX01Platform")
        holds(pred.pen_with_person(world), WORLD + "Pen", "isWith", WORLD + "Person")
        holds(pred.base_near_person(world), SVC + "P3DX01", "isNear", WORLD + "Person")
        holds(pred.base_near(world, HANDOVER_POSE), SVC + "P3DX01", "isNear", WORLD + "KitchenTable")
        for iri, body in ((SVC + "P3DX01", "P3DX01"), (WORLD + "Person", "Person")):
            x, y, _ = world.pose(body).position
            room = room_of(float(x), float(y))
            if room is not None:
                holds(True, iri, "isLocated", WORLD + room)
        positions = {}
        for thing, (_, body_name) in THINGS.items():
            if body_name is not None:
                position = world.pose(body_name).position
                positions[thing] = (float(position[0]), float(position[1]), float(position[2]))
        types = {iri: concept for iri, (concept, _) in THINGS.items()}
        return Observation(types, frozenset(facts), positions, world.time)
