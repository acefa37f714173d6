"""The simulator's generic models: the person's body, the camera model and the grid map's cell size.

What the home holds and where (rooms, walls, furniture, the dispenser, objects, the robots' bodies,
arms, platform and marker, the cameras' poses) is the semantic map's, in the store
(``ontologies/world.ttl``); the world is built from it. What stays here is no particular thing of the
home: the proportions of the mannequin that stands in for a person, and model defaults.
"""

from __future__ import annotations

from dataclasses import dataclass

from cbrs.sim.geometry import Vec3

__all__ = [
    "DOWNWARD_IMAGE_SIZE",
    "MAP_RESOLUTION",
    "OTHER_IMAGE_SIZE",
    "PERSON_HAND_HEIGHT",
    "PERSON_RADIUS",
    "SHIRT_BOTTOM",
    "SHIRT_RADIUS",
    "SHIRT_TOP",
    "CameraSpec",
]

# --- the person: an adult mannequin (legs, a shirt the cameras find by its colour, a head) ------

PERSON_RADIUS = 0.18
SHIRT_RADIUS = 0.22
SHIRT_BOTTOM = 0.85
SHIRT_TOP = 1.45
"""Shoulder height: the plane the person tracker intersects pixel rays with."""
PERSON_HAND_HEIGHT = 0.95


# --- cameras ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class CameraSpec:
    """A pinhole camera: where it is, where it looks, its image size and vertical field of view."""

    name: str
    eye: Vec3
    target: Vec3
    up: Vec3
    width: int = 320
    height: int = 240
    fov_deg: float = 90.0
    near: float = 0.2
    far: float = 8.0


DOWNWARD_IMAGE_SIZE = (320, 240)
"""Width and height (pixels) of a camera that looks straight down: the ceiling cameras, 4.5 m up
with a 90 degree lens, where a pixel is 2.8 cm of floor. Locating the base's marker needs that: at
240 x 180 the heading at seed 2's start came out 0.12 rad off (0.09 at this size), past the tests' 0.10."""
OTHER_IMAGE_SIZE = (192, 144)
"""Width and height (pixels) of any other camera: the robot's RGB-D camera over the table, 1-1.5 m
from what it looks at with a 45 degree lens, where a pixel is 3.5-5 mm. Over seeds 0-19 it finds
the cup within 0.72 cm, the pen within 0.19 cm and the pen's yaw within 0.021 rad (0.39 cm, 0.10 cm
and 0.018 rad at 320 x 240; at 160 x 120 the yaw was off by up to 0.047 rad, near the tests' 0.05),
and a frame costs about 15 ms instead of 33-38."""

MAP_RESOLUTION = 0.05
"""The occupancy grid's cell size (m)."""
