"""The simulated home's cameras as sensor hardware on the bridge, for components in other processes.

A camera's software (a localiser, a tracker) may run as its own program; the simulation then stands in
for the camera's hardware only: ``/sim/capture`` ``{camera}`` answers one frame of that camera, as the
pixels (PNG, base64) and the calibration (intrinsics and the camera-to-world transform), from which
:func:`frame_from_json` rebuilds the :class:`~sim.cameras.Frame` perception works on.
"""

from __future__ import annotations

import base64
import io
from typing import Any

import numpy as np
from PIL import Image

from cbrs.rosbridge import Bridge, ServiceError
from cbrs.sim.cameras import Frame, Intrinsics
from cbrs.sim.errors import SimulationError
from cbrs.sim.world import HomeWorld

__all__ = ["CAPTURE_SERVICE", "frame_from_json", "frame_to_json", "offer_cameras"]

CAPTURE_SERVICE = "/sim/capture"


def frame_to_json(frame: Frame) -> dict[str, Any]:
    """A frame as a JSON object: the camera, the time, the RGB image as base64 PNG, the calibration."""
    buffer = io.BytesIO()
    Image.fromarray(frame.rgb).save(buffer, format="PNG")
    k = frame.intrinsics
    return {
        "camera": frame.camera,
        "time": frame.time,
        "rgb_png": base64.b64encode(buffer.getvalue()).decode("ascii"),
        "intrinsics": {"width": k.width, "height": k.height, "fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy},
        "camera_to_world": [float(v) for v in frame.camera_to_world.ravel()],
    }


def frame_from_json(data: dict[str, Any]) -> Frame:
    """The frame :func:`frame_to_json` wrote (no depth image: it carries none); ValueError if malformed."""
    try:
        rgb = np.asarray(Image.open(io.BytesIO(base64.b64decode(data["rgb_png"]))).convert("RGB"), dtype=np.uint8)
        k = data["intrinsics"]
        intrinsics = Intrinsics(int(k["width"]), int(k["height"]), k["fx"], k["fy"], k["cx"], k["cy"])
        transform = np.asarray(data["camera_to_world"], dtype=np.float64).reshape(4, 4)
        depth = np.zeros(rgb.shape[:2], dtype=np.float32)
        return Frame(str(data["camera"]), float(data["time"]), rgb, depth, intrinsics, transform)
    except (KeyError, TypeError, ValueError, OSError) as error:
        raise ValueError(f"not a camera frame: {error}") from error


def offer_cameras(bridge: Bridge, world: HomeWorld) -> None:
    """Answer ``/sim/capture`` on ``bridge`` with frames of ``world``'s cameras."""

    def capture(args: dict[str, Any]) -> dict[str, Any]:
        name = args.get("camera")
        if not isinstance(name, str) or name not in world.cameras:
            raise ServiceError(f"no camera {name!r}; the home's cameras are {', '.join(sorted(world.cameras))}")
        try:
            return frame_to_json(world.camera(name).capture())
        except SimulationError as error:
            raise ServiceError(str(error)) from error

    bridge.add_service(CAPTURE_SERVICE, "cbrs/CaptureFrame", capture)
