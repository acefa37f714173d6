"""Components in other processes: register over the bridge, get matched, planned and invoked, and go.

A server runs in this process on loopback ports; components connect to its bridge like any program
(the SDK, cbrs.component). Every wait is a bounded poll."""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import httpx
import pyoxigraph as ox
import pytest

from cbrs.actions.components import Status
from cbrs.actions.composer import Composer
from cbrs.actions.remote import RemoteCallError, RemoteComponent
from cbrs.actions.runner import run_task
from cbrs.bridge_client import BridgeClient
from cbrs.component import Component
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.server import ServeConfig, Server
from cbrs.sim.components import SimEnvironment
from cbrs.sim.values import check
from cbrs.sim.world import open_world
from cbrs.sparql_service import EndpointConfig
from tests.helpers_roslibjs import needs_roslibjs, node_command
from tests.test_rosapi_typedefs import cbrs_types, mismatches

TOKEN = "live-components-test-token"
SVC, HOME, REQ = PREFIXES["svc"], PREFIXES["home"], PREFIXES["req"]
THERMOMETER = SVC + "ReadRoomTemperature_Thermometer07"


def thermometer(service: str = "/thermometer07/read", kind: str = "home:RoomTemperature", port: bool = True) -> str:
    grounding = (
        f'; cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "read" ; cbrs:topic "{service}" ; '
        'cbrs:messageType "cbrs_msgs/RoomTemperature" ]'
        if port
        else ""
    )
    return f"""
@prefix svc: <{SVC}> . @prefix home: <{HOME}> . @prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
svc:ReadRoomTemperature_Thermometer07 a cbrs:DynamicPerceptionComponent ;
    rdfs:label "Room temperature (thermometer 7)"@en ;
    cbrs:deviceName "Thermometer07" ; cbrs:serviceName "ReadRoomTemperature" ;
    cbrs:serviceCategory "EnvironmentalSensing" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "roomTemperature" ; cbrs:parameterType {kind} ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:LivingRoom ;
        cbrs:minX 0.0 ; cbrs:maxX 6.0 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;
    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:updateRate 1.0 ; cbrs:accuracy 0.95 ]
    {grounding} .
"""


READING = {"roomTemperature": {"@type": "home:RoomTemperature", "celsius": 21.5}}


@contextmanager
def live_server() -> Iterator[Server]:
    """A server over a fresh in-memory store, its endpoint in-process, stopped on leaving."""
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    running.start()
    try:
        yield running
    finally:
        running.stop()


@pytest.fixture
def server() -> Iterator[Server]:
    with live_server() as running:
        yield running


def url(server: Server) -> str:
    return f"ws://127.0.0.1:{server.bridge_port}"


