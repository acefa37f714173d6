"""A living-room speaker as a cbrs component of its own process (docs/components.md, "A lab's own device":
"A remote answer as another remote step's input"), the program the page writes as ``speaker.py``.

It registers docs/examples/lab_living_room_speaker.ttl over the bridge and answers
/living_room_speaker_01/announce by saying the weight it is given, the kitchen scale's answer as the scale
sent it (lab_kitchen_scale.py, running beside it). A real speaker says it aloud; this one prints it.
With the scale's program and the task lab_tell_me_my_cups_weight.ttl loaded:

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab_living_room_speaker.py [--bridge ws://127.0.0.1:9090]
    CBRS_UPDATE_TOKEN=secret cbrs --store http://127.0.0.1:8080 run TellMeMyCupsWeight --bridge ws://127.0.0.1:9090
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from cbrs.component import Component

HERE = Path(__file__).resolve().parent


def announce(request: dict[str, Any]) -> dict[str, Any]:
    """Say the weight: ``{"weight": {"@type": ..., "object": ..., "grams": ...}, "listener": {...}}``."""
    print(f"speaker: it weighs {request['weight']['grams']:g} g", flush=True)  # a real one says it aloud
    return {}


def run(bridge: str, token: str | None) -> None:
    speaker = Component((HERE / "lab_living_room_speaker.ttl").read_text(encoding="utf-8"))
    speaker.handler(announce)
    speaker.run(bridge, token=token)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    run(parser.parse_args().bridge, os.environ.get("CBRS_UPDATE_TOKEN"))
