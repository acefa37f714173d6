"""The SDK's heartbeat keeps its period when the server is slow to answer (a simulation running in it):
beats go out on a fixed schedule without waiting for the last answer, a slow answer is no warning, and
one warning says when no beat has been answered for half the lease. A stub client stands in for the
bridge, so that each answer comes exactly when the test says; every wait is a bounded poll."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from concurrent.futures import Future
from typing import Any

import pytest

from cbrs.component import Component, ConnectedComponent
from tests.test_live_components import READING, thermometer

RENEWED = {"components": ["svc:ReadRoomTemperature_Thermometer07"]}


class SlowServer:
    """A bridge client whose heartbeat answers wait until the test releases them."""

    def __init__(self) -> None:
        self.beats: list[Future[dict[str, Any]]] = []
        self.closed = False
        self._lock = threading.Lock()

    def call(self, service: str, args: Mapping[str, Any], timeout: float | None = None) -> Future[dict[str, Any]]:
        future: Future[dict[str, Any]] = Future()
        with self._lock:
            self.beats.append(future)
        return future

    def call_sync(self, service: str, args: Mapping[str, Any], timeout: float | None = None) -> dict[str, Any]:
        return self.call(service, args, timeout).result(timeout=(timeout or 1.0) + 1.0)

    def answer_all(self) -> None:
        with self._lock:
            waiting = [beat for beat in self.beats if not beat.done()]
        for beat in waiting:
            beat.set_result(RENEWED)

    def close(self) -> None:
        self.closed = True


def eventually(condition: Callable[[], bool], seconds: float = 5.0) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.005)
    return condition()


@pytest.fixture
def slow() -> Iterator[SlowServer]:
    yield SlowServer()


def beating(client: SlowServer, heartbeat: float, ttl: float) -> ConnectedComponent:
    made = Component(thermometer())
    made.handler(lambda request: READING)
    return ConnectedComponent(made, client, heartbeat, ["svc:ReadRoomTemperature_Thermometer07"], ttl)  # type: ignore[arg-type]


def warnings(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == "cbrs.component" and r.levelno >= logging.WARNING]


def test_the_next_beat_goes_out_while_the_last_is_unanswered(slow: SlowServer) -> None:
    with beating(slow, heartbeat=0.02, ttl=5.0):
        assert eventually(lambda: len(slow.beats) >= 3)
        assert not any(beat.done() for beat in slow.beats[:3])  # none was answered, yet three went out


def test_answers_slower_than_the_heartbeat_but_within_the_lease_are_no_warning(
    slow: SlowServer, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, logger="cbrs.component")
    with beating(slow, heartbeat=0.02, ttl=5.0):
        for sent in range(2, 12):  # each beat is answered only after the next one was sent
            assert eventually(lambda sent=sent: len(slow.beats) >= sent)  # type: ignore[misc]
            slow.answer_all()
    assert warnings(caplog) == []


def test_a_lease_half_unanswered_is_warned_once_and_its_end_said(
    slow: SlowServer, caplog: pytest.LogCaptureFixture
) -> None:
    caplog.set_level(logging.WARNING, logger="cbrs.component")
    connected = beating(slow, heartbeat=0.01, ttl=0.1)
    with connected:
        assert eventually(lambda: any("answered for" in text for text in warnings(caplog)))
        time.sleep(0.2)  # twice the lease, unanswered: at most a lease's worth of beats wait at once
        assert len(slow.beats) == 11
        assert [text for text in warnings(caplog) if "answered for" in text] == [warnings(caplog)[0]]
        assert "lease lasts 0.1 s" in warnings(caplog)[0]
        slow.answer_all()
        assert eventually(lambda: any("answered again" in text for text in warnings(caplog)))


class BrokenClient(SlowServer):
    """A client whose heartbeat call raises: a bug in it, or in a wrapper a lab put around it."""

    def call(self, service: str, args: Mapping[str, Any], timeout: float | None = None) -> Future[dict[str, Any]]:
        raise RuntimeError("the wrapper dropped the call")


def test_a_heartbeat_that_breaks_ends_the_component_loudly(caplog: pytest.LogCaptureFixture) -> None:
    client = BrokenClient()
    connected = beating(client, heartbeat=0.01, ttl=1.0)
    assert eventually(lambda: connected.ended is not None)
    assert "heartbeat broke: RuntimeError: the wrapper dropped the call" in str(connected.ended)
    assert client.closed  # serve() then raises ComponentEndedError, and run() exits with status 1
    assert "the heartbeat of" in caplog.text
