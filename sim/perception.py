"""Perception from rendered images only: colour segmentation in HSV, then geometry with the calibration.

* ``locate_robot``: the base's colour marker (green front, magenta rear) seen by a ceiling camera;
  the pixels are intersected with the marker's known plane, the heading is the rear-to-front vector.
* ``track_person``: the person's yellow shirt seen by a ceiling camera (see ``track_person``).
* ``recognise_object``: an object of a given colour in the Kinect's RGB-D frame; its 3D points come
  from the depth image.

Colours are hue windows with floors of saturation and brightness (hue survives the renderer's shading,
which scales brightness; the saturation floor keeps out the greys, whites and the wooden table). What a
camera tells apart is knowledge about it, in the store (:mod:`kb.colour_windows`): a frame carries its
camera's windows (``Frame.colours``), and a colour is looked for by its name among them.

None of these read the simulator's state: only ``Frame`` (pixels, depth, calibration) and the known
heights of the marker and the shirt (calibration knowledge a real system would have too).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cbrs.kb.colour_windows import ColourWindow
from cbrs.sim.cameras import Frame
from cbrs.sim.errors import AmbiguousSightingError, CutByBorderError, NotVisibleError, UnknownColourError
from cbrs.sim.layout import SHIRT_RADIUS, SHIRT_TOP

__all__ = [
    "MarkerModel",
    "ObjectEstimate",
    "PersonEstimate",
    "RobotPoseEstimate",
    "blobs",
    "locate_robot",
    "recognise_object",
    "segment",
    "track_person",
]


MIN_MARKER_PIXELS = 6
"""Fewest pixels per marker patch (each patch covers ~25 pixels at the start pose)."""
MIN_PERSON_PIXELS = 20
MIN_OBJECT_PIXELS = 15
MARKER_SPACING_TOLERANCE = 0.08
"""The two patch centres must be the marker's separation apart within 8 cm, else the marker is half hidden."""
MARKER_MERGED_FACTOR = 1.5
"""A patch blob with more than 1.5 times the pixels a whole patch can cover there has merged with
something else of its colour (an object of the marker's colour touching it): its centre would be wrong."""


def _colour(colour: str | ColourWindow, windows: Mapping[str, ColourWindow]) -> ColourWindow:
    if isinstance(colour, ColourWindow):
        return colour
    try:
        return windows[colour]
    except KeyError:
        raise UnknownColourError(colour, sorted(windows)) from None


def segment(
    rgb: NDArray[np.uint8], colour: str | ColourWindow, windows: Mapping[str, ColourWindow] | None = None
) -> NDArray[np.bool_]:
    """Boolean mask (H x W) of the pixels of a colour: a window, or the name of one of ``windows`` (a
    frame's, ``Frame.colours``: what its camera tells apart).

    Hue is worked out only for the pixels saturated and bright enough to count (a few hundred of the
    image's 76,800: the rest is white, grey and wood), with the same arithmetic as for all of them.
    """
    spec = _colour(colour, windows or {})
    red, green, blue = rgb[..., 0], rgb[..., 1], rgb[..., 2]  # (a reduction over the last axis is slow)
    value = np.maximum(np.maximum(red, green), blue).astype(np.float32) / 255.0  # largest and smallest channel
    chroma = value - np.minimum(np.minimum(red, green), blue).astype(np.float32) / 255.0
    saturation = np.where(value > 0, chroma / np.maximum(value, 1e-6), 0.0)
    mask: NDArray[np.bool_] = (chroma > 1e-6) & (saturation >= spec.min_saturation) & (value >= spec.min_value)
    rows, cols = np.nonzero(mask)
    pixels = rgb[rows, cols].astype(np.float32) / 255.0
    r, g, b = pixels[:, 0], pixels[:, 1], pixels[:, 2]
    top = value[rows, cols]
    safe = np.maximum(chroma[rows, cols], 1e-6)
    hue = (
        np.where(
            top == r,
            ((g - b) / safe) % 6.0,
            np.where(top == g, (b - r) / safe + 2.0, (r - g) / safe + 4.0),
        )
        * 60.0
    )
    distance = np.abs((hue - spec.hue + 180.0) % 360.0 - 180.0)
    mask[rows, cols] = distance <= spec.hue_tolerance
    return mask


