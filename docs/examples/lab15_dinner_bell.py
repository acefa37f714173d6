"""The kitchen's dinner bell as a cbrs component of its own process (docs/components.md, "Writing one").

It registers docs/examples/lab15_dinner_bell.ttl over the bridge and answers /lab15_dinner_bell_01/ring
with the chime it rang, for the mat the plan names. A real bell drives its solenoid in ``ring``; this
one prints the chime. With cbrs serve's bridge, lab15_place_setting.ttl loaded (docs/tasks.md, "A
fifteenth round"):

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab15_dinner_bell.py [--bridge ws://127.0.0.1:9090]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from cbrs.component import Component

HERE = Path(__file__).resolve().parent
MAT = "https://example.org/lab15#Mat1"
"""The mat the bell calls people to (lab15_place_setting.ttl)."""


def ring(request: dict[str, Any]) -> dict[str, Any]:
    """Ring for the mat the plan names; a request for another mat is refused, nothing rung."""
    mat = request.get("mat", {}).get("@id")
    if mat != MAT:
        raise ValueError(f"this bell calls people to {MAT}, not to {mat}")
    print(f"dinner bell: ding, ding: the table at {mat} is set", flush=True)
    return {"chime": {"@type": "https://example.org/lab15#Chime", "mat": mat, "rings": 2}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="cbrs serve's rosbridge URL")
    args = parser.parse_args()
    bell = Component((HERE / "lab15_dinner_bell.ttl").read_text("utf-8"))
    bell.handler(ring)
    bell.run(args.bridge, token=os.environ.get("CBRS_UPDATE_TOKEN"))


if __name__ == "__main__":
    main()
