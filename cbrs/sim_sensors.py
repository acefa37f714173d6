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

:class:`SimSensors` answers both from the world it is :meth:`~SimSensors.watching` (``cbrs serve``:
each task run's; ``cbrs run --bridge``: its own). On the bridge given to :meth:`~SimSensors.offer` it
offers them only while it watches a world: the rest of the time the names are free, for a ``cbrs run
--bridge`` in another process to provide from its world (:func:`provide_sensors`). One home at a time
answers them: whoever comes second runs without offering its own (the server's run logs a warning, a
``cbrs run`` says so; :func:`provide_sensors` raises :class:`SensorsTakenError` naming the holder), since
a run needs the sensors only if one of its devices reads the simulation, and refusing it would stop
runs that do not. The simulation is imported at the first answer: ``cbrs serve`` starts without pybullet.
"""

from __future__ import annotations

import base64
import io
import logging
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from cbrs.rosbridge import Bridge, RosbridgeError, ServiceError

if TYPE_CHECKING:
    from cbrs.bridge_client import BridgeClient
    from cbrs.sim.cameras import Frame
    from cbrs.sim.load import Load
    from cbrs.sim.world import HomeWorld

log = logging.getLogger("cbrs.sim_sensors")

__all__ = [
    "CAPTURE_SERVICE",
    "LOAD_FIELDS",
    "LOAD_SERVICE",
    "SENSOR_TYPES",
    "SensorsTakenError",
    "SimSensors",
    "frame_from_json",
    "frame_to_json",
    "load_to_json",
    "provide_sensors",
]

CAPTURE_SERVICE = "/sim/capture"
LOAD_SERVICE = "/sim/load"
LOAD_FIELDS = ("place",)
"""The fields a ``/sim/load`` request reads (``cbrs/interfaces/srv/MeasureLoad.srv``); another is refused."""
SENSOR_TYPES = {CAPTURE_SERVICE: "cbrs/CaptureFrame", LOAD_SERVICE: "cbrs/MeasureLoad"}


class SensorsTakenError(RuntimeError):
    """The simulation's sensors on a bridge answer from another world now; ``reason`` says whose."""

    def __init__(self, service: str, reason: str) -> None:
        self.service, self.reason = service, reason
        super().__init__(
            f"the simulation's sensors ({service}) on the bridge are taken: {reason}; one simulated home at a"
            " time answers them (a task run of the server's own, or one cbrs run --bridge), so this run does not"
            " offer its own: a device's program reading them meanwhile reads the other home"
        )


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
    """The simulation's sensor services, answered from the world being watched (or failing with why not
    when none is); on a bridge given to :meth:`offer`, offered only while a world is watched."""

    def __init__(self) -> None:
        self._world: HomeWorld | None = None
        self._bridge: Bridge | None = None
        self._lock = threading.Lock()  # a call in flight holds the world open until it has answered

    def offer(self, bridge: Bridge) -> None:
        """Add ``/sim/capture`` and ``/sim/load`` to ``bridge`` whenever a world is watched, and keep them
        for the client that provides them meanwhile (a client may take a service over from another)."""
        self._bridge = bridge
        bridge.hold_services(self._holder)

    def _holder(self, service: str, client: str) -> str | None:
        """Why ``client`` may not provide ``service`` now: another client does (its run's home)."""
        if service not in SENSOR_TYPES or self._bridge is None:
            return None
        holder = self._bridge.provider(service)
        if holder is None or holder == client:
            return None
        return f"{holder} provides {service} from a simulated home of its own (a cbrs run --bridge)"

    def handlers(self) -> dict[str, Callable[[dict[str, Any]], dict[str, Any]]]:
        """The services' handlers by name (what :meth:`offer` adds, or a client provides)."""
        return {CAPTURE_SERVICE: self.capture, LOAD_SERVICE: self.load}

    @contextmanager
    def watching(self, world: HomeWorld) -> Iterator[HomeWorld]:
        """Answer from ``world`` until the block ends (before the world closes). When a client of the bridge
        provides the sensors (a ``cbrs run --bridge`` in another process) they stay its: the block runs
        without offering them, and a warning says so (the run goes on; only a device reading the
        simulation would miss them)."""
        added: list[str] = []
        try:
            if self._bridge is not None:
                for name, handler in self.handlers().items():
                    try:
                        self._bridge.add_service(name, SENSOR_TYPES[name], handler)
                    except RosbridgeError as error:  # all or none: the other home keeps both
                        log.warning("%s", SensorsTakenError(name, str(error)))
                        for offered in added:
                            self._bridge.remove_service(offered)
                        added.clear()
                        break
                    added.append(name)
            with self._lock:
                self._world = world
            try:
                yield world
            finally:
                with self._lock:
                    self._world = None
        finally:
            for name in added:
                assert self._bridge is not None
                self._bridge.remove_service(name)

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
            raise ServiceError("no simulated home is running: the run whose sensors these were has ended")
        return world


@contextmanager
def provide_sensors(client: BridgeClient, world: HomeWorld) -> Iterator[SimSensors]:
    """Provide ``/sim/capture`` and ``/sim/load`` of ``world`` on the bridge ``client`` is connected to,
    until the block ends (withdrawn before it ends, however it ends); SensorsTakenError, having provided
    nothing, when the bridge refuses them (its server runs a task of its own, or another client holds them)."""
    from cbrs.bridge_client import AdvertiseRefusedError

    sensors = SimSensors()
    provided: list[str] = []
    with sensors.watching(world):
        try:
            for name, handler in sensors.handlers().items():
                provided.append(name)  # withdrawn even if refused: one refusal can follow the other's success
                try:
                    client.advertise(name, SENSOR_TYPES[name], handler)
                except AdvertiseRefusedError as error:
                    raise SensorsTakenError(name, error.reason) from None
            yield sensors
        finally:
            client.withdraw(*provided)
