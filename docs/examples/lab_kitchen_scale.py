"""A kitchen scale as a cbrs component of its own process (docs/components.md, "A lab's own device").

It registers docs/examples/lab_weigh_object.ttl over the bridge and answers /kitchen_scale_01/weigh
with what its plate bears. Its load cell is the simulation's: ``/sim/load`` on the same bridge (the
simulated home's sensor service, answered from the physics of the run going on, a task run of the
server's or a ``cbrs run --bridge``'s, docs/components.md "The simulation's sensors"). A real scale
reads its own load cell in ``read_plate`` instead. An empty plate is no weight: the call fails saying
so, and the run re-plans or fails naming the scale.

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab_kitchen_scale.py [--bridge ws://127.0.0.1:9090]
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cbrs.bridge_client import BridgeClient
from cbrs.component import Component

HERE = Path(__file__).resolve().parent
PLATE = "https://example.org/lab#KitchenScale01Plate"
"""The scale's own plate (docs/examples/lab_kitchen_scale.ttl): what its load cell is under."""
LOAD_SERVICE = "/sim/load"
EMPTY_BELOW = 1.0
"""Grams: a reading below this is an empty plate (the scale's resolution)."""


class EmptyPlateError(Exception):
    """The plate bears nothing to weigh; keeps the reading in grams."""

    def __init__(self, grams: float) -> None:
        self.grams = grams
        super().__init__(f"the plate reads {grams:.1f} g: nothing is on it to weigh")


def read_plate(sensor: BridgeClient) -> float:
    """Grams on the plate, from the load cell (here: the simulation's, through the bridge)."""
    reading = sensor.call_sync(LOAD_SERVICE, {"place": PLATE})
    return float(reading["load_kg"]) * 1000.0


def weigher(read: Callable[[], float]) -> Callable[[dict[str, Any]], dict[str, Any]]:
    """The handler: the weight of what stands on the plate, answered for the object the plan put there."""

    def weigh(request: dict[str, Any]) -> dict[str, Any]:
        plate = request.get("plate", {}).get("@id", PLATE)  # the designators the plan sends: {"@id", "@type"}
        if plate != PLATE:
            raise ValueError(f"this scale weighs on {PLATE}, not on {plate}")
        grams = round(read(), 1)
        if grams < EMPTY_BELOW:
            raise EmptyPlateError(grams)
        return {"weight": {"@type": "home:ObjectWeight", "object": request["object"]["@id"], "grams": grams}}

    return weigh


def run(bridge: str, token: str | None) -> None:
    component = Component((HERE / "lab_weigh_object.ttl").read_text(encoding="utf-8"))
    with BridgeClient(bridge, token) as sensor:
        component.handler(weigher(lambda: read_plate(sensor)))
        component.run(bridge, token=token)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    run(parser.parse_args().bridge, os.environ.get("CBRS_UPDATE_TOKEN"))
