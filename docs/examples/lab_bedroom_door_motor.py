"""A bedroom door motor as two cbrs components of its own process (docs/execution.md, "Your own
component in another process, step by step").

It registers lab_open_door.ttl and lab_close_door.ttl over the bridge (the SDK, cbrs.component; one
Component per service, each on a connection of its own) and answers /bedroom_door_motor_01/open and
/bedroom_door_motor_01/close with the door's new status. A real motor drives its relay in ``drive``.
``--misbehave`` makes the open service misbehave on purpose, to see what a run does then:

    late        answers after 15 s, past the 10 s a call may take: the step fails "did not answer"
    garbage     answers a text where a home:DoorStatus is due: the step fails naming the answer
    contradict  answers home:Closed to "open": the step fails, ContradictedEffectError
    crash       exits mid-call (status 3): the step fails "the provider ... disconnected"

In the last three cases nothing of the answer is believed: the store stays as it was. The late answer,
when it comes, is checked as an in-time one and then believed: the door open (docs/reliability.md,
section 6). With the server of the
steps (the map's door and the two tasks loaded, CBRS_UPDATE_TOKEN set as for cbrs serve):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab_bedroom_door_motor.py [--bridge ws://127.0.0.1:9090]
    CBRS_UPDATE_TOKEN=secret cbrs --store http://127.0.0.1:8080 run OpenTheBedroomDoor --bridge ws://127.0.0.1:9090
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

from cbrs.component import Component

HERE = Path(__file__).resolve().parent
MISBEHAVIOURS = ("late", "garbage", "contradict", "crash")


def drive(status: str) -> None:
    """Move the door; a real motor switches its relay here and waits for the end stop."""
    print(f"door motor: the door is now {status}", file=sys.stderr, flush=True)


def opener(misbehave: str | None) -> Any:
    def open_door(request: dict[str, Any]) -> dict[str, Any]:
        # request: {"door": {"@id": ".../lab#BedroomDoor", "@type": ".../home#Door"}}, the door the task names
        if misbehave == "late":
            time.sleep(15.0)
        elif misbehave == "garbage":
            return {"doorStatus": "wide open"}
        elif misbehave == "contradict":
            return {"doorStatus": {"@type": "home:Closed"}}
        elif misbehave == "crash":
            os._exit(3)
        drive("home:Opened")
        return {"doorStatus": {"@type": "home:Opened"}}

    return open_door


def close_door(request: dict[str, Any]) -> dict[str, Any]:
    drive("home:Closed")
    return {"doorStatus": {"@type": "home:Closed"}}


def run(bridge: str, token: str | None, misbehave: str | None) -> None:
    opening = Component((HERE / "lab_open_door.ttl").read_text(encoding="utf-8"))
    closing = Component((HERE / "lab_close_door.ttl").read_text(encoding="utf-8"))
    opening.handler(opener(misbehave))
    closing.handler(close_door)
    with opening.connect(bridge, token=token):  # served from threads of its own
        closing.run(bridge, token=token)  # until Ctrl-C or SIGTERM; status 1 when it cannot serve


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    parser.add_argument("--misbehave", choices=MISBEHAVIOURS, help="make the open service misbehave, on purpose")
    arguments = parser.parse_args()
    run(arguments.bridge, os.environ.get("CBRS_UPDATE_TOKEN"), arguments.misbehave)
