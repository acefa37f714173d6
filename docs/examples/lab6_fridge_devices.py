"""The lab's fridge door sensor and the resident's phone, two cbrs components in one program of the
lab's own, written with roslibpy alone (no cbrs package needed on the device), as docs/components.md,
"Writing one (roslibpy)", shows: each component on a connection of its own, authenticated before it
connects, registered first, then its service advertised, then three heartbeats a lease.

    lab6_fridge_door_sensor.ttl  /lab6_fridge_door_sensor_01/check
        {"fridge": ...} -> {"fridgeDoor": a home:DoorStatus}
    lab6_caregiver_phone.ttl     /lab6_resident_phone_01/alert
        {"doorStatus": ..., "person": ...} -> {"alert": a home:AlarmMessage}

With the server of docs/tasks.md, "A sixth round" (lab6_fridge.ttl in the ontology and the map,
lab6_watch_the_fridge.ttl in the requirements, cbrs serve started with CBRS_UPDATE_TOKEN):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab6_fridge_devices.py [--bridge ws://127.0.0.1:9090] [--door open]
    CBRS_UPDATE_TOKEN=secret cbrs --store http://127.0.0.1:8080 run WatchTheFridge --bridge ws://127.0.0.1:9090

It prints one line on standard output once both are registered ("fridge devices: registered ...") and
one per alert sent ("phone: ALERT ..."), and exits with status 1 and the reason when the server stops.
``--misbehave`` makes the sensor a newcomer's mistake on purpose:

    wrong-type  answers a home:RoomTemperature where a home:DoorStatus is due
    silent      never answers (its handler raises, and roslibpy then sends nothing)

and ``--sensor docs/examples/lab6_mistake_sensor_output.ttl`` registers a sensor whose output no step takes.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import roslibpy

HERE = Path(__file__).resolve().parent
LEASE = 3.0


class Device:
    """One component: its own connection, registered, then its service advertised, then beating."""

    def __init__(self, bridge: str, token: str, description: Path, service: str, kind: str) -> None:
        where = urlparse(bridge)
        self.ros = roslibpy.Ros(host=where.hostname or "127.0.0.1", port=where.port or 9090)
        self.ros.authenticate(token, "", "", "", 0, "", 0)  # before run(): roslibpy sends it as it connects
        self.ros.run(timeout=10)
        self.text = description.read_text(encoding="utf-8")
        self.service, self.kind = service, kind
        self.register = roslibpy.Service(self.ros, "/cbrs/register", "cbrs/Register")
        self.heartbeat = roslibpy.Service(self.ros, "/cbrs/heartbeat", "cbrs/Heartbeat")
        self.lapsed = threading.Event()

    def registered(self) -> Any:
        request = roslibpy.ServiceRequest({"description": self.text, "format": "turtle", "ttl": LEASE})
        return self.register.call(request, timeout=10)  # raises with the server's reason if refused

    def provide(self, handler: Any) -> None:
        roslibpy.Service(self.ros, self.service, self.kind).advertise(handler)

    def beat(self, stop: Any) -> None:
        if self.lapsed.is_set():  # register again, here rather than on roslibpy's event loop
            try:
                self.registered()
            except Exception as error:  # any refusal ends the program
                stop(f"{self.service}: it could not register again: {error}")
            self.lapsed.clear()

        def failed(reason: Any) -> None:  # on the event loop: no blocking call here
            text = str(reason)
            if "was deregistered" in text or "advertise the service" in text:
                stop(f"{self.service}: {text}")
            elif "this session has no live component" in text:
                self.lapsed.set()

        self.heartbeat.call(roslibpy.ServiceRequest({}), callback=lambda _: None, errback=failed)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    parser.add_argument("--door", choices=("open", "closed"), default="open", help="what the sensor reads")
    parser.add_argument("--misbehave", choices=("wrong-type", "silent"), help="the sensor's mistake")
    parser.add_argument(
        "--sensor",
        type=Path,
        default=HERE / "lab6_fridge_door_sensor.ttl",
        help="the sensor's description (lab6_mistake_sensor_output.ttl: an output nobody takes)",
    )
    args = parser.parse_args()
    token = os.environ.get("CBRS_UPDATE_TOKEN", "")
    ended = threading.Event()

    def stop(reason: str) -> None:
        print(f"fridge devices: stopped serving: {reason}", file=sys.stderr, flush=True)
        ended.set()

    def check(request: dict[str, Any], response: dict[str, Any]) -> bool:
        # request: {"fridge": {"@id": ".../lab6#Fridge1", "@type": ".../home#Refrigerator"}}
        if args.misbehave == "silent":
            raise RuntimeError("the door sensor is silent on purpose")  # roslibpy answers nothing
        if args.misbehave == "wrong-type":
            response["fridgeDoor"] = {"@type": "home:RoomTemperature", "celsius": 4.0}
            return True
        response["fridgeDoor"] = {"@type": "home:Opened" if args.door == "open" else "home:Closed"}
        return True

    def alert(request: dict[str, Any], response: dict[str, Any]) -> bool:
        state = str(request.get("doorStatus", {}).get("@type", "?")).rsplit("#", 1)[-1]
        print(f"phone: ALERT the fridge door is {state} (to {request.get('person', {}).get('@id')})", flush=True)
        response["alert"] = {"@type": "home:AlarmMessage", "text": f"The fridge door is {state}."}
        return True

    devices = [
        (
            Device(args.bridge, token, args.sensor, "/lab6_fridge_door_sensor_01/check", "lab6_msgs/CheckFridgeDoor"),
            check,
        ),
        (
            Device(
                args.bridge,
                token,
                HERE / "lab6_caregiver_phone.ttl",
                "/lab6_resident_phone_01/alert",
                "lab6_msgs/Alert",
            ),
            alert,
        ),
    ]
    names = []
    for device, handler in devices:
        try:
            names.append(device.registered())  # 1. register ...
        except Exception as error:  # the server's reason, said and exited on
            print(f"fridge devices: registration of {device.service} refused: {error}", file=sys.stderr, flush=True)
            return 1
        device.provide(handler)  # 2. ... then provide
        device.ros.on("close", lambda *_: stop("the server closed the connection"))
    print(f"fridge devices: registered {names}", flush=True)
    while all(device.ros.is_connected for device, _ in devices) and not ended.wait(LEASE / 3):
        for device, _ in devices:  # 3. three beats a lease, on a schedule
            device.beat(stop)
    return 1  # for a supervisor to restart it


if __name__ == "__main__":
    sys.exit(main())
