"""Whether a camera sees an object whole, from the map alone: its pose, size and shape projected through
the camera's model (pose, field of view, image size, range), and the sight lines to it tested against
the map's solid boxes (walls, furniture, appliances, robots' bodies: :func:`kb.camera_view.hidden`). The
check before a run asks it of the camera each recognition step would look with, so that an object the
camera cannot see is refused before the base drives off, not when the step looks (docs/execution.md,
"The simulated components"). The person is outlined wherever the seed may put them
(:class:`sim.world.Spread`), so that a person the check accepts is seen at every seed."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from cbrs.kb.camera_view import HIDDEN_BY, Occluder, hidden, occluders
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.semantic_map import MapObject, Person, local_name
from cbrs.sim import layout as L
from cbrs.sim.cameras import Camera, project
from cbrs.sim.geometry import Pose2D, Vec3
from cbrs.sim.perception import MarkerModel
from cbrs.sim.world import Spread

__all__ = [
    "BaseOutOfViewError",
    "OutOfViewError",
    "marker_centres",
    "object_outline",
    "occluders",
    "person_centre",
    "person_outline",
    "unseen",
]

RIM_POINTS = 24
"""Points taken round each rim of a cylinder: its silhouette is then under 1% of its radius larger
than theirs (1 - cos(pi / 24)), well under a pixel of any camera of the home."""


def object_outline(obj: MapObject, centre: Vec3) -> NDArray[np.float64]:
    """Points whose image bounds the object's (N x 3): a box's eight corners, turned by its map yaw, or
    points round a cylinder's two rims, the object centred at ``centre``."""
    sx, sy, sz = obj.size
    if obj.shape == "cylinder":
        angles = np.linspace(0.0, 2.0 * math.pi, RIM_POINTS, endpoint=False)
        flat = np.stack([np.cos(angles) * sx / 2, np.sin(angles) * sx / 2], axis=-1)
    else:
        c, s = math.cos(obj.start.yaw), math.sin(obj.start.yaw)
        corners = np.array([[x, y] for x in (-sx / 2, sx / 2) for y in (-sy / 2, sy / 2)])
        flat = corners @ np.array([[c, s], [-s, c]])
    rows = [[centre[0] + dx, centre[1] + dy, centre[2] + dz] for dz in (-sz / 2, sz / 2) for dx, dy in flat]
    return np.array(rows, dtype=np.float64)


def marker_centres(marker: MarkerModel, pose: Pose2D) -> NDArray[np.float64]:
    """The centres of the base's two marker patches (2 x 3), the base parked at ``pose``: where a locator
    must see each colour. Centres, not outlines: a patch seen in part is still found (perception needs a
    few of its pixels, ``MIN_MARKER_PIXELS``), and the base stops a few centimetres from a docking pose."""
    half = marker.separation / 2.0
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    rows = [[pose.x + sign * half * c, pose.y + sign * half * s, marker.height] for sign in (1.0, -1.0)]
    return np.array(rows, dtype=np.float64)


def person_centre(person: Person) -> Vec3:
    """The middle of the person's shirt, standing at their map pose: where a tracker looks for them."""
    return (person.start.x, person.start.y, (L.SHIRT_BOTTOM + L.SHIRT_TOP) / 2)


def person_outline(person: Person, spread: float = Spread().person) -> NDArray[np.float64]:
    """Points round the two rims of the person's shirt (the mannequin's, :mod:`sim.layout`) wherever the
    seed may put them: at their map pose moved by each corner of the square of side 2 ``spread`` the
    world draws their offset from (:class:`sim.world.Spread`; 0: the map pose alone). The person tracker
    refuses a shirt cut by the image's border, as perception does an object; a shirt whose rims are on the
    image at the four corners is on it at every offset between them (the image is a convex cone from
    the eye). Before, the rims were taken at the map pose alone, and a seed could move the person up to
    15 cm each way out of a view the check had accepted."""
    angles = np.linspace(0.0, 2.0 * math.pi, RIM_POINTS, endpoint=False)
    corners = [(0.0, 0.0)] if spread == 0.0 else [(sx * spread, sy * spread) for sx in (-1, 1) for sy in (-1, 1)]
    rows = [
        [person.start.x + dx + math.cos(a) * L.SHIRT_RADIUS, person.start.y + dy + math.sin(a) * L.SHIRT_RADIUS, z]
        for dx, dy in corners
        for z in (L.SHIRT_BOTTOM, L.SHIRT_TOP)
        for a in angles
    ]
    return np.array(rows, dtype=np.float64)


