"""What a camera of the semantic map sees, from the map alone: the camera model the simulation renders
with, kept free of pybullet and numpy so that the home's picture (:mod:`cbrs.home_plan`) can draw a
camera's view in a base install and agree with the simulation's images.

A camera is a pinhole whose vertical field of view is its ``home:fieldOfView``; its image is
:data:`DOWNWARD_IMAGE_SIZE` when it looks straight down (the top of the image towards its ``home:yaw``)
and :data:`OTHER_IMAGE_SIZE` otherwise (the top of the image up). ``sim.world`` builds its cameras from
:func:`image_up` and :func:`default_image_size`, ``sim.cameras`` its intrinsics from :func:`focal_length`;
:func:`floor_view` is where the rays through the image's corners meet a horizontal plane.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from cbrs.kb.semantic_map import Box, Camera, SemanticMap, local_name

__all__ = [
    "DOWNWARD_IMAGE_SIZE",
    "HIDDEN_BY",
    "MAX_HIDDEN",
    "OTHER_IMAGE_SIZE",
    "Occluder",
    "default_image_size",
    "floor_view",
    "focal_length",
    "hidden",
    "image_up",
    "occluders",
    "sight_blocked",
]

DOWNWARD_IMAGE_SIZE = (320, 240)
"""Width and height (pixels) of a camera that looks straight down: the ceiling cameras, 4.5 m up
with a 90 degree lens, where a pixel is 3.75 cm of floor (4.5 m over a focal length of 120 pixels).
Locating the base's marker needs that: at 240 x 180 the heading at seed 2's start came out 0.12 rad off
(0.09 at this size), past the tests' 0.10."""
OTHER_IMAGE_SIZE = (192, 144)
"""Width and height (pixels) of any other camera: the robot's RGB-D camera over the table, 1-1.5 m
from what it looks at with a 45 degree lens, where a pixel is 3.5-5 mm. Over seeds 0-19 it finds
the cup within 0.72 cm, the pen within 0.19 cm and the pen's yaw within 0.021 rad (0.39 cm, 0.10 cm
and 0.018 rad at 320 x 240; at 160 x 120 the yaw was off by up to 0.047 rad, near the tests' 0.05),
and a frame costs about 15 ms instead of 33-38."""

MAX_HIDDEN = Camera.occlusion_tolerance  # the default of a camera whose map says nothing: 0
"""The largest fraction of the sight lines to a thing's outline that the map's solid boxes may cut for a
camera still to see the thing whole (:func:`hidden`). None, by default: perception refuses a blob the
image's border cuts, and a blob a cupboard cuts is as wrong a measure of where the thing is (its centre
moves towards the part in view). A box of the map is its piece's bounding box (a table's legs and the
space between them are one solid block), so a lab whose map boxes are coarser than what they stand for
may allow a part, camera by camera (``home:occlusionTolerance``, :attr:`Camera.occlusion_tolerance`)."""
HIDDEN_BY = "sight lines to the points outlining it pass through"
"""The words of :func:`hidden`'s reason before the boxes it names: how a caller tells that reason."""
SURFACE = 0.001
"""How far (m) a sight line may run inside a box at its far end and still pass: an object's bottom rests
on its support's top face, where the line to a point of its bottom rim ends."""

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Occluder:
    """A solid box of the map that a camera cannot see through: a wall, a piece of furniture, an
    appliance or a robot's body (``iri``, its extent)."""

    iri: str
    box: Box


def occluders(semantic_map: SemanticMap) -> list[Occluder]:
    """The map's solid boxes, which hide what is behind them from a camera: its walls, furniture,
    appliances (a dispenser's body) and robots' bodies (the dual-arm robot's torso). Not the movable
    objects (small, and wherever a run has put them), the person, the mobile base (it drives) or a
    camera's housing (its own eye is inside it)."""
    smap = semantic_map
    solid = smap.walls | smap.furniture | smap.bodies | {d.iri for d in smap.dispensers.values()}
    solid -= smap.robots.keys() | smap.cameras.keys()
    return [Occluder(iri, smap.things[iri].box) for iri in sorted(solid) if iri in smap.things]