def blobs(mask: NDArray[np.bool_]) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """The 8-connected blobs of a mask as (us, vs) pixel coordinates, the largest first.

    Colours are shared: an object of the marker's green or of the person's yellow is a blob of its
    own, which must not be averaged into what is looked for.
    """
    vs, us = np.nonzero(mask)
    found = sorted(_connected([(int(v), int(u)) for v, u in zip(vs, us, strict=True)]), key=len, reverse=True)
    return [(us[group].astype(np.float64), vs[group].astype(np.float64)) for group in map(np.array, found)]


def _connected(pixels: Sequence[tuple[int, int]], joined: Callable[[int, int], bool] | None = None) -> list[list[int]]:
    """The 8-connected groups of ``pixels`` (each (v, u)) as lists of their indices, each in the order a
    breadth-first walk meets them: two neighbouring pixels ``n`` and ``m`` are of one group when
    ``joined(n, m)`` (always, when None). Masks hold a few hundred pixels, so the walk is cheap; a pixel
    is keyed by one integer (rows ``stride`` apart, wide enough that no neighbour wraps to another row)."""
    if not pixels:
        return []
    stride = max(u for _, u in pixels) + 3
    keys = [v * stride + u for v, u in pixels]
    find = {key: n for n, key in enumerate(keys)}.get
    around = [dv * stride + du for dv in (-1, 0, 1) for du in (-1, 0, 1)]
    label = [-1] * len(pixels)
    groups: list[list[int]] = []
    for first in range(len(pixels)):
        if label[first] >= 0:
            continue
        group = len(groups)
        label[first] = group
        members = [first]
        for n in members:  # a list walked while appended to: breadth-first
            key = keys[n]
            for step in around:
                m = find(key + step)
                if m is None or label[m] >= 0 or (joined is not None and not joined(n, m)):
                    continue
                label[m] = group
                members.append(m)
        groups.append(members)
    return groups


def _mask_of(shape: tuple[int, ...], us: NDArray[np.float64], vs: NDArray[np.float64]) -> NDArray[np.bool_]:
    mask = np.zeros(shape[:2], dtype=bool)
    mask[vs.astype(np.intp), us.astype(np.intp)] = True
    return mask


def _whole(frame: Frame, mask: NDArray[np.bool_], target: str) -> None:
    """Refuse a blob cut by the image's border: its shape, hence the estimate, would be wrong."""
    on_border = int(mask[0, :].sum() + mask[-1, :].sum() + mask[:, 0].sum() + mask[:, -1].sum())
    if on_border:
        raise CutByBorderError(frame.camera, target, int(mask.sum()), on_border)


@dataclass(frozen=True)
class RobotPoseEstimate:
    """The base's pose (x, y, theta: the ontology's RobotLocation) as one camera saw it."""

    x: float
    y: float
    theta: float
    camera: str
    time: float
    pixels: int


@dataclass(frozen=True)
class MarkerModel:
    """What the localiser knows of a robot's colour marker (from the semantic map): the front and rear
    patches' colours, one patch's size along and across the robot, the distance between the patches'
    centres, and the height of their top faces, the plane pixel rays are intersected with."""

    front: str
    rear: str
    patch: tuple[float, float]
    separation: float
    height: float


