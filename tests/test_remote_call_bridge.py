"""A provider's answer the bridge cannot read fails the call it answers at once, with the reason the
provider is told, instead of leaving the caller to wait for the call's timeout (repros 09 and 14)."""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from cbrs.rosbridge import Bridge, RunningBridge
from tests.helpers_threads import assert_threads_end
from tests.test_rosbridge import WAIT, Client, client_maker

LIMIT = 4096
CALL_TIMEOUT = 120.0
"""Far longer than any wait here: an answer the caller gets came from the bridge's refusal, not the timer."""


@pytest.fixture
def clients() -> Iterator[Callable[[], Client]]:
    threads = threading.active_count()
    running: RunningBridge = Bridge(call_timeout=CALL_TIMEOUT, max_message_bytes=LIMIT).start(port=0)
    with client_maker(running.url) as make:
        yield make
    assert running.stop(timeout=5.0)
    assert_threads_end(threads, WAIT)


def _provided(make: Callable[[], Client]) -> tuple[Client, Client, str]:
    """A provider of /door/open and a caller whose call it has been given; the call's id at the provider."""
    provider, caller = make(), make()
    provider.send(op="advertise_service", service="/door/open", type="lab/OpenDoor")
    provider.sync()
    caller.send(op="call_service", service="/door/open", args={}, id="c1")
    request = provider.expect("call_service")
    return provider, caller, str(request["id"])


@pytest.mark.parametrize(
    ("fields", "said"),
    [
        ({"result": "yes", "values": {"doorStatus": {}}}, "field 'result' must be a boolean, not string"),
        ({"result": True, "values": 42}, "field 'values' must be an object or a string, not number"),
    ],
    ids=["result-string", "values-number"],
)
def test_a_malformed_answer_fails_its_call_at_once_with_the_reason(
    clients: Callable[[], Client], fields: dict[str, Any], said: str
) -> None:
    provider, caller, key = _provided(clients)
    provider.send(op="service_response", service="/door/open", id=key, **fields)
    status = provider.expect("status")
    assert status["id"] == key and said in status["msg"]  # the provider is told, as before
    answer = caller.expect("service_response")
    assert answer["id"] == "c1" and answer["result"] is False
    assert answer["values"] == f"service '/door/open' answered with a service_response that could not be read: {said}"
    provider.send(op="service_response", service="/door/open", id=key, result=True, values={})
    assert "no call with id" in provider.expect("status")["msg"]  # the call is over
    caller.nothing()


def test_an_answer_over_the_size_limit_fails_its_call_at_once(clients: Callable[[], Client]) -> None:
    provider, caller, key = _provided(clients)
    other = clients()
    other.send(op="call_service", service="/door/open", args={}, id="c2")
    second = provider.expect("call_service")["id"]
    big = {"op": "service_response", "service": "/door/open", "id": key, "result": True, "values": {"s": "x" * LIMIT}}
    provider.ws.send(json.dumps(big))
    assert "exceeds the limit of 4096 bytes" in provider.expect("status")["msg"]
    answer = caller.expect("service_response")
    assert answer["result"] is False and "exceeds the limit of 4096 bytes (max_message_bytes)" in answer["values"]
    other.nothing()  # the other call, whose id the answer did not carry, still waits
    provider.send(op="service_response", service="/door/open", id=second, result=True, values={"ok": 1})
    assert other.expect("service_response")["values"] == {"ok": 1}


def test_a_malformed_answer_from_another_client_does_not_end_the_call(clients: Callable[[], Client]) -> None:
    provider, caller, key = _provided(clients)
    stranger = clients()
    stranger.send(op="service_response", service="/door/open", id=key, result="yes", values={})
    assert "must be a boolean" in stranger.expect("status")["msg"]
    caller.nothing()
    provider.send(op="service_response", service="/door/open", id=key, result=True, values={"ok": 1})
    assert caller.expect("service_response")["values"] == {"ok": 1}
