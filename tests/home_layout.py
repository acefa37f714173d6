"""The bundled home's places and start poses, read from its semantic map (ontologies/world.ttl), for
tests that drive skills directly: nothing here is a second copy of the map."""

from __future__ import annotations

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import Thing, local_name
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.layout import CameraSpec
from cbrs.sim.scene import bundled_map

WORLD, HOME = PREFIXES["world"], PREFIXES["home"]
_MAP = bundled_map()


def region(name: str) -> Region:
    """A thing of the map as a region (its name is the individual's local name)."""
    thing: Thing = _MAP.things[WORLD + name]
    b = thing.box
    return Region(thing.name, b.min_x, b.max_x, b.min_y, b.max_y, b.min_z, b.max_z)


def start(name: str) -> tuple[float, float]:
    obj = _MAP.objects[WORLD + name]
    return (obj.start.x, obj.start.y)


_dock = _MAP.things[WORLD + "KitchenTable"].dock
assert _dock is not None
HANDOVER_POSE = Pose2D(_dock.x, _dock.y, _dock.yaw)
TABLE = region("KitchenTableTop")
BELOW_OF_TAP = region("BelowOfTap")
CUP_START, PEN_START = start("Cup"), start("Pen")
_person = next(iter(_MAP.people.values()))
PERSON_START = (_person.start.x, _person.start.y)
_robot = next(iter(_MAP.robots.values()))
BASE_START = Pose2D(_robot.start.x, _robot.start.y, _robot.start.yaw)
ARM_MOUNTS = {arm.side: arm.mount for arm in _MAP.arms.values()}
ARM_FACING = {arm.side: arm.yaw for arm in _MAP.arms.values()}
ROOMS = {local_name(iri): region(local_name(iri)) for iri in _MAP.rooms}
CAMERAS = {
    cam.name: CameraSpec(
        cam.name, cam.position, (cam.position[0], cam.position[1], 0.0), (0.0, 1.0, 0.0), fov_deg=cam.fov
    )
    for cam in _MAP.cameras.values()
    if cam.looks_down
}
"""The ceiling cameras (each looks straight down, the top of its image to the north)."""
_dispenser = next(iter(_MAP.dispensers.values()))
TAP_LEVER = region(_dispenser.lever.name)
WALLS = [region(local_name(iri)) for iri in sorted(_MAP.walls)]


def room_of(x: float, y: float) -> str | None:
    """The room a point of the floor is in, by the map's rooms."""
    return next((name for name, room in ROOMS.items() if room.contains_xy(x, y)), None)


__all__ = [
    "ARM_FACING",
    "ARM_MOUNTS",
    "BASE_START",
    "BELOW_OF_TAP",
    "CAMERAS",
    "CUP_START",
    "HANDOVER_POSE",
    "PEN_START",
    "PERSON_START",
    "ROOMS",
    "TABLE",
    "TAP_LEVER",
    "WALLS",
    "local_name",
    "room_of",
]
