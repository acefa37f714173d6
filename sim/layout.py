"""The floor plan and every fixed dimension of the simulated home, in one place.

World frame: metres, z up, origin at the south-west corner of the home. The rooms and the table
match the SEA bounding boxes of ``ontologies/services.ttl``; names follow the ontology
(``LivingRoom``, ``BelowOfTap``, ``CeilingCamera01``, ``P3DX01``...) so the knowledge base can refer
to simulated things by the names it already uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sim.geometry import Region, Vec3

__all__ = [
    "ARM_MOUNT_YAW",
    "BASE_HALF_LENGTH",
    "BASE_HALF_WIDTH",
    "BASE_RADIUS",
    "DISPENSER",
    "DOORS",
    "HOME",
    "KINECT",
    "KINECT_BODY",
    "KINECT_MAST",
    "MAP_RESOLUTION",
    "MARKER_HEIGHT",
    "MARKER_OFFSET",
    "MARKER_PATCH",
    "PERSON_HAND_HEIGHT",
    "PERSON_RADIUS",
    "PLATFORM_HEIGHT",
    "SHIRT_BOTTOM",
    "SHIRT_RADIUS",
    "SHIRT_TOP",
    "SPOUT",
    "TABLE_HEIGHT",
    "TAP_LEVER",
    "TAP_OUTLET",
    "TORSO",
    "WALLS",
    "WALL_HEIGHT",
    "WALL_THICKNESS",
    "CameraSpec",
    "WallSpec",
]

# --- the home and its rooms -------------------------------------------------------------------

HOME = Region("Home", 0.0, 10.0, 0.0, 9.0)
# The rooms, the furniture, the objects, the person, the arms' mounts, the base's start and the
# ceiling cameras are in the semantic map (ontologies/world.ttl), not here. The north-east corner
# (x 6-10, y 5-9) belongs to no room: it is walled off with no door.

WALL_THICKNESS = 0.10
WALL_HEIGHT = 1.0
"""Half-height partitions: the ceiling cameras see over them into the next room (see docs/simulation.md)."""


@dataclass(frozen=True)
class WallSpec:
    """A straight wall on its centre line from (x0, y0) to (x1, y1)."""

    name: str
    x0: float
    y0: float
    x1: float
    y1: float


# Door gaps (1 m wide) are the spaces between the segments: LivingRoom-Kitchen at x = 6, y 1.6-2.6;
# LivingRoom-Bedroom at y = 5, x 2.0-3.0.
WALLS: tuple[WallSpec, ...] = (
    WallSpec("WallSouth", 0.0, 0.0, 10.0, 0.0),
    WallSpec("WallNorth", 0.0, 9.0, 10.0, 9.0),
    WallSpec("WallWest", 0.0, 0.0, 0.0, 9.0),
    WallSpec("WallEast", 10.0, 0.0, 10.0, 9.0),
    WallSpec("WallLivingKitchenSouth", 6.0, 0.0, 6.0, 1.6),
    WallSpec("WallLivingKitchenNorth", 6.0, 2.6, 6.0, 5.0),
    WallSpec("WallLivingBedroomWest", 0.0, 5.0, 2.0, 5.0),
    WallSpec("WallLivingBedroomEast", 3.0, 5.0, 6.0, 5.0),
    WallSpec("WallKitchenNorth", 6.0, 5.0, 10.0, 5.0),
    WallSpec("WallBedroomEast", 6.0, 5.0, 6.0, 9.0),
)
DOORS: dict[str, Region] = {
    "LivingRoomKitchenDoor": Region("LivingRoomKitchenDoor", 5.95, 6.05, 1.6, 2.6),
    "LivingRoomBedroomDoor": Region("LivingRoomBedroomDoor", 2.0, 3.0, 4.95, 5.05),
}

# --- the kitchen table, the water dispenser and the objects on the table -----------------------

TABLE_HEIGHT = 0.75

DISPENSER = Region("WaterDispenser", 7.66, 7.84, 3.42, 3.62, TABLE_HEIGHT, 1.10)
"""The dispenser's body, standing on the table; its spout sticks out towards the dual-arm robot."""
SPOUT = Region("Spout", 7.73, 7.77, 3.29, 3.42, 0.95, 0.98)
TAP_LEVER = Region("TapLever", 7.72, 7.78, 3.27, 3.29, 0.94, 0.99)
"""Pushing the lever towards the dispenser (+y) opens the tap; a spring pushes it back."""
TAP_OUTLET: Vec3 = (7.75, 3.31, 0.95)
"""Where the water leaves the spout: the axis of the region below the tap."""


# --- the dual-arm robot and its Kinect ---------------------------------------------------------

TORSO = Region("CytonDualArm01", 7.5, 8.0, 2.40, 2.70, 0.0, 0.65)
ARM_MOUNT_YAW = math.pi / 2.0

# --- the mobile base (a Pioneer 3-DX with a carrying platform) ---------------------------------

BASE_HALF_LENGTH = 0.225
BASE_HALF_WIDTH = 0.19
BASE_RADIUS = 0.30
"""Circumscribed radius of the footprint (0.294 m) rounded up: the obstacle inflation of the map."""
PLATFORM_HEIGHT = 0.45
"""Height of the platform's top surface, where the pen is put."""
MARKER_HEIGHT = PLATFORM_HEIGHT + 0.002
"""Height of the colour marker's top faces, the plane the localiser intersects pixel rays with."""
MARKER_OFFSET = 0.165
"""The green (front) and magenta (rear) marker patches sit this far ahead of and behind the centre."""
MARKER_PATCH = (0.12, 0.30)
"""Size of each marker patch along and across the base (m)."""

# --- the person -------------------------------------------------------------------------------

PERSON_RADIUS = 0.18
SHIRT_RADIUS = 0.22
SHIRT_BOTTOM = 0.85
SHIRT_TOP = 1.45
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


KINECT = CameraSpec(
    "Kinect01", (7.75, 2.45, 1.45), (7.75, 3.40, 0.75), (0.0, 0.0, 1.0), fov_deg=45.0, near=0.3, far=4.0
)
"""The Kinect on a mast at the back of the torso, looking down at the front of the table."""
KINECT_BODY = Region("Kinect01", 7.62, 7.88, 2.42, 2.48, 1.425, 1.475)
"""The Kinect's box; the camera sits inside it (its 0.3 m near plane hides the box)."""
KINECT_MAST = Region("KinectMast", 7.735, 7.765, 2.435, 2.465, TORSO.zmax, KINECT_BODY.zmin)

MAP_RESOLUTION = 0.05
