"""The JavaScript component of docs/components.md (tests/js/thermometer.mjs) behaves as the Python SDK:
it comes back after a pause longer than its lease, a refused copy provides nothing, and it ends with
status 1 and the reason when it is deregistered. The node process is stopped by its PID; every wait is
a bounded poll."""

from __future__ import annotations

import json
import os
import signal
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from cbrs.bridge_client import BridgeClient
from cbrs.server import Server
from tests.helpers_roslibjs import needs_roslibjs, node_command
from tests.test_live_components import (
    READING,
    THERMOMETER,
    TOKEN,
    eventually,
    sdk_thermometer,
    server,
    thermometer,
    url,
)

__all__ = ["server"]  # the fixture, used by name

LEASE = 0.6  # seconds: a beat every 0.2 s


@contextmanager
def js_thermometer(server: Server, tmp_path: Path) -> Iterator[subprocess.Popen[str]]:
    description = tmp_path / "thermometer.ttl"
    description.write_text(thermometer(), encoding="utf-8")
    command = node_command("thermometer.mjs", server.bridge_port, TOKEN, description, 30, LEASE)
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        yield child
    finally:
        child.kill()  # stopped by its PID
        child.wait(timeout=10)


def live(server: Server) -> bool:
    state = server.kb.liveness.states().get(THERMOMETER)
    return state is not None and state.live


@needs_roslibjs
def test_the_js_component_registers_again_after_a_pause_longer_than_its_lease(server: Server, tmp_path: Path) -> None:
    with js_thermometer(server, tmp_path) as child:
        assert child.stdout is not None
        assert json.loads(child.stdout.readline()) == {"registered": [THERMOMETER]}
        os.kill(child.pid, signal.SIGSTOP)  # a pause: the lease lapses, the connection stays open
        try:
            assert eventually(lambda: not live(server))
        finally:
            os.kill(child.pid, signal.SIGCONT)
        assert json.loads(child.stdout.readline()) == {"registeredAgain": [THERMOMETER]}
        assert eventually(lambda: live(server))
        with BridgeClient(url(server), TOKEN) as caller:
            assert caller.call_sync("/thermometer07/read", {})["roomTemperature"]["source"] == "roslibjs"


@needs_roslibjs
def test_a_refused_js_copy_ends_with_the_reason_and_takes_no_calls(server: Server, tmp_path: Path) -> None:
    with sdk_thermometer().connect(url(server), TOKEN):
        with js_thermometer(server, tmp_path) as child:
            assert child.wait(timeout=10) == 1
            assert child.stderr is not None and "running twice" in child.stderr.read()
        with BridgeClient(url(server), TOKEN) as caller:  # the Python component still answers its service
            assert caller.call_sync("/thermometer07/read", {}) == READING


@needs_roslibjs
def test_a_deregistered_js_component_ends_with_status_1(server: Server, tmp_path: Path) -> None:
    with js_thermometer(server, tmp_path) as child:
        assert child.stdout is not None
        assert json.loads(child.stdout.readline()) == {"registered": [THERMOMETER]}
        with server.sparql.lock:
            server.kb.registry.deregister(THERMOMETER)
        assert child.wait(timeout=10) == 1
        assert child.stderr is not None and "was deregistered" in child.stderr.read()
