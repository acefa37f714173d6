"""The simulator's generic models: the person's body, the camera model and the grid map's cell size.

What the home holds and where (rooms, walls, furniture, the dispenser, objects, the robots' bodies,
arms, platform and marker, the cameras' poses) is the semantic map's, in the store
(``ontologies/world.ttl``); the world is built from it. What stays here is no particular thing of the
home: the proportions of the mannequin that stands in for a person, and model defaults.
"""

from __future__ import annotations

from dataclasses import dataclass

from cbrs.kb.camera_view import DOWNWARD_IMAGE_SIZE, MAX_HIDDEN, OTHER_IMAGE_SIZE  # the camera model, shared
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
    max_hidden: float = MAX_HIDDEN
    """The fraction of sight lines to a thing the map's boxes may cut with the thing still seen whole."""


MAP_RESOLUTION = 0.05
"""The occupancy grid's cell size (m)."""
