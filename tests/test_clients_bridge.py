"""Programs and rosbridge clients as a new user runs them against a served knowledge base.

The README's camera program, started beside a plain ``cbrs serve``, used to end in a traceback: the
store already holds the bundled camera it registers. It now says why in one line and exits 1, as the
CLI does, and once the bundled component makes way it registers.
"""

from __future__ import annotations

import socket
from collections.abc import Iterator

import pytest

from cbrs import external_camera
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig

TOKEN = "clients-bridge-token"
WAIT = 10.0


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    served = Server(
        KnowledgeBase.open(":memory:"),
        ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)),
    )
    served.start()
    yield served
    served.stop(timeout=WAIT)


def _closed_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_the_camera_program_without_a_server_says_so_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    url = f"ws://127.0.0.1:{_closed_port()}"
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("Error: CeilingCamera01: cannot reach the bridge") and err.count("\n") == 1, err


def test_the_camera_program_refused_says_why_in_one_line(
    server: Server, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    url = f"ws://127.0.0.1:{server.bridge_port}"
    monkeypatch.delenv("CBRS_UPDATE_TOKEN", raising=False)
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert "needs the update token" in err and err.count("\n") == 1, err
    monkeypatch.setenv("CBRS_UPDATE_TOKEN", TOKEN)
    assert external_camera.main(["--url", url, "CeilingCamera01"]) == 1
    err = capsys.readouterr().err
    assert "LocateMobileRobot_CeilingCamera01> is already registered" in err and err.count("\n") == 1, err
