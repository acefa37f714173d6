"""The component SDK against a real server on loopback: a registration holds its bridge service, a lapsed
lease is registered again, the component ends loudly when it cannot serve, and its messages say what
went wrong. Every wait is a bounded poll; child processes are stopped by their PID."""

from __future__ import annotations

import json
import logging
import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path
from typing import Any

import httpx
import pytest

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient, BridgeClosedError
from cbrs.component import Component, ComponentEndedError, RegistrationRefusedError
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import READING, THERMOMETER, TOKEN, eventually, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name

ROOT = Path(__file__).resolve().parents[1]
OTHER = THERMOMETER.replace("Thermometer07", "Thermometer08")


def other_thermometer(service: str = "/thermometer07/read") -> str:
    """A second device whose description was copied from the first and names the same service."""
    return thermometer(service).replace("Thermometer07", "Thermometer08")


def component(description: str, answer: dict[str, Any] | None = None, name: str = "") -> Component:
    made = Component(description)
    made.handler(lambda request: {**(answer or READING), **({"by": name} if name else {})})
    return made


def serve_in_thread(connected: Any) -> tuple[threading.Thread, list[BaseException]]:
    """``connected.serve()`` in a thread; what it raised lands in the list."""
    raised: list[BaseException] = []

    def serve() -> None:
        try:
            connected.serve()
        except BaseException as error:  # the test looks at it
            raised.append(error)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    return thread, raised


# -- a registration holds its service ----------------------------------------------------------------


def test_a_second_copy_of_a_running_component_is_refused_and_takes_nothing_from_the_first(server: Server) -> None:
    with component(thermometer(), name="first").connect(url(server), TOKEN) as first:
        second = component(thermometer(), name="second")
        with pytest.raises(RegistrationRefusedError, match="running twice") as refused:
            second.connect(url(server), TOKEN)
        assert refused.value.component == THERMOMETER
        with BridgeClient(url(server), TOKEN) as caller:  # the first still answers its service
            assert caller.call_sync("/thermometer07/read", {})["by"] == "first"
        assert server.kb.liveness.states()[THERMOMETER].live
        assert first.registered == [THERMOMETER]


def test_two_components_naming_one_service_the_second_is_refused_naming_both(server: Server) -> None:
    with component(thermometer(), name="seven").connect(url(server), TOKEN):
        with pytest.raises(RegistrationRefusedError) as refused:
            component(other_thermometer(), name="eight").connect(url(server), TOKEN)
        assert "Thermometer07" in refused.value.reason and "Thermometer08" in refused.value.reason
        assert "/thermometer07/read" in refused.value.reason
        assert not server.kb.registry.is_registered(OTHER)
        with BridgeClient(url(server), TOKEN) as caller:
            assert caller.call_sync("/thermometer07/read", {})["by"] == "seven"
    # once the first has gone, the service is free for another component
    with component(other_thermometer(), name="eight").connect(url(server), TOKEN) as eight:
        assert eight.registered == [OTHER]


def test_a_service_held_over_http_is_refused_over_the_bridge_and_the_other_way(server: Server) -> None:
    headers = {"Content-Type": "text/turtle", "Authorization": f"Bearer {TOKEN}"}
    base = f"http://127.0.0.1:{server.http_port}"
    with BridgeClient(url(server), TOKEN) as firmware:  # answers the service, registers nothing
        firmware.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
        assert eventually(lambda: "/thermometer07/read" in dict(server.bridge.services()))
        created = httpx.post(f"{base}/components?ttl=30", content=thermometer(), headers=headers)
        assert created.status_code == 201, created.text
        with pytest.raises(RegistrationRefusedError, match="Thermometer07"):
            component(other_thermometer()).connect(url(server), TOKEN)
        refused = httpx.post(f"{base}/components?ttl=30", content=other_thermometer(), headers=headers)
        assert refused.status_code == 409 and "Thermometer08" in refused.text and "Thermometer07" in refused.text


@pytest.mark.parametrize("service", ["/cbrs/run_task", "cbrs/register", "/rosapi/topics"])
def test_a_service_of_the_server_is_refused_as_a_components_grounding(server: Server, service: str) -> None:
    before = server.kb.store.count()
    with BridgeClient(url(server), TOKEN) as client, pytest.raises(RemoteCallError, match="server's own"):
        client.call_sync("/cbrs/register", {"description": thermometer(service)})
    assert server.kb.store.count() == before


