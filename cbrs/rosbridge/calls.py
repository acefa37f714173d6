"""Service calls in flight: to handlers on worker threads, or forwarded to the client that provides them.

Every call ends in exactly one ``service_response`` to its caller, with the caller's id: the answer, or
``result: false`` with the reason (handler error, timeout, provider gone). Runs on the bridge's loop;
only the handler itself runs on a worker thread.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import logging
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cbrs.rosbridge import protocol
from cbrs.rosbridge.errors import ProtocolError, ServiceError
from cbrs.rosbridge.graph import Handler
from cbrs.rosbridge.protocol import MessageId
from cbrs.rosbridge.session import _CALLER, Caller, Session
from cbrs.rosbridge.workers import WorkerPool

log = logging.getLogger("cbrs.rosbridge")


@dataclass(eq=False)
class Call:
    """One call in flight."""

    key: str
    service: str  # global name
    caller: Session
    caller_id: MessageId | None
    spelling: str  # the service name as the caller wrote it
    provider: Session | None = None  # None: a server handler
    timer: asyncio.TimerHandle | None = None
    done: bool = False
    fragment_size: int | None = None  # the caller asked for the response in pieces of this size


def run_handler(
    handler: Handler, args: dict[str, Any], service: str, caller: Caller | None = None, non_finite: str = "null"
) -> tuple[bool, str]:
    """Run a handler (``caller`` is what :func:`current_caller` gives it); (result, encoded values), the
    values being the error text on failure, their NaNs written as ``non_finite`` says."""
    token = _CALLER.set(caller)
    try:
        values = handler(args)
        if not isinstance(values, dict):
            raise TypeError(f"the handler returned {type(values).__name__}, not a dict")
        return True, protocol.dumps(values, non_finite)
    except ServiceError as error:
        log.info("service %s failed: %s", service, error)
        return False, protocol.dumps(str(error))
    except Exception as error:
        log.exception("service %s: handler raised", service)
        return False, protocol.dumps(f"internal error: {type(error).__name__}: {error}")
    finally:
        _CALLER.reset(token)


class Calls:
    """The calls in flight on one running bridge."""

    def __init__(
        self,
        loop: asyncio.AbstractEventLoop,
        workers: WorkerPool,
        non_finite: str = "null",
        strict: Callable[[str], bool] = lambda service: False,
    ) -> None:
        self._loop = loop
        self._strict = strict  # services whose provider's `result: false` fails the call, values or not
        self._workers = workers
        self._non_finite = non_finite  # how values' NaNs are written (protocol.NON_FINITE)
        self._pending: dict[str, Call] = {}
        self._keys = itertools.count(1)
        self._per_caller: Counter[Session] = Counter()

    def __len__(self) -> int:
        return len(self._pending)

    def in_flight(self, caller: Session) -> int:
        """How many of ``caller``'s calls wait for an answer (a handler's or a provider's)."""
        return self._per_caller[caller]

    def to_handler(self, call: Call, handler: Handler, args: dict[str, Any], timeout: float) -> None:
        """Run ``handler`` on a worker thread; its answer (or the timeout) goes to the caller."""
        self._start(call, timeout)
        caller = call.caller.identity()

        def job() -> None:
            if call.done:  # timed out while waiting for a free worker
                return
            result, values = run_handler(handler, args, call.service, caller, self._non_finite)
            with contextlib.suppress(RuntimeError):  # the loop has closed: the server stopped meanwhile
                self._loop.call_soon_threadsafe(self.finish, call, result, values)

        try:
            self._workers.submit(job)
        except RuntimeError:
            self.finish(call, False, protocol.dumps("the server is shutting down"))

    def to_provider(self, call: Call, provider: Session, spelling: str, args: Any, timeout: float) -> None:
        """Forward the call to the client ``provider`` under a fresh id."""
        call.provider = provider
        self._start(call, timeout)
        provider.reply(protocol.call_service(spelling, args, call.key, self._non_finite))

    def answer(self, provider: Session, key: MessageId | None, result: bool, values: Any, service: str) -> bool:
        """A provider's ``service_response`` for ``service`` (its global name); False if ``provider`` has no
        call with that id. One that names another service than its call's is dropped (ProtocolError), as
        rosbridge_suite, which looks the id up under the service named, drops it: the call waits on."""
        call = self._pending.get(str(key))
        if call is None or call.provider is not provider:
            return False
        if service != call.service:
            log.warning(
                "%s answered call %s of %s as %s: dropped, the call waits", provider.name, key, call.service, service
            )
            raise ProtocolError(
                f"service_response names {service!r}, but its id {key!r} is a call of {call.service!r}:"
                " dropped, that call still waits for its answer"
            )
        strict = isinstance(values, dict) and self._strict(call.service)
        if strict and not result:
            given = protocol.dumps(values, self._non_finite)
            result, values = (
                False,
                f"service {call.service!r} answered result: false" + (f" (values {given[:200]})" if values else ""),
            )
        elif strict and (where := protocol.non_finite_field(values)) is not None:
            # Its JSON callers would read null: a broken reading taken for a missing one.
            result, values = False, f"service {call.service!r} answered values that are not JSON: {where}"
        elif isinstance(values, dict):
            result = True  # rosbridge_suite's rule: an object of values is the response, whatever `result` says
        elif values is None:
            values = {} if result else f"service {call.service!r} failed (its provider gave no reason)"
        elif result:
            result, values = False, f"service {call.service!r} answered with values that are not an object"
        self.finish(call, result, protocol.dumps(values, self._non_finite))
        return True

    def refuse(self, provider: Session, key: MessageId | None, reason: str, named: Any = None) -> bool:
        """A provider's ``service_response`` that could not be read (``"result": "yes"``, ``"values": 42``):
        the call it answers, when ``provider`` has one with that id, fails at once with ``reason``, as the
        caller would otherwise wait for its timeout. False if there is no such call, or the response
        ``named`` another service than the call's (it answers none: see :meth:`answer`)."""
        call = self._pending.get(str(key)) if key is not None else None
        if call is None or call.provider is not provider:
            return False
        if isinstance(named, str) and named.strip() and protocol.resolve(named) != call.service:
            return False
        self.finish(call, False, protocol.dumps(_malformed(call, reason)))
        return True

    def refuse_unread(self, provider: Session, text: str, reason: str) -> bool:
        """A message from ``provider`` too large to read at all: when it is a ``service_response`` that
        carries the id of one of ``provider``'s calls (looked for as the JSON string the bridge sent, not
        parsed), that call fails at once with ``reason``. False if it names none."""
        if '"service_response"' not in text:
            return False
        for call in list(self._pending.values()):
            if call.provider is provider and protocol.dumps(call.key) in text:
                self.finish(call, False, protocol.dumps(_malformed(call, reason)))
                return True
        return False

    def refuse_sole(self, provider: Session, service: str, reason: str) -> bool:
        """A ``service_response`` for ``service`` without an id: when ``provider`` has exactly one call of
        ``service`` in flight, the answer can only be meant for it, and it fails at once with ``reason``
        (several: none can be told apart, and they wait). False if none failed."""
        calls = [call for call in self._pending.values() if call.provider is provider and call.service == service]
        if len(calls) != 1:
            return False
        self.finish(calls[0], False, protocol.dumps(_malformed(calls[0], reason)))
        return True

    def fail_provider(self, provider: Session, service: str | None, reason: str) -> None:
        """Fail the calls waiting on ``provider`` (for ``service``, or all of them)."""
        for call in list(self._pending.values()):
            if call.provider is provider and service in (None, call.service):
                self.finish(call, False, protocol.dumps(reason.format(service=call.service)))

    def fail_all(self, reason: str) -> None:
        for call in list(self._pending.values()):
            self.finish(call, False, protocol.dumps(reason))

    def finish(self, call: Call, result: bool, values_json: str) -> None:
        """Answer the caller once; later answers (a late handler, a late provider) are dropped."""
        if call.done:
            return
        call.done = True
        if self._pending.pop(call.key, None) is not None:
            self._per_caller[call.caller] -= 1
            if self._per_caller[call.caller] <= 0:
                del self._per_caller[call.caller]
        if call.timer is not None:
            call.timer.cancel()
        text = protocol.service_response(call.spelling, result, values_json, call.caller_id)
        if call.fragment_size is None:
            call.caller.reply(text)
        else:
            piece_id = call.caller_id or f"service_response:{call.spelling}:{call.key.rpartition(':')[2]}"
            call.caller.reply_in_pieces(text, call.fragment_size, piece_id)

    def _start(self, call: Call, timeout: float) -> None:
        self._pending[call.key] = call
        self._per_caller[call.caller] += 1
        message = protocol.dumps(f"service {call.service!r} did not answer within {timeout:g} s")
        call.timer = self._loop.call_later(timeout, self.finish, call, False, message)

    def new_key(self, service: str) -> str:
        return f"cbrs:{service}:{next(self._keys)}"


def _malformed(call: Call, reason: str) -> str:
    return f"service {call.service!r} answered with a service_response that could not be read: {reason}"
