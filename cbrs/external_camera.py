"""A ceiling camera's robot localiser as a program of its own: ``python -m cbrs.external_camera CAMERA``.

It is what a lab's camera would run: it takes the camera's bundled LocateMobileRobot description,
grounds it in a bridge service of its own, registers it with the server at ``--bridge`` (the update
token from ``CBRS_UPDATE_TOKEN``), and answers each call by taking a frame from the camera (the
simulation's ``/sim/capture``, standing in for the camera's hardware) and finding the robot's marker
in it. ``cbrs demo --external`` starts two of them and kills one mid-run.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
from typing import Any

import pyoxigraph as ox

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.component import Component
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.semantic_map import SemanticMap
from cbrs.kb.vocab import CBRS
from cbrs.sim.perception import locate_robot
from cbrs.sim.values import to_json
from cbrs.sim.world import marker_model
from cbrs.sim_sensors import CAPTURE_SERVICE, frame_from_json

__all__ = ["LOCATE", "description", "localiser", "localisers", "main"]

LOCATE = "LocateMobileRobot"
"""The service the camera programs run (a service name, as the simulation's skills are named)."""


def localisers(kb: KnowledgeBase) -> dict[str, str]:
    """The cameras of the semantic map with a LocateMobileRobot component: device name -> component IRI."""
    cameras = {camera.name for camera in SemanticMap.read(kb).cameras.values()}
    return {
        ad.device_name: ad.iri
        for ad in kb.advertisements()
        if ad.service_name == LOCATE and ad.device_name is not None and ad.device_name in cameras
    }


def description(kb: KnowledgeBase, camera: str) -> str:
    """The camera's bundled LocateMobileRobot description, grounded in ``/<camera>/locate_robot``."""
    found = localisers(kb).get(camera)
    if found is None:
        raise SystemExit(f"the store has no {LOCATE} component of a camera named {camera} to run")
    component = ox.NamedNode(found)
    quads = kb.registry.description_quads(component.value)
    port = ox.NamedNode(component.value + "_bridge_port")
    graph = GraphName.SERVICES.node
    grounding = [
        ox.Quad(component, ox.NamedNode(CBRS.hasPort), port, graph),
        ox.Quad(port, ox.NamedNode(PREFIXES["rdf"] + "type"), ox.NamedNode(CBRS.ServicePort), graph),
        ox.Quad(port, ox.NamedNode(CBRS.portName), ox.Literal("locate"), graph),
        ox.Quad(port, ox.NamedNode(CBRS.topic), ox.Literal(f"/{camera.lower()}/locate_robot"), graph),
        ox.Quad(port, ox.NamedNode(CBRS.messageType), ox.Literal(f"cbrs_msgs/{LOCATE}"), graph),
    ]
    triples = [ox.Triple(q.subject, q.predicate, q.object) for q in (*quads, *grounding)]
    written = ox.serialize(triples, format=ox.RdfFormat.TURTLE)
    assert written is not None
    return written.decode("utf-8")


def localiser(camera: str, capture: BridgeClient, smap: SemanticMap) -> Any:
    """The handler: a frame of ``camera`` from the simulation, the marker found in it."""
    try:
        marker = marker_model(next(iter(smap.robots.values())))
    except ValueError as error:
        raise SystemExit(str(error)) from None

    # the colours the camera tells apart are the store's, as the simulation's cameras have them
    colours = {w.name: w for cam in smap.cameras.values() if cam.name == camera for w in cam.colours}

    def locate(request: dict[str, Any]) -> dict[str, Any]:
        frame = frame_from_json(capture.call_sync(CAPTURE_SERVICE, {"camera": camera}))
        return {"robotLocation": to_json(locate_robot(dataclasses.replace(frame, colours=colours), marker))}

    return locate


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cbrs.external_camera", description=__doc__.splitlines()[0])
    parser.add_argument("camera", help="the ceiling camera, e.g. CeilingCamera01")
    parser.add_argument(  # --bridge as cbrs run spells it; --url as the external demo passes it
        "--bridge",
        "--url",
        dest="url",
        default="ws://127.0.0.1:9090",
        help="the server's rosbridge websocket (%(default)s)",
    )
    parser.add_argument("--heartbeat", type=float, default=1.0, help="seconds between heartbeats (%(default)s)")
    parser.add_argument("--lease", type=float, default=3.0, help="seconds the lease lasts (%(default)s)")
    args = parser.parse_args(argv)
    token = os.environ.get("CBRS_UPDATE_TOKEN")
    kb = KnowledgeBase.open(":memory:")  # the bundled descriptions and map: the camera's own knowledge
    component = Component(description(kb, args.camera))
    try:
        with BridgeClient(args.url, token) as capture:
            component.handler(localiser(args.camera, capture, SemanticMap.read(kb)))
            connected = component.connect(args.url, token, args.heartbeat, args.lease)
            print(f"{args.camera}: registered {', '.join(connected.registered)}", flush=True)
            connected.serve()
    except (RemoteCallError, ConnectionError) as error:  # refused, or no server: one line, as the CLI says it
        print(f"Error: {args.camera}: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