def eventually(condition: Callable[[], bool], seconds: float = 5.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


def sdk_thermometer(answer: Callable[[dict[str, Any]], dict[str, Any]] = lambda request: READING) -> Component:
    component = Component(thermometer())
    component.handler(answer)
    return component


def test_a_component_written_with_the_sdk_is_matched_planned_and_invoked(server: Server) -> None:
    kb = server.kb
    assert not kb.registry.is_registered(THERMOMETER)
    calls: list[dict[str, Any]] = []

    def read(request: dict[str, Any]) -> dict[str, Any]:
        calls.append(request)
        return READING

    with sdk_thermometer(read).connect(url(server), TOKEN) as connected:
        assert connected.registered == [THERMOMETER]
        assert kb.liveness.states()[THERMOMETER].live
        ranking = Matchmaker(kb, "sem-str").rank(REQ + "RoomTemperature", explain=0)
        assert ranking.candidates[0].advertisement == THERMOMETER
        plan = Composer(kb).compose(REQ + "RoomTemperature").plan
        assert plan is not None and plan.components() == [THERMOMETER]
        with open_world(semantic_map=SemanticMap.read(kb)) as world, BridgeClient(url(server), TOKEN) as bridge:
            result = run_task(kb, REQ + "RoomTemperature", SimEnvironment(world, kb, bridge), composer=Composer(kb))
        assert result.succeeded, result.report
        assert calls == [{}]
        step = result.report.steps[0] if result.report else None
        assert step is not None and step.attempts[0].component == THERMOMETER


def test_a_component_that_disconnects_is_unavailable_at_once_and_comes_back_when_it_registers_again(
    server: Server,
) -> None:
    kb = server.kb
    connected = sdk_thermometer().connect(url(server), TOKEN)
    assert THERMOMETER in [ad.iri for ad in kb.advertisements()]
    connected.stop()
    assert eventually(lambda: not kb.liveness.states()[THERMOMETER].live)
    state = kb.liveness.states()[THERMOMETER]
    assert state.reason == "its session closed"
    assert THERMOMETER not in [ad.iri for ad in kb.advertisements()]  # not matched, not planned
    assert THERMOMETER in [ad.iri for ad in kb.advertisements(include_unavailable=True)]
    assert kb.registry.is_registered(THERMOMETER)  # the description is kept
    rows = kb.select("component_liveness", {"component": THERMOMETER})
    assert [row["live"].value for row in rows] == ["false"]
    with sdk_thermometer().connect(url(server), TOKEN):
        assert kb.liveness.states()[THERMOMETER].live
        assert THERMOMETER in [ad.iri for ad in kb.advertisements()]


def test_a_component_that_stops_renewing_its_lease_lapses(server: Server) -> None:
    kb = server.kb
    with BridgeClient(url(server), TOKEN) as client:  # registers, provides, but sends no heartbeat
        client.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
        registered = client.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 0.3})
        beat = client.call_sync("/cbrs/heartbeat", {})  # one beat, then none
        assert registered["components"] == beat["components"] == [THERMOMETER]
        types = cbrs_types()  # the replies are what rosapi's typedefs say (tests/test_rosapi_typedefs.py)
        assert mismatches(types.response("cbrs/Register"), registered) == []
        assert mismatches(types.response("cbrs/Heartbeat"), beat) == []
        assert kb.liveness.states()[THERMOMETER].live
        assert eventually(lambda: not kb.liveness.states()[THERMOMETER].live)
        assert kb.liveness.states()[THERMOMETER].reason == "its lease lapsed"


def test_a_registration_with_unset_fields_as_a_ros_client_sends_them_takes_the_defaults(server: Server) -> None:
    """A form built from cbrs/Register's typedef sends "" and 0 for the format and lease it leaves unset."""
    with BridgeClient(url(server), TOKEN) as client:
        client.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
        registered = client.call_sync("/cbrs/register", {"description": thermometer(), "format": "", "ttl": 0})
        assert registered == {"components": [THERMOMETER], "ttl": server.live.ttl}
        with pytest.raises(RemoteCallError, match="ttl"):
            client.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 0.01})


def test_heartbeats_keep_a_short_lease_alive(server: Server) -> None:
    kb = server.kb
    with sdk_thermometer().connect(url(server), TOKEN, heartbeat=0.1, ttl=0.5):
        time.sleep(1.5)  # three lease periods
        assert kb.liveness.states()[THERMOMETER].live


@pytest.mark.parametrize(
    ("description", "token", "expected"),
    [
        (thermometer(), "not-the-token", "token"),
        (thermometer(), None, "needs the update token"),
        (thermometer(port=False), TOKEN, "cbrs:messageType"),
        (thermometer(kind="home:RoomTemprature"), TOKEN, "RoomTemperature"),  # did-you-mean
        (
            thermometer().replace("ReadRoomTemperature_Thermometer07", "LocateMobileRobot_CeilingCamera01"),
            TOKEN,
            "is a component of the store, not a live one",
        ),
        ("this is not turtle", TOKEN, "registration"),
    ],
)
def test_a_bad_registration_is_refused_with_a_reason_and_leaves_the_store_as_it_was(
    server: Server, description: str, token: str | None, expected: str
) -> None:
    kb = server.kb
    before = kb.store.count()
    with BridgeClient(url(server), token) as client, pytest.raises(RemoteCallError, match=expected):
        client.call_sync("/cbrs/register", {"description": description})
    assert kb.store.count() == before


