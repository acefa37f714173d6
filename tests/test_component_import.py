"""A component's program imports only what talking to a server needs.

``cbrs.component`` runs in a lab's own small programs (a sensor board, a camera process) that may
restart after a fault: it once brought the store, the loader, backup, the SPARQL service, the
rosbridge server and Flask with it (docs/components.md has the figures). These tests look in
``sys.modules`` of a fresh interpreter, so the weight cannot come back unnoticed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cbrs.bridge_client import BridgeClient
from cbrs.component import Component
from cbrs.kb.errors import RdfParseError
from cbrs.server import Server
from tests.test_live_components import READING, TOKEN, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name

ROOT = Path(__file__).resolve().parents[1]

HEAVY = (
    "flask",
    "werkzeug",
    "httpx",
    "networkx",
    "numpy",
    "pybullet",
    "rdflib",
    "cbrs.kb.loader",
    "cbrs.kb.backup",
    "cbrs.kb.knowledge_base",
    "cbrs.kb.store",
    "cbrs.kb.shapes",
    "cbrs.reasoner",
    "cbrs.actions.remote",
    "cbrs.actions.plan",
    "cbrs.live_components",
    "cbrs.sparql_service",
    "cbrs.server",
    "cbrs.rosbridge",
    "cbrs.sim",
)
"""Modules a component's program has no use for: the server's, the store's, the planner's, the simulator's."""

PROGRAM = """
import json, sys, threading
HEAVY = json.loads(sys.argv[1])
def heavy():
    return sorted(m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in HEAVY))
def say(stage):
    print(json.dumps([stage, heavy()]), flush=True)

from cbrs.component import Component
say("imported")
answered = threading.Event()
def read(request):
    answered.set()
    return json.loads(sys.argv[5])
made = Component(sys.argv[4])
made.handler(read)
say("described")
with made.connect(sys.argv[2], token=sys.argv[3]):
    say("serving")
    sys.stdin.readline()  # the test's call was answered (or the test went: its end of the pipe closed)
if not answered.is_set():
    raise SystemExit("no call came")
say("answered")
import cbrs.kb.loader  # the check itself: it must see a heavy module once one is imported
say("loader")
"""


def test_a_component_program_imports_nothing_heavy_to_describe_connect_register_and_answer(server: Server) -> None:
    """One fresh interpreter runs a component as a lab's program does, and says at each stage what
    it has imported."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    command = [sys.executable, "-c", PROGRAM, json.dumps(HEAVY), url(server), TOKEN, thermometer(), json.dumps(READING)]
    child = subprocess.Popen(
        command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env
    )
    try:
        assert child.stdout is not None
        said = [json.loads(child.stdout.readline()) for _ in range(3)]  # it exits by itself if it cannot connect
        assert said == [["imported", []], ["described", []], ["serving", []]]
        with BridgeClient(url(server), TOKEN) as caller:
            assert caller.call_sync("/thermometer07/read", {}) == READING
        out, err = child.communicate(input="answered\n", timeout=30)
    finally:
        child.kill()  # by its PID
        child.wait(timeout=10)
    assert child.returncode == 0, err
    answered, loader = [json.loads(line) for line in out.splitlines()]
    assert answered == ["answered", []]
    assert loader[0] == "loader" and "cbrs.kb.loader" in loader[1]


def test_a_description_oxigraph_refuses_still_gets_the_loaders_located_error() -> None:
    """The SDK reads a description with Oxigraph alone; a faulty one goes through the loader, whose error
    names the line and column, as every description's once did."""
    broken = thermometer().replace("cbrs:serviceName", "cbrs:serviceName ;;", 1)
    with pytest.raises(RdfParseError, match=r"^<component>:6:\d+: "):
        Component(broken)