def locate_robot(frame: Frame, marker: MarkerModel) -> RobotPoseEstimate:
    """The base's pose from its two-colour marker; ``NotVisibleError`` if either patch is missing.

    Each colour may show several blobs (a green object on the table, a magenta book): the patches are
    the front and rear blobs whose centres are the marker's separation apart, the pair closest to it.
    """
    candidates: list[list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]]] = []
    for colour, target in ((marker.front, "marker front"), (marker.rear, "marker rear")):
        found = [
            (us, vs) for us, vs in blobs(segment(frame.rgb, colour, frame.colours)) if us.size >= MIN_MARKER_PIXELS
        ]
        if not found:
            raise NotVisibleError(frame.camera, f"robot {target} ({colour})", 0, MIN_MARKER_PIXELS)
        candidates.append(
            [(us, vs, frame.intersect_plane(us, vs, marker.height)[:, :2].mean(axis=0)) for us, vs in found]
        )
    pairs = [
        (abs(float(np.linalg.norm(f[2] - r[2])) - marker.separation), f, r)
        for f in candidates[0]
        for r in candidates[1]
    ]
    error, front, rear = min(pairs, key=lambda pair: pair[0])
    count = int(front[0].size + rear[0].size)
    if error > MARKER_SPACING_TOLERANCE:
        spacing = float(np.linalg.norm(front[2] - rear[2]))
        raise NotVisibleError(frame.camera, f"whole robot marker (patches {spacing:.2f} m apart)", count, count + 1)
    for (us, vs, _), colour, target in ((front, marker.front, "marker front"), (rear, marker.rear, "marker rear")):
        _whole(frame, _mask_of(frame.rgb.shape, us, vs), f"robot {target} ({colour})")
        # A partly hidden patch would pull its centroid off: compare its pixel count with the fewest
        # a whole patch covers there, one row and one column less than its size in pixels (pixel
        # size measured on the marker's plane at the patch); one merged with a thing of its colour
        # covers more than a whole patch can.
        u, v = float(np.median(us)), float(np.median(vs))
        corners = frame.intersect_plane(np.array([u, u + 1.0, u]), np.array([v, v, v + 1.0]), marker.height)
        pixel = math.sqrt(float(np.linalg.norm(np.cross(corners[1] - corners[0], corners[2] - corners[0]))))
        along, across = marker.patch[0] / pixel, marker.patch[1] / pixel
        needed = math.ceil((along - 1.0) * (across - 1.0))
        if us.size < needed:
            raise NotVisibleError(frame.camera, f"whole robot {target} ({colour})", int(us.size), needed)
        most = MARKER_MERGED_FACTOR * (along + 1.0) * (across + 1.0)
        if us.size > most:
            raise NotVisibleError(
                frame.camera, f"robot {target} ({colour}) apart from another {colour} thing touching it", 0, 1
            )
    head, tail = front[2], rear[2]
    centre = (head + tail) / 2.0
    theta = math.atan2(float(head[1] - tail[1]), float(head[0] - tail[0]))
    return RobotPoseEstimate(float(centre[0]), float(centre[1]), theta, frame.camera, frame.time, count)


@dataclass(frozen=True)
class PersonEstimate:
    """Where the person stands on the floor (x, y: the ontology's PersonPosition)."""

    x: float
    y: float
    camera: str
    time: float
    pixels: int


def track_person(frame: Frame, shirt: str = "yellow") -> PersonEstimate:
    """The person's floor position from their shirt, seen from above.

    The shirt is an upright cylinder. Seen obliquely, most of its pixels are on the side facing the
    camera, so a plain centroid is pulled towards the camera. Intersected with the plane of the
    shoulders, though, the side's pixels land nearer the camera than the cylinder and the shoulders'
    pixels land where they are: the far edge of the projected blob is the far edge of the shoulders.
    Across the viewing direction the blob is symmetric. So: centre = far edge minus the shirt's
    radius along the viewing direction, and the middle of the blob across it.
    """
    found = blobs(segment(frame.rgb, shirt, frame.colours))
    if not found or found[0][0].size < MIN_PERSON_PIXELS:
        raise NotVisibleError(
            frame.camera, f"person ({shirt} shirt)", int(found[0][0].size) if found else 0, MIN_PERSON_PIXELS
        )
    # The shirt is the largest blob of its colour, with the pieces of it within a shirt's width (the
    # head may cut it); a thing of that colour farther away is not the person.
    pieces = [(us, vs, frame.intersect_plane(us, vs, SHIRT_TOP)[:, :2]) for us, vs in found]
    middle = pieces[0][2].mean(axis=0)
    kept = [piece for piece in pieces if float(np.linalg.norm(piece[2].mean(axis=0) - middle)) <= 2.0 * SHIRT_RADIUS]
    us = np.concatenate([piece[0] for piece in kept])
    vs = np.concatenate([piece[1] for piece in kept])
    _whole(frame, _mask_of(frame.rgb.shape, us, vs), f"person ({shirt} shirt)")
    points = np.concatenate([piece[2] for piece in kept])
    eye = frame.eye[:2]
    rough = points.mean(axis=0)
    along = rough - eye
    norm = float(np.linalg.norm(along))
    if norm < 0.3:
        # Right below the camera the blob is the shoulders themselves.
        centre = rough
    else:
        along /= norm
        across = np.array([-along[1], along[0]])
        a = (points - eye) @ along
        c = (points - eye) @ across
        index = int(np.argmax(a))
        # The farthest pixel's sample point lies on average half a pixel inside the true edge.
        u, v = us[index], vs[index]
        corners = frame.intersect_plane(np.array([u, u + 1.0, u]), np.array([v, v, v + 1.0]), SHIRT_TOP)[:, :2]
        pixel = abs(float((corners[1] - corners[0]) @ along)) + abs(float((corners[2] - corners[0]) @ along))
        far = float(a[index]) + pixel / 2.0
        mid_across = (float(c.min()) + float(c.max())) / 2.0
        centre = eye + along * (far - SHIRT_RADIUS) + across * mid_across
    return PersonEstimate(float(centre[0]), float(centre[1]), frame.camera, frame.time, int(us.size))