# -- the lease -------------------------------------------------------------------------------------


def test_a_component_whose_lease_lapsed_registers_again(server: Server, caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.WARNING, logger="cbrs.component")
    kb = server.kb
    with component(thermometer()).connect(url(server), TOKEN, heartbeat=0.1, ttl=0.5) as connected:
        connected.heartbeat = 2.0  # the program hangs: no heartbeat for four lease periods
        assert eventually(lambda: not kb.liveness.states()[THERMOMETER].live)
        assert kb.liveness.states()[THERMOMETER].reason == "its lease lapsed"
        connected.heartbeat = 0.1  # it runs again
        assert eventually(lambda: kb.liveness.states()[THERMOMETER].live, seconds=10)
        assert eventually(lambda: "registered again" in caplog.text)  # logged once its answer is back
        with BridgeClient(url(server), TOKEN) as caller:
            assert caller.call_sync("/thermometer07/read", {}) == READING


def test_a_component_deregistered_while_live_is_told_and_ends(server: Server) -> None:
    kb = server.kb
    stopped: list[str] = []
    made = component(thermometer())
    made.on_stop(lambda: stopped.append("on_stop"))
    connected = made.connect(url(server), TOKEN, heartbeat=0.1, ttl=0.5)
    thread, raised = serve_in_thread(connected)
    with server.sparql.lock:
        kb.registry.deregister(THERMOMETER)
    thread.join(timeout=10)
    assert not thread.is_alive()
    assert len(raised) == 1 and isinstance(raised[0], ComponentEndedError)
    assert "deregistered" in str(raised[0])
    assert stopped == ["on_stop"]
    assert THERMOMETER not in kb.liveness.states()  # GET /components no longer lists it
    assert server.live.live() == []


# -- ending ----------------------------------------------------------------------------------------


def test_when_the_server_goes_the_component_ends_with_the_reason_and_its_hooks_run() -> None:
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    server = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    server.start()
    stopped: list[str] = []
    try:
        made = component(thermometer())
        made.on_stop(lambda: stopped.append("on_stop"))
        connected = made.connect(url(server), TOKEN)
        thread, raised = serve_in_thread(connected)
    finally:
        server.stop()
    thread.join(timeout=10)
    assert not thread.is_alive()
    assert len(raised) == 1 and isinstance(raised[0], ComponentEndedError)
    assert "the server closed the connection" in str(raised[0])
    assert stopped == ["on_stop"]


# The component programs take their description and reading as arguments: importing them from
# tests.test_live_components (which imports the simulator) cost each program more than a second.
HOOKED = """
import json, sys
from cbrs.component import Component
made = Component(sys.argv[3])
made.handler(lambda request: json.loads(sys.argv[4]))
made.on_stop(lambda: print("on_stop ran", flush=True))
made.on_start(lambda: print("started", flush=True))
made.run(sys.argv[1], token=sys.argv[2])
print("run returned", flush=True)
"""


def program(text: str, bridge: str) -> list[str]:
    """The command running the component program ``text`` against ``bridge``, as the thermometer."""
    return [sys.executable, "-c", textwrap.dedent(text), bridge, TOKEN, thermometer(), json.dumps(READING)]


def start_hooked(bridge: str) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen(
        program(HOOKED, bridge), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env
    )


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "Ctrl-C"])
def test_a_stop_signal_at_any_moment_after_start_runs_the_hooks_and_exits_cleanly(
    server: Server, stop: signal.Signals
) -> None:
    """Signals landing at different points of the hand-over from connecting to serving (a SIGTERM raised
    from its handler once escaped there, skipping the hooks, or hung the exit)."""
    for delay in [0.0, 0.002, 0.02]:  # one at a time: copies of one program may not serve together
        # the last copy's session ended as far as the server knows (its next registration was once refused
        # as a copy running twice, the server not having seen the last one go yet)
        assert eventually(lambda: THERMOMETER not in server.live.live())
        child = start_hooked(url(server))
        try:
            assert child.stdout is not None
            assert child.stdout.readline().strip() == "started"  # it gives up by itself if it cannot connect
            time.sleep(delay)
            child.send_signal(stop)  # by its PID
            out, err = child.communicate(timeout=20)
        finally:
            child.kill()
            child.wait(timeout=10)
        assert child.returncode == 0, err
        assert out.splitlines() == ["on_stop ran", "run returned"], err
        # run() says it is up, naming the component, the bridge and the service, before it serves
        assert f"cbrs component: svc:ReadRoomTemperature_Thermometer07 registered at {url(server)}" in err
        assert "serving /thermometer07/read until Ctrl-C or SIGTERM" in err


