"""Cameras: rendered RGB and depth images plus the calibration that maps pixels to the world.

Pixels follow the image convention (u to the right, v down from the top row). The camera frame
follows OpenCV (x right, y down, z along the optical axis); ``Frame.camera_to_world`` is the 4x4
extrinsic transform of that frame. Depth is the distance along the optical axis in metres, recovered
from pybullet's non-linear depth buffer.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np
import pybullet as p
from numpy.typing import NDArray

from cbrs.kb.camera_view import focal_length
from cbrs.kb.colour_windows import SIMULATED_LIGHTING, ColourWindow
from cbrs.sim.errors import CameraUnavailableError
from cbrs.sim.layout import CameraSpec

__all__ = ["Camera", "Clock", "Frame", "Intrinsics", "camera_to_world", "project", "render"]
# Where the TINY renderer samples pixel (u, v), in continuous image coordinates: at the pixel's corner
# in OpenGL's bottom-up rows, which is (u, v + 1) counted from the top. Measured, not assumed: with
# centres (u + 0.5, v + 0.5) every estimate was half a pixel (1.7 cm on the floor) off.
_SAMPLE_U = 0.0
_SAMPLE_V = 1.0


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics in pixels (square pixels, principal point at the image centre)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_fov(cls, width: int, height: int, fov_deg: float) -> Intrinsics:
        """Intrinsics of pybullet's projection for a vertical field of view and the image's aspect ratio."""
        f = focal_length(height, fov_deg)
        return cls(width, height, f, f, width / 2.0, height / 2.0)


def camera_to_world(spec: CameraSpec) -> NDArray[np.float64]:
    """4x4 transform from the camera frame (x right, y down, z forward) to the world frame."""
    eye = np.asarray(spec.eye, dtype=np.float64)
    forward = np.asarray(spec.target, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(spec.up, dtype=np.float64))
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    transform = np.eye(4)
    transform[:3, 0] = right
    transform[:3, 1] = down
    transform[:3, 2] = forward
    transform[:3, 3] = eye
    return transform


def project(
    intrinsics: Intrinsics, camera_to_world: NDArray[np.float64], points: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Pixel coordinates (N x 2) of world points for a calibration (the inverse of ``Frame.rays``)."""
    cam = (np.atleast_2d(points) - camera_to_world[:3, 3]) @ camera_to_world[:3, :3]
    k = intrinsics
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(cam[:, 2] > 0, k.fx * cam[:, 0] / cam[:, 2] + k.cx - _SAMPLE_U, np.nan)
        v = np.where(cam[:, 2] > 0, k.fy * cam[:, 1] / cam[:, 2] + k.cy - _SAMPLE_V, np.nan)
    pixels: NDArray[np.float64] = np.stack([u, v], axis=-1)
    return pixels