SAME_THING_GAP = 0.03
"""Blobs of one colour whose 3D points come within 3 cm of each other are one thing (split by what
stands in front of it); farther apart, they are separate things."""


def _surfaces(
    us: NDArray[np.float64], vs: NDArray[np.float64], points: NDArray[np.float64]
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]]:
    """A blob's pixels split into the pieces whose neighbouring pixels' points (8-connected) lie within
    SAME_THING_GAP of each other: the surfaces seen, apart where the depth jumps."""
    xyz = [(float(x), float(y), float(z)) for x, y, z in points]

    def near(n: int, m: int) -> bool:
        (x, y, z), (mx, my, mz) = xyz[n], xyz[m]
        return max(abs(mx - x), abs(my - y), abs(mz - z)) <= SAME_THING_GAP

    pieces = _connected([(int(v), int(u)) for v, u in zip(vs, us, strict=True)], near)
    if len(pieces) == 1:
        return [(us, vs, points)]
    return [(us[members], vs[members], points[members]) for members in (np.array(p) for p in pieces)]


def _things(
    frame: Frame, mask: NDArray[np.bool_]
) -> list[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]]:
    """The separate things of a colour in an RGB-D frame: (us, vs, 3D points), the largest first. A blob
    of the image is first split where neighbouring pixels' points lie more than SAME_THING_GAP apart in
    depth (:func:`_surfaces`): a tall bottle's top seen against a pen of its colour lying behind it on the
    table is one blob of the image, and was taken for one thing between them, 6 cm from the bottle."""
    pieces = [piece for us, vs in blobs(mask) for piece in _surfaces(us, vs, frame.deproject(us, vs))]
    group = list(range(len(pieces)))

    def root(i: int) -> int:
        while group[i] != i:
            i = group[i]
        return i

    for i in range(len(pieces)):
        for j in range(i + 1, len(pieces)):
            a, b = pieces[i][2], pieces[j][2]
            if np.any(np.abs(a[:, None, :] - b[None, :, :]).max(axis=2) <= SAME_THING_GAP):
                group[root(j)] = root(i)
    merged: dict[int, list[int]] = {}
    for i in range(len(pieces)):
        merged.setdefault(root(i), []).append(i)
    things = [
        (
            np.concatenate([pieces[i][0] for i in members]),
            np.concatenate([pieces[i][1] for i in members]),
            np.concatenate([pieces[i][2] for i in members]),
        )
        for members in merged.values()
    ]
    things.sort(key=lambda thing: thing[0].size, reverse=True)
    return things


@dataclass(frozen=True)
class ObjectEstimate:
    """An object found by colour: the centre of its 3D extent (the ontology's ObjectPosition3D)."""

    x: float
    y: float
    z: float
    yaw: float | None
    """Direction of the long axis for elongated objects (radians, modulo pi), else None."""
    size: tuple[float, float, float]
    """Extent of the seen points along x, y, z (m)."""
    colour: str
    camera: str
    time: float
    pixels: int

    @property
    def position(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)