def test_a_server_restart_ends_a_run_component_with_status_1_and_the_reason() -> None:
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    server = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    server.start()
    try:
        child = start_hooked(url(server))
        assert child.stdout is not None
        assert child.stdout.readline().strip() == "started"
    finally:
        server.stop()
    try:
        out, err = child.communicate(timeout=20)
    finally:
        child.kill()  # by its PID
        child.wait(timeout=10)
    assert child.returncode == 1
    assert "on_stop ran" in out and "run returned" not in out
    assert "the server closed the connection" in err


# -- what the SDK says -------------------------------------------------------------------------------


def test_a_wrong_token_is_reported_in_the_servers_words(server: Server) -> None:
    with pytest.raises(RegistrationRefusedError, match="the token is not this server's update token") as refused:
        component(thermometer()).connect(url(server), "not-the-token")
    # the SDK sent the auth op itself: the advice for hand-written clients (send auth first) is not repeated
    assert "CBRS_UPDATE_TOKEN" in str(refused.value) and "roslibpy" not in str(refused.value)


@pytest.mark.parametrize(
    ("answer", "expected"),
    [
        (["opened"], r"returned \['opened'\]: a list, not a dict of the response's fields"),
        ({"roomTemperature": {"celsius": math.nan}}, "not JSON"),
    ],
)
def test_a_handler_answer_that_is_no_response_says_what_was_wrong_and_is_logged(
    server: Server, caplog: pytest.LogCaptureFixture, answer: Any, expected: str
) -> None:
    made = Component(thermometer())
    made.handler(lambda request: answer)
    with (
        made.connect(url(server), TOKEN),
        BridgeClient(url(server), TOKEN) as caller,
        pytest.raises(RemoteCallError, match=expected),
    ):
        caller.call_sync("/thermometer07/read", {})
    assert "the handler of /thermometer07/read failed" in caplog.text


def test_a_handler_that_raises_is_logged_in_the_components_process(
    server: Server, caplog: pytest.LogCaptureFixture
) -> None:
    def stall(request: dict[str, Any]) -> dict[str, Any]:
        raise RuntimeError("motor stalled")

    made = Component(thermometer())
    made.handler(stall)
    with (
        made.connect(url(server), TOKEN),
        BridgeClient(url(server), TOKEN) as caller,
        pytest.raises(RemoteCallError, match="RuntimeError: motor stalled"),
    ):
        caller.call_sync("/thermometer07/read", {})
    failed = [record for record in caplog.records if "the handler of /thermometer07/read failed" in record.message]
    assert failed and failed[0].exc_info is not None and "motor stalled" in str(failed[0].exc_info[1])


@pytest.mark.parametrize(
    ("slip", "near"),
    [("cbrs:messageType", "cbrs:messageType"), ("cbrs:topic", "cbrs:topic"), ("cbrs:ServicePort", "cbrs:ServicePort")],
)
def test_a_misspelt_grounding_gets_a_did_you_mean(slip: str, near: str) -> None:
    misspelt = slip[:-2] + slip[-1]  # cbrs:messageTye, cbrs:topc, cbrs:ServicePot
    with pytest.raises(InvalidDescriptionError, match=f"{misspelt}: did you mean {near}\\?"):
        Component(thermometer().replace(slip, misspelt))


def test_a_right_description_gets_no_did_you_mean() -> None:
    with pytest.raises(InvalidDescriptionError) as refused:
        Component(thermometer(port=False))
    assert "did you mean" not in str(refused.value)