def sight_blocked(eye: Sequence[float], point: Sequence[float], boxes: Iterable[Occluder]) -> list[str]:
    """The occluders the straight line from ``eye`` to ``point`` runs through, in the map's order: an
    occluder counts when the line enters its box's inside (a slab test, axis by axis) more than
    :data:`SURFACE` before the point. A line that only grazes a face, or ends on one, passes."""
    delta = [p - e for p, e in zip(point, eye, strict=True)]
    length = math.sqrt(sum(d * d for d in delta))
    if length == 0.0:
        return []
    end = 1.0 - SURFACE / length
    cut = []
    for occluder in boxes:
        b = occluder.box
        low, high = 0.0, end
        for start, step, lo, hi in zip(
            eye, delta, (b.min_x, b.min_y, b.min_z), (b.max_x, b.max_y, b.max_z), strict=True
        ):
            if step == 0.0:
                if not lo < start < hi:
                    low, high = 1.0, 0.0
                    break
                continue
            t0, t1 = sorted(((lo - start) / step, (hi - start) / step))
            low, high = max(low, t0), min(high, t1)
            if low >= high:
                break
        if low < high:
            cut.append(occluder.iri)
    return cut


def hidden(
    eye: Sequence[float],
    points: Iterable[Sequence[float]],
    boxes: Sequence[Occluder],
    max_hidden: float = MAX_HIDDEN,
) -> str:
    """Why a camera whose eye is at ``eye`` does not see whole what ``points`` outline (the points the
    border check projects), because solid boxes of the map stand between: empty when it does. Each
    point's sight line is tested (:func:`sight_blocked`); the thing is hidden when more than
    ``max_hidden`` of the lines (a fraction, :data:`MAX_HIDDEN` by default) are cut. The reason names
    the boxes that cut them, the most first."""
    if not 0.0 <= max_hidden < 1.0:
        raise ValueError(f"max_hidden is a fraction from 0 up to (not including) 1, not {max_hidden!r}")
    outline = list(points)
    cutting: dict[str, int] = {}
    blocked = 0
    for point in outline:
        cut = sight_blocked(eye, point, boxes)
        blocked += bool(cut)
        for iri in cut:
            cutting[iri] = cutting.get(iri, 0) + 1
    if not outline or blocked <= max_hidden * len(outline):
        return ""
    named = ", ".join(
        f"{local_name(iri)} ({count})" for iri, count in sorted(cutting.items(), key=lambda item: (-item[1], item[0]))
    )
    return f"{blocked} of the {len(outline)} {HIDDEN_BY} {named}, more than the {max_hidden:.0%} allowed"


def default_image_size(camera: Camera) -> tuple[int, int]:
    """The image width and height the simulation renders ``camera`` at unless told otherwise."""
    return DOWNWARD_IMAGE_SIZE if camera.looks_down else OTHER_IMAGE_SIZE


def image_up(camera: Camera) -> Vec3:
    """The world direction the top of ``camera``'s image faces: its yaw when it looks straight down
    (where "up" is no help), else straight up."""
    return (math.cos(camera.yaw), math.sin(camera.yaw), 0.0) if camera.looks_down else (0.0, 0.0, 1.0)


def focal_length(height: int, fov_deg: float) -> float:
    """The focal length (pixels) of a pinhole image ``height`` pixels high with a vertical field of view
    of ``fov_deg`` degrees (pybullet's projection's)."""
    return (height / 2.0) / math.tan(math.radians(fov_deg) / 2.0)


def floor_view(camera: Camera, size: tuple[int, int] | None = None, z: float = 0.0) -> list[tuple[float, float]] | None:
    """The corners (x, y) of the part of the horizontal plane at height ``z`` that ``camera`` sees, in
    the order of the image's corners (top left, top right, bottom right, bottom left), for an image of
    ``size`` (:func:`default_image_size` if not given). None when a corner's ray does not meet the
    plane, or meets it outside the camera's range (nearer than ``home:minRange``, farther along its
    axis than ``home:maxRange``): the camera sees no whole patch of it."""
    width, height = size or default_image_size(camera)
    forward = camera.direction
    right = _unit(_cross(forward, image_up(camera)))
    down = _cross(forward, right)
    half_v = (height / 2.0) / focal_length(height, camera.fov)
    half_h = (width / 2.0) / focal_length(height, camera.fov)
    eye = camera.position
    corners = []
    for across, along in ((-half_h, -half_v), (half_h, -half_v), (half_h, half_v), (-half_h, half_v)):
        ray = tuple(f + across * r + along * d for f, r, d in zip(forward, right, down, strict=True))
        if ray[2] >= 0.0:
            return None
        depth = (z - eye[2]) / ray[2]  # along the optical axis: the ray's forward part is 1
        if not camera.near <= depth <= camera.far:
            return None
        corners.append((eye[0] + depth * ray[0], eye[1] + depth * ray[1]))
    return corners


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(v: Vec3) -> Vec3:
    norm = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    return (v[0] / norm, v[1] / norm, v[2] / norm)
