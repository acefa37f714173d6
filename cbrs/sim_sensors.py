"""The simulated home's sensors as hardware on the bridge, for components in other processes.

A device's software (a camera's localiser, a kitchen scale's program) may run as its own program; the
simulation then stands in for the device's hardware only, and answers from the physics, never from the
map (docs/components.md, "The simulation's sensors"):

- ``/sim/capture`` ``{camera}`` (``cbrs/CaptureFrame``): one frame of that camera, as the pixels (PNG,
  base64) and the calibration (intrinsics and the camera-to-world transform), from which
  :func:`frame_from_json` rebuilds the :class:`~sim.cameras.Frame` perception works on;
- ``/sim/load`` ``{place}`` (``cbrs/MeasureLoad``): a load cell under a place (a body such as a table, or
  a place of the map with an extent such as a scale's plate): the weight it bears and the bodies resting
  on it with their masses (:mod:`sim.load`).

:class:`SimSensors` offers both on a bridge for as long as the bridge runs and answers them from the
world it is :meth:`~SimSensors.watching` (``cbrs serve``: each task run's); with none, a call fails
saying so. The simulation is imported at the first answer: ``cbrs serve`` starts without pybullet.
"""

from __future__ import annotations

import base64
import io
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from cbrs.rosbridge import Bridge, ServiceError

if TYPE_CHECKING:
    from cbrs.sim.cameras import Frame
    from cbrs.sim.load import Load
    from cbrs.sim.world import HomeWorld

__all__ = [
    "CAPTURE_SERVICE",
    "LOAD_FIELDS",
    "LOAD_SERVICE",
    "SimSensors",
    "frame_from_json",
    "frame_to_json",
    "load_to_json",
]

CAPTURE_SERVICE = "/sim/capture"
LOAD_SERVICE = "/sim/load"
LOAD_FIELDS = ("place",)
"""The fields a ``/sim/load`` request reads (``cbrs/interfaces/srv/MeasureLoad.srv``); another is refused."""


def frame_to_json(frame: Frame) -> dict[str, Any]:
    """A frame as a JSON object: the camera, the time, the RGB image as base64 PNG, the calibration."""
    from PIL import Image

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
    import numpy as np
    from PIL import Image

    from cbrs.sim.cameras import Frame, Intrinsics

    try:
        rgb = np.asarray(Image.open(io.BytesIO(base64.b64decode(data["rgb_png"]))).convert("RGB"), dtype=np.uint8)
        k = data["intrinsics"]
        intrinsics = Intrinsics(int(k["width"]), int(k["height"]), k["fx"], k["fy"], k["cx"], k["cy"])
        transform = np.asarray(data["camera_to_world"], dtype=np.float64).reshape(4, 4)
        depth = np.zeros(rgb.shape[:2], dtype=np.float32)
        return Frame(str(data["camera"]), float(data["time"]), rgb, depth, intrinsics, transform)
    except (KeyError, TypeError, ValueError, OSError) as error:
        raise ValueError(f"not a camera frame: {error}") from error


def load_to_json(load: Load) -> dict[str, Any]:
    """A load cell's reading as ``/sim/load`` answers it: the resting bodies as parallel lists, by name
    (as ``sensor_msgs/JointState`` lists its joints); a body the map does not name has its body name."""
    return {
        "place": load.place,
        "time": load.time,
        "load_kg": load.load_kg,
        "resting": [body.iri or body.name for body in load.resting],
        "masses_kg": [body.mass_kg for body in load.resting],
    }


class SimSensors:
    """The simulation's sensor services on a bridge, answered from the world being watched (or failing
    with why not when none is)."""

    def __init__(self) -> None:
        self._world: HomeWorld | None = None
        self._lock = threading.Lock()  # a call in flight holds the world open until it has answered

    def offer(self, bridge: Bridge) -> None:
        """Add ``/sim/capture`` and ``/sim/load`` to ``bridge``."""
        bridge.add_service(CAPTURE_SERVICE, "cbrs/CaptureFrame", self.capture)
        bridge.add_service(LOAD_SERVICE, "cbrs/MeasureLoad", self.load)

    @contextmanager
    def watching(self, world: HomeWorld) -> Iterator[HomeWorld]:
        """Answer from ``world`` until the block ends (before the world closes)."""
        with self._lock:
            self._world = world
        try:
            yield world
        finally:
            with self._lock:
                self._world = None

    def capture(self, args: dict[str, Any]) -> dict[str, Any]:
        """``/sim/capture``: a frame of the camera ``args["camera"]``."""
        from cbrs.sim.errors import SimulationError

        with self._lock:
            world = self._present()
            name = args.get("camera")
            if not isinstance(name, str) or name not in world.cameras:
                raise ServiceError(f"no camera {name!r}; the home's cameras are {', '.join(sorted(world.cameras))}")
            try:
                return frame_to_json(world.camera(name).capture())
            except SimulationError as error:
                raise ServiceError(str(error)) from error

    def load(self, args: dict[str, Any]) -> dict[str, Any]:
        """``/sim/load``: what rests on ``args["place"]`` and the weight it bears."""
        from cbrs.sim.errors import SimulationError
        from cbrs.sim.load import measure_load

        unread = sorted(set(args) - set(LOAD_FIELDS))
        if unread:
            raise ServiceError(f"{LOAD_SERVICE} reads {', '.join(LOAD_FIELDS)}, not {', '.join(unread)}")
        place = args.get("place")
        if not isinstance(place, str) or not place:
            raise ServiceError(f"{LOAD_SERVICE} needs a place (an IRI or a local name), not {place!r}")
        with self._lock:
            world = self._present()
            try:
                return load_to_json(measure_load(world, place))
            except SimulationError as error:
                raise ServiceError(str(error)) from error

    def _present(self) -> HomeWorld:
        world = self._world
        if world is None or world.closed:
            raise ServiceError(
                "no simulated home is running on this server: its sensors answer during its own task runs (the"
                " tasks page, /cbrs/run_task), not during a cbrs run in another process"
            )
        return world
