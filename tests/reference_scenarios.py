"""The two scenarios of paper section 6.2 as fixed sequences of skills (no planner, no knowledge base).

They are the reference runs: the composition engine should arrive at the same sequences. Each step
is recorded as an ``Outcome``; a scenario stops at the first failed step.

1. ``serve_cup`` (RobotArmServeACup): find the red cup with the Kinect, approach it, pick it up,
   carry it above the region below the tap, put it down there, fill it from the tap.
2. ``fetch_pen`` (FetchMyPen): localise the base with a ceiling camera, get the grid map, plan to the
   hand-over pose, drive there, let the dual-arm robot load the pen onto the platform, track the
   person, localise again, plan to a point next to the person, drive there, deliver the pen.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.errors import SimulationError
from cbrs.sim.grasping import ObjectModel, compute_grasp_pose
from cbrs.sim.mapping import OccupancyGrid, build_occupancy_grid
from cbrs.sim.perception import RobotPoseEstimate, locate_robot, recognise_object, track_person
from cbrs.sim.planning import approach_point, plan_path
from cbrs.sim.skills import Outcome
from cbrs.sim.world import HomeWorld
from tests.home_layout import ARM_FACING, ARM_MOUNTS, BELOW_OF_TAP, HANDOVER_POSE, TAP_LEVER

__all__ = ["PERSON_APPROACH_DISTANCE", "ScenarioResult", "fetch_pen", "serve_cup"]

PERSON_APPROACH_DISTANCE = 0.75
"""The base stops this far from the person's centre: outside their inflated footprint on the map
(0.22 m shirt + 0.30 m base radius), inside the 1 m of ``predicates.NEAR_PERSON_DISTANCE``."""

T = TypeVar("T")


@dataclass(frozen=True)
class ScenarioResult:
    name: str
    seed: int
    succeeded: bool
    steps: tuple[Outcome, ...]
    sim_seconds: float

    @property
    def failure(self) -> Outcome | None:
        return next((step for step in self.steps if not step.succeeded), None)


@dataclass
class _Run:
    world: HomeWorld
    name: str
    started: float = 0.0
    steps: list[Outcome] = field(default_factory=list)

    def act(self, outcome: Outcome) -> bool:
        self.steps.append(outcome)
        return outcome.succeeded

    def sense(self, skill: str, compute: Callable[[], T]) -> T | None:
        """Run a perception or planning step; its typed error becomes a failed outcome."""
        start = self.world.time
        try:
            value = compute()
        except SimulationError as error:
            self.steps.append(Outcome(skill, False, str(error), start, self.world.time))
            return None
        self.steps.append(Outcome(skill, True, "", start, self.world.time))
        return value

    def result(self) -> ScenarioResult:
        ok = bool(self.steps) and all(step.succeeded for step in self.steps)
        return ScenarioResult(self.name, self.world.seed, ok, tuple(self.steps), self.world.time - self.started)


def serve_cup(world: HomeWorld, arm: ArmSide = ArmSide.LEFT, tap_arm: ArmSide = ArmSide.RIGHT) -> ScenarioResult:
    """Scenario 1, RobotArmServeACup."""
    run = _Run(world, "RobotArmServeACup", world.time)
    if not run.act(skills.clear_view(world)):
        return run.result()
    model = ObjectModel.of(world.objects["Cup"])
    cup = run.sense(
        "RecogniseObjectByColour", lambda: recognise_object(world.camera("Kinect01").capture(), model.colour)
    )
    if cup is None:
        return run.result()
    grasp = compute_grasp_pose(model, cup.position, cup.yaw, ARM_MOUNTS[arm.value], ARM_FACING[arm.value])
    steps: list[Callable[[], Outcome]] = [
        lambda: skills.approach_object(world, arm, grasp),
        lambda: skills.pick_up_object(world, arm, grasp),
        lambda: skills.carry_object(world, arm, BELOW_OF_TAP),
        lambda: skills.put_down_object(world, arm, BELOW_OF_TAP),
        lambda: skills.fill_cup_from_tap(world, tap_arm, TAP_LEVER, "Cup"),
    ]
    for step in steps:
        if not run.act(step()):
            break
    return run.result()


def fetch_pen(
    world: HomeWorld,
    camera: str = "CeilingCamera01",
    algorithm: str = "astar",
    person_camera: str = "CeilingCamera01",
    arm: ArmSide = ArmSide.RIGHT,
    grid: OccupancyGrid | None = None,
) -> ScenarioResult:
    """Scenario 2, FetchMyPen. ``camera`` localises the base, ``person_camera`` tracks the person (only
    CeilingCamera01 sees the living room's far side); ``grid`` reuses a map instead of measuring one."""
    run = _Run(world, "FetchMyPen", world.time)

    def locate() -> RobotPoseEstimate | None:
        return run.sense(
            f"LocateMobileRobot_{camera}", lambda: locate_robot(world.camera(camera).capture(), world.marker_model)
        )

    start = locate()
    if start is None:
        return run.result()
    the_map = grid if grid is not None else run.sense("ProvideGridMap", lambda: build_occupancy_grid(world))
    if the_map is None:
        return run.result()
    path = run.sense(
        f"PlanPath_{algorithm}", lambda: plan_path(the_map, (start.x, start.y), HANDOVER_POSE.xy, algorithm)
    )
    if path is None or not run.act(skills.navigate_to_place(world, path, HANDOVER_POSE)):
        return run.result()
    parked = locate()
    if parked is None:
        return run.result()
    model = ObjectModel.of(world.objects["Pen"])
    pen = run.sense(
        "RecogniseObjectByColour", lambda: recognise_object(world.camera("Kinect01").capture(), model.colour)
    )
    reach = world.arm_specs[arm].reach
    if pen is None or not run.act(skills.hand_over_onto_platform(world, pen, parked, arm, model, reach)):
        return run.result()
    person = run.sense(f"TrackPerson_{person_camera}", lambda: track_person(world.camera(person_camera).capture()))
    if person is None:
        return run.result()
    here = locate()
    if here is None:
        return run.result()
    goal = approach_point((person.x, person.y), (here.x, here.y), PERSON_APPROACH_DISTANCE)
    path = run.sense(f"PlanPath_{algorithm}", lambda: plan_path(the_map, (here.x, here.y), goal, algorithm))
    if path is None or not run.act(skills.navigate_to_person(world, path, person)):
        return run.result()
    run.act(skills.deliver_object(world))
    return run.result()
