"""A component that runs in another process, invoked through a transport (the rosbridge protocol).

The executor treats it like any other component: ``begin`` sends the call with the step's inputs as
the request's fields, ``update`` polls for the answer (waiting a few milliseconds per tick, so that a
tick is bounded in time), and the answer's fields become the outputs. Whatever the remote side does
(answers with an error, with the wrong fields or types, never, or goes away) ends the invocation
with a reason; nothing it sends can reach the plan unchecked.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Protocol

from cbrs.actions.components import Component, Status

__all__ = ["POLL_SECONDS", "RemoteCallError", "RemoteComponent", "Transport"]

POLL_SECONDS = 0.005
"""How long one tick waits for the answer: short, so a run's other work is not held up."""


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
    answered value against its type (for example :func:`sim.values.check`); ``timeout`` bounds one call.
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
    ) -> None:
        super().__init__(iri)
        self.transport = transport
        self.service = service
        self.output_types = dict(outputs)
        self.check = check
        self.timeout = timeout
        self._clock = clock
        self._pending: Future[dict[str, Any]] | None = None
        self._deadline = 0.0

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.outputs = {}
        self.reason = ""
        self._deadline = self._clock() + self.timeout
        self._pending = self.transport.call(self.service, dict(inputs), self.timeout)

    def update(self) -> Status:
        pending = self._pending
        if pending is None:
            self.reason = "not started"
            return Status.FAILED
        try:
            values = pending.result(timeout=POLL_SECONDS)
        except FutureTimeout:
            if self._clock() < self._deadline:
                return Status.RUNNING
            self.reason = f"{self.service} did not answer within {self.timeout:g} s"
            return self._fail()
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
        if self._pending is not None:
            self._pending.cancel()
        self._pending = None
        return Status.FAILED

    def halt(self) -> None:
        self._fail()
