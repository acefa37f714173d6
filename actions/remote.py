"""A component that runs in another process, invoked through a transport (the rosbridge protocol).

The executor treats it like any other component: ``begin`` sends the call with the step's inputs as
the request's fields, ``update`` polls for the answer (waiting a few milliseconds per tick, so that a
tick is bounded in time), and the answer's fields become the outputs. Whatever the remote side does
(answers with an error, with the wrong fields or types, never, or goes away) ends the invocation
with a reason; nothing it sends can reach the plan unchecked.
"""

from __future__ import annotations

import threading
import time
import weakref
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Protocol

from cbrs.actions.components import Component, Status

__all__ = ["LATE_WINDOW", "MAX_POLLS", "POLL_SECONDS", "RemoteCallError", "RemoteComponent", "Transport", "given_up"]

POLL_SECONDS = 0.005
"""How long one tick waits for the answer at least: short, so a run's other work is not held up."""
MAX_POLLS = 1000
"""A call's timeout is spread over at most this many ticks (a tick waits ``timeout / MAX_POLLS`` when
that is longer than POLL_SECONDS), so that the executor's bound on a step's ticks (10,000) never cuts
a call short before its own timeout, however long the timeout."""
LATE_WINDOW = 2.0
"""The transport is given this many times the component's timeout: a call the component has given up
stays open at the bridge for as long again, so that the provider's late answer is still heard and,
until it is, no new call is sent to a service that may still be executing the last one (an actuator)."""

_given_up: weakref.WeakKeyDictionary[Transport, dict[str, tuple[Future[dict[str, Any]], float, float]]] = (
    weakref.WeakKeyDictionary()
)
"""By transport (kept only while it lives), by service: the call given up last, when it was sent, and
its timeout."""
_given_up_lock = threading.Lock()


class RemoteCallError(Exception):
    """A remote service answered with ``result: false``; the message is its reason."""


class Transport(Protocol):
    """Something that can call a service in another process."""

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        """Send the call; the future gets the answer's values, or raises RemoteCallError or another error."""


OutputCheck = Callable[[str, Any], Any]
"""(port type, value) -> the value to pass on; raises ValueError (or a subclass) for a wrong one."""


class RemoteComponent(Component):
    """An advertised service provided by ``service`` over ``transport``.

    ``outputs`` maps each output's name to its type (the advertisement's); ``check`` validates each
    answered value against its type (for example :func:`sim.values.check`); ``timeout`` bounds one call
    (the transport is given ``LATE_WINDOW`` times as long, so that its own timeout never comes first and
    a timeout has one reason). ``exclusive`` (an actuator): no new call is sent while a call given up
    unanswered may still be executing (:func:`given_up`); the invocation fails saying so instead.
    """

    def __init__(
        self,
        iri: str,
        transport: Transport,
        service: str,
        outputs: Mapping[str, str],
        check: OutputCheck | None = None,
        timeout: float = 10.0,
        clock: Callable[[], float] = time.monotonic,
        exclusive: bool = False,
    ) -> None:
        super().__init__(iri)
        self.transport = transport
        self.service = service
        self.output_types = dict(outputs)
        self.check = check
        self.timeout = timeout
        self._clock = clock
        self.exclusive = exclusive
        self._pending: Future[dict[str, Any]] | None = None
        self._sent = 0.0
        self._deadline = 0.0

    def begin(self, inputs: Mapping[str, Any]) -> None:
        """Send the call, unless this transport's last call to the service was given up unanswered and
        may still be executing: then the invocation fails with that reason and nothing is sent."""
        self.outputs = {}
        self.reason = ""
        self._pending = None
        busy = given_up(self.transport, self.service, self._clock) if self.exclusive else ""
        if busy:
            self.reason = busy
            return
        self._sent = self._clock()
        self._deadline = self._sent + self.timeout
        self._pending = self.transport.call(self.service, dict(inputs), self.timeout * LATE_WINDOW)

    def update(self) -> Status:
        pending = self._pending
        if pending is None:
            self.reason = self.reason or "not started"
            return Status.FAILED
        try:
            values = pending.result(timeout=max(POLL_SECONDS, self.timeout / MAX_POLLS))
        except FutureTimeout:
            if self._clock() < self._deadline:
                return Status.RUNNING
            self.reason = f"{self.service} did not answer within {self.timeout:g} s"
            return self._give_up()
        except RemoteCallError as error:
            self.reason = f"{self.service} failed: {error}"
            return self._fail()
        except Exception as error:  # the transport broke (the connection closed, the provider left)
            self.reason = f"{self.service}: {type(error).__name__}: {error}"
            return self._fail()
        self._pending = None
        return self._accept(values)

    def _accept(self, values: Any) -> Status:
        if not isinstance(values, dict):
            self.reason = f"{self.service} answered {type(values).__name__}, not an object of named outputs"
            return Status.FAILED
        missing = [name for name in self.output_types if name not in values]
        if missing:
            given = ", ".join(sorted(values)) or "nothing"
            self.reason = f"{self.service} answered without {', '.join(missing)} (it gave {given})"
            return Status.FAILED
        outputs = {}
        for name, concept in self.output_types.items():
            value = values[name]
            if self.check is not None:
                try:
                    value = self.check(concept, value)
                except ValueError as error:
                    self.reason = f"{self.service} answered a wrong {name}: {error}"
                    return Status.FAILED
            outputs[name] = value
        self.outputs = outputs
        return Status.SUCCEEDED

    def _fail(self) -> Status:
        self._pending = None
        return Status.FAILED

    def _give_up(self) -> Status:
        """Stop waiting for a call that has not answered; the provider may still be executing it (a door
        motor cannot be told to stop by a dropped call), so it is kept until it answers (``given_up``)."""
        pending = self._pending
        if self.exclusive and pending is not None and not pending.done():
            with _given_up_lock:
                _given_up.setdefault(self.transport, {})[self.service] = (pending, self._sent, self.timeout)
        return self._fail()

    def halt(self) -> None:
        self._give_up()


def given_up(transport: Transport, service: str, clock: Callable[[], float] = time.monotonic) -> str:
    """Why no new call may be sent to ``service`` over ``transport`` now: its last call was given up
    (it timed out, or its step was halted) and has not answered yet, so the provider may still be
    executing it. Empty when the service is free: it answered late, or the transport ended the call
    (after ``LATE_WINDOW`` times the timeout, or the connection closed)."""
    with _given_up_lock:
        calls = _given_up.get(transport, {})
        entry = calls.get(service)
        if entry is None:
            return ""
        pending, sent, timeout = entry
        if pending.done():
            del calls[service]
            return ""
    return (
        f"{service} is still executing the call sent {clock() - sent:.1f} s ago, given up after {timeout:g} s"
        f" without an answer: no new call is sent until it answers (or {timeout * LATE_WINDOW:g} s after it was"
        " sent, when the bridge ends it)"
    )
