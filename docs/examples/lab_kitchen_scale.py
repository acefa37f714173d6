"""A kitchen scale as a cbrs component of its own process (docs/components.md, "A lab's own device").

It registers docs/examples/lab_weigh_object.ttl over the bridge and answers /kitchen_scale_01/weigh
with the weight of the object the plan put on its plate. The simulated home has no load cell, so this
stand-in reads the object's home:massKg from the server's map (GET /store, one graph, matched by
pattern: nothing of the request goes into a query). A real scale reads its load cell here instead.

    CBRS_UPDATE_TOKEN=secret python docs/examples/lab_kitchen_scale.py \
        [--bridge ws://127.0.0.1:9090] [--url http://127.0.0.1:8080]
"""

from __future__ import annotations

import argparse
import os
import urllib.parse
import urllib.request
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cbrs.component import Component

HERE = Path(__file__).resolve().parent
MAP_GRAPH = "https://w3id.org/cbrs/graph/map"
MASS = ox.NamedNode("https://w3id.org/cbrs/home#massKg")


def mass_of(server: str, thing: str) -> float:
    """The object's mass as the server's map states it; raises when the map states none."""
    query = urllib.parse.urlencode({"graph": MAP_GRAPH})
    request = urllib.request.Request(f"{server}/store?{query}", headers={"Accept": "application/n-triples"})
    with urllib.request.urlopen(request, timeout=5) as answer:
        triples = ox.parse(answer.read(), format=ox.RdfFormat.N_TRIPLES)
    for triple in triples:
        if triple.subject == ox.NamedNode(thing) and triple.predicate == MASS:
            return float(triple.object.value)
    raise LookupError(f"the map states no home:massKg of <{thing}>: nothing to read off the scale")


def scale(server: str) -> Component:
    component = Component((HERE / "lab_weigh_object.ttl").read_text(encoding="utf-8"))

    @component.handler
    def weigh(request: dict[str, Any]) -> dict[str, Any]:
        thing = request["object"]["@id"]  # the designator the plan sends: {"@id": ..., "@type": ...}
        grams = round(mass_of(server, thing) * 1000.0, 1)
        return {"weight": {"@type": "home:ObjectWeight", "object": thing, "grams": grams}}

    return component


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bridge", default="ws://127.0.0.1:9090", help="the bridge of cbrs serve")
    parser.add_argument("--url", default="http://127.0.0.1:8080", help="the HTTP base URL of cbrs serve")
    options = parser.parse_args()
    scale(options.url).run(options.bridge, token=os.environ.get("CBRS_UPDATE_TOKEN"))
