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

from cbrs.kb.semantic_map import Camera

__all__ = ["DOWNWARD_IMAGE_SIZE", "OTHER_IMAGE_SIZE", "default_image_size", "floor_view", "focal_length", "image_up"]

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

Vec3 = tuple[float, float, float]


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