OBLONG = 1.4
"""A thing seen this many times as long along its principal axis as across it has a long axis (a yaw),
even where its points' variances differ less than ninefold: a phone 15 x 7 cm lying at 46 degrees (the
variances 4.6-fold, the extents 2.1-fold) had none, and its top grasp closed along the world's x axis,
14 cm across it. The cup's points, seen from the Kinect, span 1.04-1.16 times as much one way as the
other; the boxes of the examples 1.6-2.8 times."""


def recognise_object(
    frame: Frame, colour: str, near: tuple[float, float] | None = None, radius: float = 0.25
) -> ObjectEstimate:
    """The object of a colour in an RGB-D frame, located from the depth image.

    The seen points cover the top and the camera-facing side. For the upright and lying shapes on
    the table that is enough: the middle of the points' bounding box (taken along the object's own
    axis) is the object's centre, within the pixel size. The yaw comes from the points' principal axis,
    for a thing long along it (its variances ninefold, or its extents OBLONG-fold).
    The pixels of the colour are split into separate things (:func:`blobs`, joined where their points
    touch). With ``near`` (x, y) the object is the thing whose centre is nearest it, within ``radius``:
    another thing of the same colour is not this object. Without it, two things of the colour in view
    are an ``AmbiguousSightingError`` rather than one estimate between them.
    """
    target = f"{colour} object" if near is None else f"{colour} object near ({near[0]:.2f}, {near[1]:.2f})"
    things = _things(frame, segment(frame.rgb, colour, frame.colours))
    if near is not None:
        # the thing nearest where the object is believed to be, if it is within the radius; another
        # thing of its colour nearby is not part of it
        distance = [float(np.hypot(*(points[:, :2].mean(axis=0) - near))) for _, _, points in things]
        things = [thing for thing, d in sorted(zip(things, distance, strict=True), key=lambda t: t[1]) if d <= radius]
    else:
        big = [thing for thing in things if thing[0].size >= MIN_OBJECT_PIXELS]
        if len(big) > 1:
            centres = [points.mean(axis=0) for _, _, points in big]
            raise AmbiguousSightingError(
                frame.camera, colour, [(float(c[0]), float(c[1]), float(c[2])) for c in centres]
            )
    pixels = int(things[0][0].size) if things else 0
    if pixels < MIN_OBJECT_PIXELS:
        raise NotVisibleError(frame.camera, target, pixels, MIN_OBJECT_PIXELS)
    us, vs, points = things[0]
    _whole(frame, _mask_of(frame.rgb.shape, us, vs), target)
    xy = points[:, :2]
    mean = xy.mean(axis=0)
    cov = np.cov((xy - mean).T)
    eigenvalues, eigenvectors = np.linalg.eigh(cov)
    major = eigenvectors[:, 1]
    principal = np.column_stack([major, [-major[1], major[0]]])
    span = np.ptp((xy - mean) @ principal, axis=0)
    elongated = eigenvalues[1] > 9.0 * max(eigenvalues[0], 1e-12) or span[0] >= OBLONG * max(float(span[1]), 1e-9)
    axes = principal if elongated else np.eye(2)
    local = (xy - mean) @ axes
    low = local.min(axis=0)
    high = local.max(axis=0)
    centre_xy = mean + axes @ ((low + high) / 2.0)
    z_low, z_high = float(points[:, 2].min()), float(points[:, 2].max())
    yaw = math.atan2(float(major[1]), float(major[0])) if elongated else None
    if yaw is not None:
        yaw = (yaw + math.pi / 2.0) % math.pi - math.pi / 2.0
    extent = points.max(axis=0) - points.min(axis=0)
    return ObjectEstimate(
        float(centre_xy[0]),
        float(centre_xy[1]),
        (z_low + z_high) / 2.0,
        yaw,
        (float(extent[0]), float(extent[1]), float(extent[2])),
        colour,
        frame.camera,
        frame.time,
        int(us.size),
    )
