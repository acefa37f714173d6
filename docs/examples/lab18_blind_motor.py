"""The window blind's motor as two cbrs components, written with roslibpy alone (no cbrs import).

The eighteenth round (docs/components.md, "Tried by a component developer"): a slow actuator. As
docs/components.md "Writing one (roslibpy)" says: the update token before ``run()``, one
``/cbrs/register`` of both components (lab18_blind_motor.ttl), then the two services advertised, and
``/cbrs/heartbeat`` three times a lease from the main thread. The motor takes seconds (``--motion``,
4 by default), longer than a roslibpy handler may block the event loop that also sends the heartbeat,
so the handler answers later: ``DeferredService`` runs the motor on a thread of Twisted's pool and
sends the ``service_response`` from the reactor when it is done. ``--behave`` makes it misbehave as
real motors do: ``late S`` (answers S s after the call), ``twice``, ``wrong`` (the opposite status),
``missing`` (no ``blindStatus``), ``text`` (the status as a string), ``crash`` (exits mid-call),
``silent`` (never answers). It prints one line of JSON once registered and one per call; it exits 1
when the server ends it. With lab18_window_blind.ttl in the ontology and the map:

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab18_blind_motor.py --bridge ws://127.0.0.1:9090
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import roslibpy
from twisted.internet import reactor

HERE = Path(__file__).resolve().parent
LAB18 = "https://example.org/lab18#"
STATUS = {"/lab18_blind_motor_01/lower": "Lowered", "/lab18_blind_motor_01/raise": "Raised"}
LEASE = 10.0  # s: a motion of 4 s blocks nothing, but the lease outlasts a slow reactor


def say(**fields: Any) -> None:
    print(json.dumps(fields), flush=True)


class DeferredService(roslibpy.Service):
    """A service whose answer is sent when ``work`` returns, from a thread: the event loop stays free."""

    def __init__(self, ros: roslibpy.Ros, name: str, service_type: str, work: Any) -> None:
        super().__init__(ros, name, service_type)
        self.work = work
        self.advertise(lambda request, response: True)  # the callback roslibpy wants; never used

    def _service_response_handler(self, request: dict[str, Any]) -> None:
        def answer(result: tuple[bool, Any] | None) -> None:
            if result is None:  # silent: no answer at all
                return
            ok, values = result
            message = {"op": "service_response", "service": self.name, "values": values, "result": ok}
            if "id" in request:
                message["id"] = request["id"]
            self.ros.send_on_ready(roslibpy.Message(message))

        def run() -> None:
            for result in self.work(self.name, request.get("args", {})):
                reactor.callFromThread(answer, result)

        reactor.callInThread(run)


def motor(behave: str, motion: float, late: float, prefix: str) -> Any:
    def work(service: str, args: dict[str, Any]) -> Any:
        say(called=service, request=args)
        status = STATUS[service]
        if behave == "crash":
            time.sleep(min(1.0, motion))
            os._exit(3)  # the driver died mid-motion
        time.sleep(late if behave == "late" else motion)  # the motor runs
        if behave == "silent":
            yield None
            return
        if behave == "wrong":
            status = "Raised" if status == "Lowered" else "Lowered"
        values: dict[str, Any] = {"blindStatus": {"@type": (prefix or LAB18) + status}}
        if behave == "missing":
            values = {}
        elif behave == "text":
            values = {"blindStatus": status.lower()}
        yield True, values
        if behave == "twice":
            yield True, values

    return work


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090")
    parser.add_argument(
        "--behave", default="ok", choices=["ok", "late", "twice", "wrong", "missing", "text", "crash", "silent"]
    )
    parser.add_argument("--motion", type=float, default=4.0, help="seconds the motor runs")
    parser.add_argument("--late", type=float, default=20.0, help="with --behave late: seconds before it answers")
    parser.add_argument(
        "--prefix", default="", help="write the status's class with this prefix (lab18:) instead of in full"
    )
    parser.add_argument("--seconds", type=float, default=600.0, help="exit 0 after this long")
    options = parser.parse_args()
    url = urlparse(options.bridge)
    ros = roslibpy.Ros(host=url.hostname or "127.0.0.1", port=url.port or 9090)
    ros.authenticate(os.environ.get("CBRS_UPDATE_TOKEN", ""), "", "", "", 0, "", 0)  # before run()
    ros.run(timeout=10)
    description = (HERE / "lab18_blind_motor.ttl").read_text()
    register = roslibpy.Service(ros, "/cbrs/register", "cbrs/Register")
    heartbeat = roslibpy.Service(ros, "/cbrs/heartbeat", "cbrs/Heartbeat")
    ended = threading.Event()
    why: list[str] = []

    def stop(reason: str) -> None:
        why.append(reason)
        ended.set()

    def registered() -> Any:
        return register.call(
            roslibpy.ServiceRequest({"description": description, "format": "turtle", "ttl": LEASE}), timeout=10
        )

    try:
        answer = registered()
    except Exception as error:
        print(f"blind motor: registration refused: {error}", file=sys.stderr, flush=True)
        return 2
    for name in STATUS:
        DeferredService(
            ros, name, "lab18_msgs/MoveBlind", motor(options.behave, options.motion, options.late, options.prefix)
        )
    say(registered=answer["components"], behave=options.behave)
    ros.on("close", lambda *_: stop("the server closed the connection"))

    def beat_failed(reason: Any) -> None:
        if (
            "was deregistered" in str(reason)
            or "advertise the service" in str(reason)
            or "no live component" in str(reason)
        ):
            stop(str(reason))

    deadline = time.monotonic() + options.seconds
    while ros.is_connected and not ended.wait(LEASE / 3) and time.monotonic() < deadline:
        heartbeat.call(roslibpy.ServiceRequest({}), callback=lambda _: None, errback=beat_failed)
    if why:
        print(f"blind motor: stopped serving: {why[0]}", file=sys.stderr, flush=True)
        os._exit(1)
    os._exit(0)  # roslibpy's reactor thread does not end by itself


if __name__ == "__main__":
    sys.exit(main())