# -- registered over HTTP: available while a bridge client provides the service ---------------------


def provided_by_the_bridge(server: Server) -> None:
    """The server wires it: a service is provided when its bridge lists it."""
    assert server.live.provided is not None
    assert not server.live.provided("/thermometer07/read")


def test_a_component_registered_over_http_needs_a_bridge_client_providing_its_service(server: Server) -> None:
    provided_by_the_bridge(server)
    headers = {"Content-Type": "text/turtle", "Authorization": f"Bearer {TOKEN}"}
    with httpx.Client(base_url=f"http://127.0.0.1:{server.http_port}", timeout=10) as http:
        nobody = http.post("/components?ttl=30", content=thermometer(), headers=headers)
        assert nobody.status_code == 409 and "/thermometer07/read is provided by no bridge client" in nobody.text
        assert not server.kb.registry.is_registered(THERMOMETER)
        with BridgeClient(url(server), TOKEN) as firmware:  # answers the service, registers nothing
            firmware.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", lambda request: READING)
            assert eventually(lambda: "/thermometer07/read" in dict(server.bridge.services()))
            created = http.post("/components?ttl=0.4", content=thermometer(), headers=headers)
            assert created.status_code == 201, created.text
            lease = created.json()["lease"]
            assert http.post(f"/components/leases/{lease}", headers=headers).status_code == 200
        # the firmware went: the lease ends at its next renewal that writes the store
        assert eventually(lambda: http.post(f"/components/leases/{lease}", headers=headers).status_code == 404)
        state = server.kb.liveness.states()[THERMOMETER]
        assert not state.live and state.reason == "no bridge client provides its service"


def test_the_sdk_registers_before_it_provides_so_the_provider_check_does_not_refuse_it(server: Server) -> None:
    provided_by_the_bridge(server)
    with component(thermometer()).connect(url(server), TOKEN, heartbeat=0.1, ttl=0.5) as connected:
        assert connected.registered == [THERMOMETER]
        with BridgeClient(url(server), TOKEN) as caller:
            assert eventually(lambda: "/thermometer07/read" in dict(server.bridge.services()))
            assert caller.call_sync("/thermometer07/read", {}) == READING
        assert server.kb.liveness.states()[THERMOMETER].live


def test_a_call_whose_send_loses_the_race_with_the_connection_ending_fails_once(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The reader's shutdown may fail a waiting call just before the call's own send finds the socket
    closed: the heartbeat thread then died of "future already finished" instead of getting its error."""
    with BridgeClient(url(server), TOKEN) as client:
        sent = client.send

        def closed_under_the_send(message: Any) -> None:
            client._shutdown("the server went while this call was sent")  # the reader got there first
            sent({"op": "status"})  # the socket itself is still open: only the order of events is forced
            raise BridgeClosedError("the connection is closed")

        monkeypatch.setattr(client, "send", closed_under_the_send)
        future = client.call("/cbrs/heartbeat", {})
        with pytest.raises(BridgeClosedError, match="went while this call was sent"):
            future.result(timeout=5)


INTERRUPTED_IN_ON_START = """
import json, os, signal, sys
from cbrs.component import Component
made = Component(sys.argv[3])
made.handler(lambda request: json.loads(sys.argv[4]))
made.on_stop(lambda: print("on_stop ran", flush=True))

@made.on_start
def start():
    print("started", flush=True)
    os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C while the hook still runs
    print("start done", flush=True)

made.run(sys.argv[1], token=sys.argv[2])
print("run returned", flush=True)
"""


def test_ctrl_c_during_on_start_lets_the_hook_finish_then_stops_with_on_stop(server: Server) -> None:
    """run() takes Ctrl-C as a note for its whole length: it raised KeyboardInterrupt wherever it landed
    while connecting, so a hook was cut short and taken for a failed start (no on_stop), or, landing
    between the hooks and the serving wait, nothing stopped the component at all."""
    command = program(INTERRUPTED_IN_ON_START, url(server))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env)
    try:
        out, err = child.communicate(timeout=30)
    finally:
        child.kill()
        child.wait(timeout=10)
    assert child.returncode == 0, err
    assert out.splitlines() == ["started", "start done", "on_stop ran", "run returned"], err
