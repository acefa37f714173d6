"""The pybullet home of paper section 6.2 and what the robots can do in it.

A library (no CLI, no knowledge base): ``HomeWorld`` builds the home; ``cameras`` render images;
``perception`` localises the base, tracks the person and recognises objects from those images;
``mapping`` and ``planning`` are the map server and the path planners; ``skills`` are the robots'
actions, each returning an ``Outcome``; ``predicates`` check the knowledge base's statements against
the simulated world. (The paper's two scenarios as fixed skill sequences, the reference runs, are
in tests/reference_scenarios.py.)
See docs/simulation.md.
"""

from __future__ import annotations

import cbrs.sim.quiet  # noqa: F401  (first: keeps pybullet's banner off stdout)
from cbrs.sim.arms import ArmSide
from cbrs.sim.errors import (
    CameraUnavailableError,
    GraspMisfitError,
    GraspTooDeepError,
    GraspTooWideError,
    ImageSizeError,
    MapError,
    MovesRefusedError,
    NoFreeCellError,
    NoPathError,
    NotVisibleError,
    OutsideMapError,
    PerceptionError,
    SimulationError,
    UnknownAlgorithmError,
    UnknownColourError,
    UnknownEntityError,
    UnknownPlaceError,
    WorldClosedError,
)
from cbrs.sim.geometry import Pose2D, Pose3D, Region
from cbrs.sim.grasping import GraspPose, ObjectModel, compute_grasp_pose
from cbrs.sim.mapping import OccupancyGrid, build_occupancy_grid
from cbrs.sim.perception import (
    ObjectEstimate,
    PersonEstimate,
    RobotPoseEstimate,
    locate_robot,
    recognise_object,
    track_person,
)
from cbrs.sim.planning import PlannedPath, plan_path
from cbrs.sim.skills import Outcome
from cbrs.sim.world import HomeWorld, open_world

__all__ = [
    "ArmSide",
    "CameraUnavailableError",
    "GraspMisfitError",
    "GraspPose",
    "GraspTooDeepError",
    "GraspTooWideError",
    "HomeWorld",
    "ImageSizeError",
    "MapError",
    "MovesRefusedError",
    "NoFreeCellError",
    "NoPathError",
    "NotVisibleError",
    "ObjectEstimate",
    "ObjectModel",
    "OccupancyGrid",
    "Outcome",
    "OutsideMapError",
    "PerceptionError",
    "PersonEstimate",
    "PlannedPath",
    "Pose2D",
    "Pose3D",
    "Region",
    "RobotPoseEstimate",
    "SimulationError",
    "UnknownAlgorithmError",
    "UnknownColourError",
    "UnknownEntityError",
    "UnknownPlaceError",
    "WorldClosedError",
    "build_occupancy_grid",
    "compute_grasp_pose",
    "locate_robot",
    "open_world",
    "plan_path",
    "recognise_object",
    "track_person",
]