@dataclass(frozen=True)
class Frame:
    """One capture: the images, when they were taken (sim seconds) and the calibration."""

    camera: str
    time: float
    rgb: NDArray[np.uint8] = field(repr=False)
    """H x W x 3, uint8."""
    depth: NDArray[np.float32] = field(repr=False)
    """H x W, metres along the optical axis."""
    intrinsics: Intrinsics
    camera_to_world: NDArray[np.float64] = field(repr=False)
    colours: Mapping[str, ColourWindow] = field(default_factory=dict, repr=False)
    """The colours its camera tells apart, by name (the store's, :mod:`kb.colour_windows`)."""

    @property
    def eye(self) -> NDArray[np.float64]:
        return self.camera_to_world[:3, 3]

    def rays(self, us: NDArray[np.float64], vs: NDArray[np.float64]) -> NDArray[np.float64]:
        """World-frame directions (N x 3, not normalised, unit z in the camera frame) through the pixels."""
        k = self.intrinsics
        cam = np.stack([(us + _SAMPLE_U - k.cx) / k.fx, (vs + _SAMPLE_V - k.cy) / k.fy, np.ones_like(us)], axis=-1)
        return cam @ self.camera_to_world[:3, :3].T

    def intersect_plane(self, us: NDArray[np.float64], vs: NDArray[np.float64], z: float) -> NDArray[np.float64]:
        """World points (N x 3) where the pixels' rays meet the horizontal plane at height ``z``."""
        dirs = self.rays(us, vs)
        eye = self.eye
        t = (z - eye[2]) / dirs[:, 2]
        points: NDArray[np.float64] = eye + dirs * t[:, None]
        return points

    def deproject(self, us: NDArray[np.float64], vs: NDArray[np.float64]) -> NDArray[np.float64]:
        """World points (N x 3) seen at the pixels, using the depth image."""
        depth = self.depth[vs.astype(np.intp), us.astype(np.intp)].astype(np.float64)
        return self.eye + self.rays(us, vs) * depth[:, None]

    def project(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Pixel coordinates (N x 2, u and v) of world points: the pixel whose sample point they fall
        on is (floor(u), floor(v)). Points behind the camera get NaN."""
        return project(self.intrinsics, self.camera_to_world, points)


class Clock(Protocol):
    """What a camera needs of its world: the current sim time, to stamp frames."""

    @property
    def time(self) -> float: ...


def render(client: int, width: int, height: int, view: Any, projection: Any) -> tuple[Any, Any]:
    """One frame (RGBA and depth buffer) by pybullet's software renderer, lit the same for every
    camera: the perception thresholds and the recordings see the same colours. The light is
    ``kb.colour_windows.SIMULATED_LIGHTING``, which the colour warnings shade a paint by."""
    _, _, rgba, zbuffer, _ = p.getCameraImage(
        width,
        height,
        view,
        projection,
        shadow=0,
        lightDirection=SIMULATED_LIGHTING.direction,
        lightAmbientCoeff=SIMULATED_LIGHTING.ambient,
        lightDiffuseCoeff=SIMULATED_LIGHTING.diffuse,
        lightSpecularCoeff=0.0,
        renderer=p.ER_TINY_RENDERER,
        flags=p.ER_NO_SEGMENTATION_MASK,
        physicsClientId=client,
    )
    return rgba, zbuffer


class Camera:
    """A camera placed in one world's pybullet client; ``capture()`` renders with the TINY renderer.

    ``scene``, if given, tells what the image depends on (``HomeWorld.scene_key``): asked again before
    it changes, the camera gives a copy of its last frame instead of rendering the same image again
    (a render costs 50-70 ms, about 35 ms of it the Panda arms' 205,000 triangles).
    """

    def __init__(
        self,
        client: int,
        spec: CameraSpec,
        clock: Clock,
        scene: Callable[[], Hashable] | None = None,
        colours: Mapping[str, ColourWindow] | None = None,
    ) -> None:
        self.spec = spec
        self.colours = dict(colours or {})
        """The colours it tells apart, by name: its frames carry them (``Frame.colours``)."""
        self.name = spec.name
        self.failed = False
        """A failed camera raises ``CameraUnavailableError``: the fault the executor must recover from."""
        self._client = client
        self._clock = clock
        self.intrinsics = Intrinsics.from_fov(spec.width, spec.height, spec.fov_deg)
        self.camera_to_world = camera_to_world(spec)
        self._view = p.computeViewMatrix(spec.eye, spec.target, spec.up, physicsClientId=client)
        self._projection = p.computeProjectionMatrixFOV(
            spec.fov_deg, spec.width / spec.height, spec.near, spec.far, physicsClientId=client
        )
        self._scene = scene
        self._last: tuple[Hashable, Frame] | None = None
        self.renders = 0
        """How many images this camera rendered (a capture answered from the last frame renders none)."""

    def capture(self) -> Frame:
        """Render one RGB-D frame of the world as it is now."""
        if self.failed:
            raise CameraUnavailableError(self.name)
        key = self._scene() if self._scene is not None else None
        if key is not None and self._last is not None and self._last[0] == key:
            return _copy(self._last[1])
        s = self.spec
        rgba, zbuffer = render(self._client, s.width, s.height, self._view, self._projection)
        self.renders += 1
        rgb = np.ascontiguousarray(np.reshape(np.asarray(rgba, dtype=np.uint8), (s.height, s.width, 4))[:, :, :3])
        z = np.reshape(np.asarray(zbuffer, dtype=np.float64), (s.height, s.width))
        depth = (s.far * s.near / (s.far - (s.far - s.near) * z)).astype(np.float32)
        frame = Frame(s.name, self._clock.time, rgb, depth, self.intrinsics, self.camera_to_world.copy(), self.colours)
        if key is not None:
            self._last = (key, _copy(frame))
        return frame


def _copy(frame: Frame) -> Frame:
    """A frame whose arrays are its own: what a caller does with one never reaches a camera's last frame."""
    return replace(frame, rgb=frame.rgb.copy(), depth=frame.depth.copy(), camera_to_world=frame.camera_to_world.copy())
