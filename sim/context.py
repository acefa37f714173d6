"""What the simulated components share while a plan runs.

One :class:`SimContext` per environment carries the world, the store and what the arms are doing from
one step to the next (the object at hand, its grasp, where it is carried); a skill reports failure with
:class:`SkillFailed`, which fails the step with its reason.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap, local_name
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspPose
from cbrs.sim.hold_choice import GraspChoice
from cbrs.sim.mapping import OccupancyGrid
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.perception import ObjectEstimate
from cbrs.sim.world import HomeWorld


@dataclass
class SimContext:
    """What sim components share: the world, the knowledge base, and what the arms are doing."""

    world: HomeWorld
    kb: KnowledgeBase
    grid: OccupancyGrid | None = None
    focus: str | None = None  # the object an arm last took (by name)
    grasp: GraspPose | None = None  # the grasp pose of the object the arm is working on
    seen: ObjectEstimate | None = None  # where and how it lay when ``grasp`` was computed for it
    arm: ArmSide = ArmSide.LEFT
    region: Region | None = None  # where the carried object goes
    spot: Region | None = None  # the part of ``region`` the arm carrying the object sets it down on
    last_arm: ArmSide | None = None  # the arm that acted last, so a tie goes to the other
    inputs: Mapping[str, Any] = field(default_factory=dict)  # what the running component was given
    belief: PerceivedWorld | None = None  # where the robots believe things are
    designated: frozenset[str] = frozenset()  # the things the running task's inputs name (IRIs)
    acted: bool = False  # a component has run in this world (the checks before a run are done)
    choices: list[GraspChoice] = field(default_factory=list)  # the grasps chosen in this run, in order
    plan: Plan | None = None  # the plan being run, and the values the task gives its steps (``given``)
    given: Mapping[str, Any] = field(default_factory=dict)
    component: str | None = None  # the IRI of the running component
    step: PlanStep | None = None  # the plan's step being run, and every step's inputs known at its start
    known: Mapping[int, Mapping[str, Any]] = field(default_factory=dict)
    looked_for: set[str] = field(default_factory=set)
    """The things (IRIs) a camera looked for by colour for the run's steps and their effects: a run's colour
    warnings are of these and what its plans perceive (``actions.colour_warnings``)."""

    def __post_init__(self) -> None:
        specs = getattr(self.world, "arm_specs", None)  # None: a context for planning alone, with no world
        if specs and self.arm not in specs:
            self.arm = next(iter(specs))  # a robot with one arm: the arm at work is that one

    @property
    def map(self) -> SemanticMap:
        return self.world.map

    @property
    def object(self) -> str | None:
        """The object an arm last took in hand."""
        return self.focus or (self.grasp.model.name if self.grasp is not None else None)


Work = Callable[[SimContext, Mapping[str, Any], str], dict[str, Any]]
"""A skill as a component: (context, inputs, the component's device name) -> outputs."""


class SkillFailed(Exception):
    """A skill reported failure; the message is its reason."""


def check_outcome(outcome: skills.Outcome) -> None:
    if not outcome.succeeded:
        raise SkillFailed(f"{outcome.skill}: {outcome.reason}")


def robot_camera(ctx: SimContext, robot: str) -> str:
    """The camera mounted on a robot (home:mountedOn in the store)."""
    rows = ctx.kb.select("mounted_cameras", {"robot": PREFIXES["svc"] + robot})
    cameras = [local_name(row["device"].value) for row in rows if local_name(row["device"].value) in ctx.world.cameras]
    if not cameras:
        raise SkillFailed(f"no camera is mounted on {robot}")
    return cameras[0]