def test_the_sdk_refuses_a_description_without_a_bridge_service() -> None:
    with pytest.raises(InvalidDescriptionError, match="cbrs:messageType"):
        Component(thermometer(port=False))


def test_a_component_answering_the_wrong_type_or_never_fails_its_step_with_the_reason(server: Server) -> None:
    answers: dict[str, Any] = {"value": {"roomTemperature": {"@type": "home:PersonPosition", "x": 1.0}}}

    def read(request: dict[str, Any]) -> dict[str, Any]:
        if answers["value"] is None:
            time.sleep(2.0)  # never answers in time
        return dict(answers["value"])

    outputs = {"roomTemperature": HOME + "RoomTemperature"}
    with sdk_thermometer(read).connect(url(server), TOKEN), BridgeClient(url(server), TOKEN) as bridge:

        def invoke(timeout: float = 5.0) -> RemoteComponent:
            component = RemoteComponent(THERMOMETER, bridge, "/thermometer07/read", outputs, check, timeout)
            component.begin({})
            for _ in range(5000):  # ticks of at most a few milliseconds each
                status = component.update()
                if status is not Status.RUNNING:
                    component.outputs["status"] = status
                    break
            return component

        wrong = invoke()
        assert wrong.outputs["status"] is Status.FAILED and "wrong roomTemperature" in wrong.reason
        answers["value"] = {"temperature": 20.0}
        missing = invoke()
        assert missing.outputs["status"] is Status.FAILED and "without roomTemperature" in missing.reason
        answers["value"] = None
        silent = invoke(timeout=0.3)
        assert silent.outputs["status"] is Status.FAILED and "did not answer within 0.3 s" in silent.reason
        answers["value"] = READING
        right = invoke()
        assert right.outputs["status"] is Status.SUCCEEDED
        assert right.outputs["roomTemperature"]["@type"] == HOME + "RoomTemperature"


def test_a_component_registers_renews_and_ends_its_lease_over_http(server: Server) -> None:
    kb = server.kb
    base = f"http://127.0.0.1:{server.http_port}"
    turtle = {"Content-Type": "text/turtle"}
    with httpx.Client(base_url=base, timeout=10) as http:
        assert http.post("/components", content=thermometer(), headers=turtle).status_code == 403
        bearer = {**turtle, "Authorization": f"Bearer {TOKEN}"}
        wrong_type = http.post("/components", content=thermometer(), headers={**bearer, "Content-Type": "text/plain"})
        assert wrong_type.status_code == 415
        with BridgeClient(url(server), TOKEN) as firmware:  # the program answering the service
            firmware.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
            assert eventually(lambda: "/thermometer07/read" in dict(server.bridge.services()))
            created = http.post("/components?ttl=30", content=thermometer(), headers=bearer)
            assert created.status_code == 201, created.text
            lease = created.json()["lease"]
            assert created.json()["components"] == [THERMOMETER]
            listed = {row["component"]: row for row in http.get("/components").json()}
            assert listed[THERMOMETER]["available"] is True
            renewed = http.post(f"/components/leases/{lease}", headers=bearer)
            assert renewed.json() == {"components": [THERMOMETER]}
            assert http.delete(f"/components/leases/{lease}", headers=bearer).status_code == 204
        assert not kb.liveness.states()[THERMOMETER].live
        assert http.post(f"/components/leases/{lease}", headers=bearer).status_code == 404
        listed = {row["component"]: row for row in http.get("/components").json()}
        assert listed[THERMOMETER]["available"] is False and listed[THERMOMETER]["reason"] == "its session closed"


def test_a_description_in_json_ld_registers_like_turtle(server: Server) -> None:
    triples = list(ox.parse(thermometer().encode("utf-8"), format=ox.RdfFormat.TURTLE))
    json_ld = ox.serialize(triples, format=ox.RdfFormat.JSON_LD)
    assert json_ld is not None
    headers = {"Content-Type": "application/ld+json", "Authorization": f"Bearer {TOKEN}"}
    with BridgeClient(url(server), TOKEN) as firmware:  # the program answering the service
        firmware.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
        assert eventually(lambda: "/thermometer07/read" in dict(server.bridge.services()))
        created = httpx.post(f"http://127.0.0.1:{server.http_port}/components", content=json_ld, headers=headers)
        assert created.status_code == 201, created.text
        assert server.kb.liveness.states()[THERMOMETER].live
    assert server.kb.description(THERMOMETER).outputs[0].type == HOME + "RoomTemperature"


