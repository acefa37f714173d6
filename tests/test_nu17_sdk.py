"""What a lab meets first with the component SDK, each said where it happens: a start hook that fails
leaves nothing serving, a read-only server says so instead of asking for a token, and an answer the
server refuses is logged in the component's own process. A server runs in this process on loopback;
every wait is a bounded poll."""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator

import pytest

from cbrs.bridge_client import BridgeClient
from cbrs.component import RegistrationRefusedError
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import THERMOMETER, TOKEN, eventually, sdk_thermometer, server, url

__all__ = ["server"]  # the fixture, used by name


@pytest.fixture
def read_only_server() -> Iterator[Server]:
    running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig()))
    running.start()
    try:
        yield running
    finally:
        running.stop()


def test_a_start_hook_that_raises_leaves_the_component_unavailable_and_runs_no_stop_hook(server: Server) -> None:
    made = sdk_thermometer()
    stopped: list[str] = []

    @made.on_start
    def open_relay() -> None:
        raise OSError("relay board /dev/ttyUSB0 not found")

    made.on_stop(lambda: stopped.append("on_stop"))
    with pytest.raises(OSError, match="ttyUSB0"):
        made.connect(url(server), TOKEN)
    assert eventually(lambda: not server.kb.liveness.states()[THERMOMETER].live)
    assert server.kb.liveness.states()[THERMOMETER].reason == "its session closed"
    assert "/thermometer07/read" not in dict(server.bridge.services())  # nobody answers its calls
    assert stopped == []


@pytest.mark.parametrize("token", [None, TOKEN], ids=["no-token", "a-token"])
def test_a_read_only_server_says_it_registers_nothing_and_how_to_start_one_that_does(
    read_only_server: Server, token: str | None
) -> None:
    with pytest.raises(RegistrationRefusedError) as refused:
        sdk_thermometer().connect(url(read_only_server), token)
    assert "read-only" in refused.value.reason and "CBRS_UPDATE_TOKEN" in refused.value.reason
    assert "send it first" not in refused.value.reason  # no token of the component's would help
    assert not read_only_server.kb.registry.is_registered(THERMOMETER)


def test_an_answer_the_server_refuses_is_logged_in_the_components_process(
    server: Server, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, logger="cbrs.bridge_client")
    huge = {"roomTemperature": {"@type": "home:RoomTemperature", "log": "x" * (2 << 20)}}  # over the 1 MiB limit
    with sdk_thermometer(lambda request: huge).connect(url(server), TOKEN), BridgeClient(url(server), TOKEN) as caller:
        with pytest.raises(Exception, match="exceeds the limit"):
            caller.call_sync("/thermometer07/read", {})
        assert eventually(lambda: "refused a message of this client" in caplog.text)
    refusals = [r for r in caplog.records if "refused a message" in r.getMessage()]
    assert "exceeds the limit" in refusals[0].getMessage()


@pytest.mark.parametrize(
    ("wrong", "said"),
    [
        pytest.param(lambda s: f"ws://127.0.0.1:{s.http_port}", "HTTP port", id="the-http-port"),
        pytest.param(lambda s: f"http://127.0.0.1:{s.bridge_port}", "not a websocket URL", id="an-http-url"),
    ],
)
def test_a_wrong_bridge_url_is_one_line_saying_which_to_give(
    server: Server, wrong: Callable[[Server], str], said: str
) -> None:
    with pytest.raises(SystemExit) as ended:
        sdk_thermometer().run(wrong(server), TOKEN)
    assert said in str(ended.value.code) and "--bridge-port" in str(ended.value.code)
    assert str(ended.value.code).startswith("cbrs component: ")


def test_a_component_given_no_token_is_told_so_in_the_sdks_words(server: Server) -> None:
    with pytest.raises(RegistrationRefusedError) as refused:
        sdk_thermometer().connect(url(server), None)
    assert "needs the update token" in refused.value.reason and "token=None" in refused.value.reason
    assert "roslibpy" not in refused.value.reason  # the advice for hand-written clients is not the SDK's
    assert not server.kb.registry.is_registered(THERMOMETER)
