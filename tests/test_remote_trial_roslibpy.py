"""The roslibpy component of docs/components.md, run as the docs give it (a child process, roslibpy
unchanged): it registers, answers a call, registers again after a pause longer than its lease, and ends
with status 1 and the reason once deregistered. Loopback only; the child is stopped by its PID; every
wait is a bounded poll."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.bridge_client import BridgeClient
from cbrs.server import Server
from tests.test_live_components import THERMOMETER, TOKEN, eventually, live_server, thermometer

pytest.importorskip("roslibpy")

DOCS = Path(__file__).resolve().parents[1] / "docs" / "components.md"
LAB = THERMOMETER.replace("Thermometer07", "LabThermo12")


def docs_program(port: int) -> str:
    """The roslibpy block of components.md, its port the test server's."""
    text = DOCS.read_text(encoding="utf-8")
    section = text[text.index("## Writing one (roslibpy)") :]
    block = re.search(r"```python\n(.*?)```", section, re.S)
    assert block is not None, "components.md has no roslibpy program"
    assert "port=9090" in block[1]
    return block[1].replace("port=9090", f"port={port}")


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with live_server() as running:
        yield running


def test_the_roslibpy_component_of_the_docs_serves_comes_back_and_ends_loudly(server: Server, tmp_path: Path) -> None:
    renamed = thermometer().replace("Thermometer07", "LabThermo12").replace("thermometer07", "lab_thermo12")
    (tmp_path / "thermometer.ttl").write_text(renamed, encoding="utf-8")
    program = tmp_path / "thermometer_roslibpy.py"
    text = docs_program(server.bridge_port)
    assert '"CBRS_UPDATE_TOKEN"], 3.0' in text
    program.write_text(text.replace('"CBRS_UPDATE_TOKEN"], 3.0', '"CBRS_UPDATE_TOKEN"], 1.0'))  # a short lease
    child = subprocess.Popen(
        [sys.executable, str(program)],
        cwd=tmp_path,
        env={**os.environ, "CBRS_UPDATE_TOKEN": TOKEN},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        live = lambda: LAB in server.kb.liveness.states() and server.kb.liveness.states()[LAB].live  # noqa: E731
        assert eventually(live, 15.0), "the program did not register"
        with BridgeClient(f"ws://127.0.0.1:{server.bridge_port}", TOKEN) as caller:
            assert eventually(lambda: "/lab_thermo12/read" in dict(server.bridge.services()), 5.0)
            answer = caller.call_sync("/lab_thermo12/read", {})
        assert answer["roomTemperature"]["celsius"] == 22.25
        os.kill(child.pid, signal.SIGSTOP)  # paused past its lease: the server's watchdog ends it
        assert eventually(lambda: not live(), 10.0)
        os.kill(child.pid, signal.SIGCONT)
        assert eventually(live, 10.0), "the program did not register again after its lease lapsed"
        with server.sparql.lock:
            server.kb.registry.deregister(LAB)
        _, err = child.communicate(timeout=15.0)
        assert child.returncode == 1
        assert "stopped serving" in err and "was deregistered" in err
    finally:
        if child.poll() is None:
            os.kill(child.pid, signal.SIGCONT)
            child.kill()
            child.wait(timeout=5.0)
