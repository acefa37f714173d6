"""A component in another process, as docs/execution.md's step by step writes it: the bedroom door motor
of docs/examples/lab_bedroom_door_motor.py in a child process, registered on a loopback server whose
store has the examples' door (map) and tasks (requirements) loaded. Its open service is planned for
OpenTheBedroomDoor and answers over the bridge; killed, it leaves no plan; made to contradict its effect,
the run (one, through /cbrs/run_task) fails naming it, and the store is as it was. Children are stopped
by their PID; every wait is a bounded poll."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.actions.composer import Composer
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import HOME, PREFIXES
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import eventually

TOKEN = "blind-component-token"
EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
LAB = "https://example.org/lab#"
OPEN, CLOSE = LAB + "OpenDoor_BedroomDoorMotor01", LAB + "CloseDoor_BedroomDoorMotor01"
DOOR = {"@id": LAB + "BedroomDoor", "@type": HOME + "Door"}
KEPT = ("map", "services", "requirements")
"""Graphs a misbehaving component must leave as they were (plans and liveness record what happened; the
belief graph, world, is set up by a run: of it, nothing may be said of the door)."""


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab_bedroom_door.ttl"], graph="map")
    kb.load([EXAMPLES / "lab_bedroom_door_tasks.ttl"], graph="requirements")
    running = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN, isolate=False)))
    running.start()
    try:
        yield running
    finally:
        running.stop()


def _bridge(server: Server) -> str:
    return f"ws://127.0.0.1:{server.bridge_port}"


def _motor(server: Server, *options: str) -> subprocess.Popen[str]:
    """The example program, as its docstring starts it; returns once both its components are live."""
    program = [sys.executable, str(EXAMPLES / "lab_bedroom_door_motor.py"), "--bridge", _bridge(server), *options]
    child = subprocess.Popen(program, env={**os.environ, "CBRS_UPDATE_TOKEN": TOKEN}, stderr=subprocess.PIPE, text=True)
    states = server.kb.liveness.states
    live = lambda: all(iri in states() and states()[iri].live for iri in (OPEN, CLOSE))  # noqa: E731
    if not eventually(live, 20.0):
        _stop(child)
        pytest.fail(f"the door motor never registered: {child.stderr.read() if child.stderr else ''}")
    return child


def _stop(child: subprocess.Popen[str]) -> str:
    """Ends the child by its PID; its standard error."""
    if child.poll() is None:
        os.kill(child.pid, signal.SIGTERM)
    _, errors = child.communicate(timeout=10.0)
    return errors


def _graphs(kb: KnowledgeBase) -> set[tuple[str, ...]]:
    values = " ".join(f"<{PREFIXES['graph']}{name}>" for name in KEPT)
    rows = _rows(kb, f"SELECT ?g ?s ?p ?o WHERE {{ VALUES ?g {{ {values} }} GRAPH ?g {{ ?s ?p ?o }} }}")
    return {tuple(str(row[name]) for name in ("g", "s", "p", "o")) for row in rows}


def _door_status(kb: KnowledgeBase) -> list[str]:
    """The statuses the belief (graph:world) holds of the door."""
    world = PREFIXES["graph"] + "world"
    rows = _rows(kb, f"SELECT ?o WHERE {{ GRAPH <{world}> {{ <{DOOR['@id']}> <{HOME}hasStatus> ?o }} }}")
    return [str(row["o"]) for row in rows]


def _rows(kb: KnowledgeBase, query: str) -> list[ox.QuerySolution]:
    result = kb.query(query)
    assert isinstance(result, ox.QuerySolutions)
    return list(result)


def test_the_example_motor_is_planned_answers_and_once_killed_leaves_no_plan(server: Server) -> None:
    kb = server.kb
    child = _motor(server)
    try:
        plan = Composer(kb).compose(LAB + "OpenTheBedroomDoor").plan
        assert plan is not None and plan.components() == [OPEN]
        with BridgeClient(_bridge(server), TOKEN) as caller:
            answer = caller.call_sync("/bedroom_door_motor_01/open", {"door": DOOR})
        assert answer == {"doorStatus": {"@type": "home:Opened"}}
        before = _graphs(kb)
        os.kill(child.pid, signal.SIGKILL)  # vanishes while registered
        assert eventually(lambda: not kb.liveness.states()[OPEN].live, 5.0)
        assert kb.liveness.states()[OPEN].reason == "its session closed"
        outcome = Composer(kb).compose(LAB + "OpenTheBedroomDoor")
        assert outcome.plan is None
        assert "(home:Door, home:hasStatus, home:Opened)" in outcome.unsatisfied[0].text()
        assert _graphs(kb) == before and _door_status(kb) == []
    finally:
        errors = _stop(child)
    assert "the door is now home:Opened" in errors


def test_a_motor_contradicting_its_effect_fails_the_run_naming_it_and_the_store_is_as_it_was(server: Server) -> None:
    child = _motor(server, "--misbehave", "contradict")
    try:
        before = _graphs(server.kb)
        with BridgeClient(_bridge(server), TOKEN, timeout=60.0) as client:
            run = client.call_sync("/cbrs/run_task", {"task": "OpenTheBedroomDoor"}, timeout=60.0)
        after = _graphs(server.kb)
    finally:
        errors = _stop(child)
    assert run["status"] == "failed", run
    attempts = [attempt for step in run["result"]["execution"]["steps"] for attempt in step["attempts"]]
    assert attempts and {attempt["component"] for attempt in attempts} == {OPEN}
    assert all("ContradictedEffectError" in attempt["reason"] for attempt in attempts), attempts
    assert "OpenDoor_BedroomDoorMotor01" in run["result"]["execution"]["reason"]
    assert after == before
    assert _door_status(server.kb) == []  # nothing believed: the door is neither opened nor closed
    assert "the door is now" not in errors  # the handler never drove the motor
