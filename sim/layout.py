"""The floor plan and every fixed dimension of the simulated home, in one place.

World frame: metres, z up, origin at the south-west corner of the home. The rooms and the table
match the SEA bounding boxes of ``ontologies/services.ttl``; names follow the ontology
(``LivingRoom``, ``BelowOfTap``, ``CeilingCamera01``, ``P3DX01``...) so the knowledge base can refer
to simulated things by the names it already uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from sim.geometry import Pose2D, Region, Vec3

__all__ = [
    "ARM_MOUNTS",
    "ARM_MOUNT_YAW",
    "BASE_HALF_LENGTH",
    "BASE_HALF_WIDTH",
    "BASE_RADIUS",
    "BASE_START",
    "BELOW_OF_TAP",
    "CAMERAS",
    "CUP_HEIGHT",
    "CUP_RADIUS",
    "CUP_START",
    "DISPENSER",
    "DOORS",
    "HANDOVER_POSE",
    "HOME",
    "KINECT",
    "KINECT_BODY",
    "KINECT_MAST",
    "MAP_RESOLUTION",
    "MARKER_HEIGHT",
    "MARKER_OFFSET",
    "MARKER_PATCH",
    "PEN_LENGTH",
    "PEN_START",
    "PEN_START_YAW",
    "PEN_WIDTH",
    "PERSON_HAND_HEIGHT",
    "PERSON_RADIUS",
    "PERSON_START",
    "PLATFORM_HEIGHT",
    "ROOMS",
    "SHIRT_BOTTOM",
    "SHIRT_RADIUS",
    "SHIRT_TOP",
    "SPOUT",
    "TABLE",
    "TABLE_HEIGHT",
    "TAP_LEVER",
    "TAP_OUTLET",
    "TORSO",
    "WALLS",
    "WALL_HEIGHT",
    "WALL_THICKNESS",
    "CameraSpec",
    "WallSpec",
    "room_of",
]

# --- the home and its rooms -------------------------------------------------------------------

HOME = Region("Home", 0.0, 10.0, 0.0, 9.0)
ROOMS: dict[str, Region] = {
    "LivingRoom": Region("LivingRoom", 0.0, 6.0, 0.0, 5.0),
    "Kitchen": Region("Kitchen", 6.0, 10.0, 0.0, 5.0),
    "Bedroom": Region("Bedroom", 0.0, 6.0, 5.0, 9.0),
}
"""The north-east corner (x 6-10, y 5-9) belongs to no room: it is walled off with no door."""

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
TABLE = Region("TableTop", 7.0, 8.5, 3.0, 4.5, TABLE_HEIGHT, TABLE_HEIGHT)

DISPENSER = Region("WaterDispenser", 7.66, 7.84, 3.42, 3.62, TABLE_HEIGHT, 1.10)
"""The dispenser's body, standing on the table; its spout sticks out towards the dual-arm robot."""
SPOUT = Region("Spout", 7.73, 7.77, 3.29, 3.42, 0.95, 0.98)
TAP_LEVER = Region("TapLever", 7.72, 7.78, 3.27, 3.29, 0.94, 0.99)
"""Pushing the lever towards the dispenser (+y) opens the tap; a spring pushes it back."""
TAP_OUTLET: Vec3 = (7.75, 3.31, 0.95)
"""Where the water leaves the spout: the axis of the region below the tap."""
BELOW_OF_TAP = Region("BelowOfTap", 7.725, 7.775, 3.285, 3.335, TABLE_HEIGHT, SPOUT.zmin)
"""A cup whose centre is in this 5 cm square on the table catches the water: the stream (on the
outlet axis) then falls at most 2.5 cm from the cup's axis, inside its 3 cm radius."""

CUP_RADIUS = 0.03
CUP_HEIGHT = 0.10
CUP_START = (7.45, 3.32)
PEN_LENGTH = 0.14
PEN_WIDTH = 0.016
PEN_START = (8.07, 3.30)
PEN_START_YAW = 0.0

# --- the dual-arm robot and its Kinect ---------------------------------------------------------

TORSO = Region("CytonDualArm01", 7.5, 8.0, 2.40, 2.70, 0.0, 0.65)
ARM_MOUNTS: dict[str, Vec3] = {"left": (7.57, 2.55, 0.65), "right": (7.93, 2.55, 0.65)}
"""Where each arm's base sits on the torso; both arms face the table (+y)."""
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
BASE_START = Pose2D(3.0, 1.5, 0.0)
HANDOVER_POSE = Pose2D(8.5, 2.2, 0.0)
"""Where the base parks so that the right arm can load its platform (south-east of the torso)."""

# --- the person -------------------------------------------------------------------------------

PERSON_START = (2.0, 3.6)
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


CAMERAS: dict[str, CameraSpec] = {
    "CeilingCamera01": CameraSpec("CeilingCamera01", (4.5, 2.5, 4.5), (4.5, 2.5, 0.0), (0.0, 1.0, 0.0)),
    "CeilingCamera02": CameraSpec("CeilingCamera02", (7.0, 2.5, 4.5), (7.0, 2.5, 0.0), (0.0, 1.0, 0.0)),
}
"""Both look straight down from 4.5 m with a 90 x 106 degree view: each sees the base's start pose
in the living room and its hand-over pose in the kitchen, so either can stand in for the other."""
KINECT = CameraSpec(
    "Kinect01", (7.75, 2.45, 1.45), (7.75, 3.40, 0.75), (0.0, 0.0, 1.0), fov_deg=45.0, near=0.3, far=4.0
)
"""The Kinect on a mast at the back of the torso, looking down at the front of the table."""
KINECT_BODY = Region("Kinect01", 7.62, 7.88, 2.42, 2.48, 1.425, 1.475)
"""The Kinect's box; the camera sits inside it (its 0.3 m near plane hides the box)."""
KINECT_MAST = Region("KinectMast", 7.735, 7.765, 2.435, 2.465, TORSO.zmax, KINECT_BODY.zmin)

MAP_RESOLUTION = 0.05


def room_of(x: float, y: float) -> str | None:
    """The room a floor point is in (the ontology's LocateRoomOfPosition), or None outside every room."""
    for name, room in ROOMS.items():
        if room.contains_xy(x, y):
            return name
    return None