def unseen(
    camera: Camera,
    points: NDArray[np.float64],
    blockers: Sequence[Occluder] = (),
    max_hidden: float | None = None,
) -> str:
    """Why ``camera`` would not see the whole of what ``points`` outline; empty when it would. Whole
    means every point nearer than the camera's far range and beyond its near one, and on a pixel off the
    image's border: perception refuses a blob touching the border (``CutByBorderError``); and no more than
    ``max_hidden`` of the sight lines from the camera's eye to the points passing through one of
    ``blockers`` (the map's solid boxes, :func:`occluders`; none given, none tested). ``max_hidden``
    defaults to the camera's own ``home:occlusionTolerance`` (``kb.camera_view.MAX_HIDDEN`` unless the map says)."""
    spec = camera.spec
    depth = (points - camera.camera_to_world[:3, 3]) @ camera.camera_to_world[:3, 2]
    if float(depth.min()) < spec.near or float(depth.max()) > spec.far:
        return (
            f"{depth.min():.2f}-{depth.max():.2f} m along its axis, outside its range {spec.near:.2f}-{spec.far:.2f} m"
        )
    pixels = np.floor(project(camera.intrinsics, camera.camera_to_world, points))
    us, vs = pixels[:, 0], pixels[:, 1]
    out = (us < 1) | (us > spec.width - 2) | (vs < 1) | (vs > spec.height - 2)
    if not out.any():
        allowed = camera.spec.max_hidden if max_hidden is None else max_hidden
        return hidden(camera.spec.eye, points.tolist(), blockers, allowed)
    return (
        f"{int(out.sum())} of the {len(points)} points outlining it fall on or past the border of its "
        f"{spec.width} x {spec.height} image (columns {us.min():.0f} to {us.max():.0f}, rows {vs.min():.0f} to "
        f"{vs.max():.0f})"
    )


class OutOfViewError(KnowledgeBaseError):
    """A recognition step would look for an object the task gives (or a tracking step for the person)
    with a camera that cannot see it whole from where it is believed to be, and no camera that could
    stand in for it can either: the run is refused before anything moves. ``cameras`` holds (camera
    name, why it does not see it)."""

    http_status = 422

    def __init__(self, component: str, thing: str, where: Vec3, cameras: list[tuple[str, str]]) -> None:
        self.component = component
        self.thing = thing
        self.where = where
        self.cameras = tuple(cameras)
        each = "; ".join(f"{camera}: {why}" for camera, why in self.cameras)
        names = " or ".join(camera for camera, _ in self.cameras)
        super().__init__(
            f"{local_name(component)} would look for the {local_name(thing)} at ({where[0]:.2f}, {where[1]:.2f}, "
            f"{where[2]:.2f}) with {names}, which cannot see it whole ({each}); move it in the map (home:x, home:y) "
            f"to where {names} sees it{_or_what_hides(self.cameras)}, or hang a camera over it and register a "
            "component that looks with that camera (docs/tasks.md, 'Which arm')"
        )


class BaseOutOfViewError(KnowledgeBaseError):
    """A step would locate the mobile base by its marker where an earlier step of the plan parks it (a
    place's docking pose), and no camera of the locators that may do the step sees the marker there: the
    base would drive off and be lost at the place, the next drive failing with "marker not visible". The
    run is refused before anything moves. ``cameras`` holds (camera name, why it does not see it)."""

    http_status = 422

    def __init__(self, component: str, place: str, pose: Pose2D, cameras: list[tuple[str, str]]) -> None:
        self.component = component
        self.place = place
        self.pose = pose
        self.cameras = tuple(cameras)
        each = "; ".join(f"{camera}: {why}" for camera, why in self.cameras)
        names = " or ".join(camera for camera, _ in self.cameras)
        super().__init__(
            f"{local_name(component)} would locate the mobile base by its marker at {local_name(place)}'s docking "
            f"pose ({pose.x:.2f}, {pose.y:.2f}), where an earlier step parks it, with {names}, which cannot see "
            f"the marker there ({each}); the base would be lost there and could not drive on. Hang a camera "
            "over the place and register a locator (LocateMobileRobot) that looks with it "
            "(docs/examples/lab20_bedroom_locator.ttl does so for the bedroom), or move the place's "
            "home:dockingPose to where a camera sees the base"
        )


def _or_what_hides(cameras: tuple[tuple[str, str], ...]) -> str:
    """The advice for a thing the map's boxes hide: moving what hides it is a fix too."""
    return ", or what hides it out of the way" if any(HIDDEN_BY in why for _, why in cameras) else ""