@needs_roslibjs
def test_a_component_written_with_roslibjs_registers_and_is_invoked(server: Server, tmp_path: Path) -> None:
    kb = server.kb
    description = tmp_path / "thermometer.ttl"
    description.write_text(thermometer(), encoding="utf-8")
    command = node_command("thermometer.mjs", server.bridge_port, TOKEN, description, 60)
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None
        first = json.loads(child.stdout.readline())  # blocks until registered; the script gives up by itself
        assert first == {"registered": [THERMOMETER]}
        assert kb.liveness.states()[THERMOMETER].live
        with open_world(semantic_map=SemanticMap.read(kb)) as world, BridgeClient(url(server), TOKEN) as bridge:
            result = run_task(kb, REQ + "RoomTemperature", SimEnvironment(world, kb, bridge), composer=Composer(kb))
        assert result.succeeded, result.report
        assert json.loads(child.stdout.readline()) == {"answered": {}}
    finally:
        child.kill()  # stopped by its PID
        child.wait(timeout=10)
    assert eventually(lambda: not kb.liveness.states()[THERMOMETER].live)


def test_rosout_carries_the_servers_log_and_rosapi_describes_the_bridge(
    server: Server, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level("INFO", logger="cbrs")  # what cbrs serve's log_level setting does
    heard: list[dict[str, Any]] = []
    with BridgeClient(url(server), TOKEN) as listener:
        listener.subscribe("/rosout", heard.append)
        time.sleep(0.2)  # the subscription is in place before the registration logs
        with sdk_thermometer().connect(url(server), TOKEN):
            assert eventually(lambda: any("registered" in message["msg"] for message in heard))
        record = next(message for message in heard if "registered" in message["msg"])
        assert record["level"] == 2 and record["name"] == "cbrs.live_components"
        details = listener.call_sync("/rosapi/node_details", {"node": "/cbrs_rosbridge"})
        assert "/rosout" in details["publishing"] and "/cbrs/register" in details["services"]
        assert listener.call_sync("/rosapi/service_node", {"service": "/cbrs/register"}) == {"node": "/cbrs_rosbridge"}
        log = listener.call_sync("/rosapi/message_details", {"type": "rosgraph_msgs/Log"})["typedefs"]
        assert log[0]["type"] == "rosgraph_msgs/Log" and mismatches(log, record) == []  # what /rosout sends
        raw = listener.call_sync("/rosapi/topics_and_raw_types", {})
        assert "/rosout" in raw["topics"] and len(raw["typedefs_full_text"]) == len(raw["topics"])


def test_a_flooding_component_harms_no_plan_and_no_store(server: Server) -> None:
    kb = server.kb
    with sdk_thermometer().connect(url(server), TOKEN), BridgeClient(url(server), TOKEN) as flood:
        before = kb.store.count()
        beats = [flood.call("/cbrs/heartbeat", {}, 10.0) for _ in range(500)]  # as fast as it can send
        for beat in beats:  # each is answered (this session has no component of its own), or refused past
            # the bridge's max_calls_per_client (256 waiting); none harms
            with pytest.raises(RemoteCallError, match=r"no live component|max_calls_per_client"):
                beat.result(timeout=20)
        huge = flood.call("/cbrs/register", {"description": "# " + "x" * (300 << 10)}, 10.0)
        with pytest.raises(RemoteCallError, match="larger than"):
            huge.result(timeout=20)
        assert kb.store.count() == before  # no write for any of it
        with open_world(semantic_map=SemanticMap.read(kb)) as world, BridgeClient(url(server), TOKEN) as bridge:
            result = run_task(kb, REQ + "RoomTemperature", SimEnvironment(world, kb, bridge), composer=Composer(kb))
        assert result.succeeded, result.report
        assert kb.liveness.states()[THERMOMETER].live
