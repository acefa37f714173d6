"""What this process knows of each remote service's calls: a circuit breaker, and an actuator's call given up.

A handler that hangs keeps its registration: its SDK sends heartbeats on a schedule of its own, so the
lease cannot see the hang, and every run planned onto it (every re-plan too) waited a whole call
timeout before failing over. A breaker per service remembers the timeouts instead
(docs/execution.md, "A component that hangs is passed over"):

- *closed*: calls go out. ``BreakerPolicy.timeouts`` calls in a row that time out (1 by default) open it.
- *open*: for ``BreakerPolicy.cooldown`` seconds the component is passed over: composition leaves it
  out (:func:`passed_over`, saying why), and an invocation of it fails at once, sending nothing.
- *half-open*: after the cool-down one trial call goes out; any other waits for its verdict (passed
  over meanwhile). An answer in time closes the breaker (an error answer too: it came at once, and the
  breaker is about the time lost waiting); a timeout opens it again for another cool-down. A late
  answer closes nothing: the handler is still slower than its timeout.
- A component registered again from another session (its program restarted) starts closed.

An actuator (``RemoteComponent(exclusive=True)``) keeps the rule it had before the breaker: while a call
given up unanswered may still be executing, no new call goes to its service (:func:`given_up`), and
composition passes it over with that reason. Both facts live in one table per transport, kept only
while the transport lives (a server's own bridge connection outlives its runs). The answer to a call
given up, when it comes, corrects the belief (:mod:`actions.late_answers`, the ``late`` callback), or
is logged when there is no store to write.
"""

from __future__ import annotations

import logging
import threading
import time
import weakref
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any, Protocol

from cbrs.actions.errors import ActionsError
from cbrs.kb.namespaces import shorten

log = logging.getLogger("cbrs.actions.remote")

__all__ = [
    "BreakerPolicy",
    "BreakerPolicyError",
    "Late",
    "ServiceCalls",
    "busy",
    "calls_of",
    "late_answers_awaited",
    "passed_over",
    "settle_late_answers",
]


Late = Callable[[Future[dict[str, Any]]], None]
"""Called with an actuator's call given up once it ends (answered, failed or ended by the transport), in
a thread of its own: the transport's reader ends the future, and must not wait for a store."""


class _Transport(Protocol):
    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]: ...


class BreakerPolicyError(ActionsError, ValueError):
    """A breaker was given an impossible parameter (a negative count or cool-down)."""

    def __init__(self, name: str, value: object, why: str) -> None:
        super().__init__(f"{name} = {value!r}: {why}")
        self.name, self.value = name, value


@dataclass(frozen=True)
class BreakerPolicy:
    """``timeouts``: calls in a row that time out before the component is passed over (0: never);
    ``cooldown``: seconds it is passed over before one trial call (settings ``remote_breaker_timeouts``,
    ``remote_breaker_cooldown``)."""

    timeouts: int = 1
    cooldown: float = 30.0

    def __post_init__(self) -> None:
        if self.timeouts < 0:
            raise BreakerPolicyError("timeouts", self.timeouts, "a number of timeouts cannot be negative")
        if not 0.0 <= self.cooldown <= 86_400.0:
            raise BreakerPolicyError("cooldown", self.cooldown, "a cool-down is 0 to 86400 seconds")


@dataclass
class _Service:
    component: str
    session: str | None = None  # the registration its timeouts were met under
    timeouts: int = 0  # in a row
    timeout: float = 0.0  # the last call's timeout
    opened: float | None = None  # when the breaker last opened
    cooldown: float = 0.0
    trial: tuple[float, float] | None = None  # the trial call out: when it was sent, how long it may be out
    given_up: tuple[Future[dict[str, Any]], float, float] | None = None  # an actuator's call: future, sent, timeout


class ServiceCalls:
    """One transport's services: their breakers and the actuators' calls given up."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._services: dict[str, _Service] = {}
        self._settling: list[tuple[str, float, threading.Event]] = []  # calls given up: service, end, taken

    def admit(
        self, service: str, component: str, now: float, window: float, exclusive: bool, session: str | None
    ) -> str:
        """Why no call may go to ``service`` now ("" when one may). A call let through a half-open breaker
        is its trial, out for at most ``window`` seconds unless its verdict comes first."""
        with self._lock:
            entry = self._current(service, component, session)
            if entry is None:
                return ""
            if exclusive and (busy := _busy(service, entry, now)):
                return busy
            why = _open(service, entry, now)
            if not why and entry.opened is not None:  # half-open: this call is the trial
                entry.trial = (now, window)
            return why

    def timed_out(
        self,
        service: str,
        component: str,
        now: float,
        timeout: float,
        policy: BreakerPolicy | None,
        session: str | None,
        pending: Future[dict[str, Any]] | None = None,
        sent: float = 0.0,
        late: Late | None = None,
    ) -> None:
        """A call to ``service`` got no answer within ``timeout``; ``pending``: an actuator's call, kept
        until it answers; ``late``: what to do with its answer if one comes (by default, log it)."""
        with self._lock:
            entry = self._current(service, component, session) or self._services.setdefault(
                service, _Service(component, session)
            )
            entry.timeouts += 1
            entry.timeout = timeout
            if pending is not None and not pending.done():
                entry.given_up = (pending, sent, timeout)
                self._watch(
                    service,
                    pending,
                    sent + timeout * _late_window(),
                    late or _say_when_late(service, component, timeout),
                )
            if (
                policy is not None
                and policy.timeouts
                and (entry.trial is not None or entry.timeouts >= policy.timeouts)
            ):
                entry.opened, entry.cooldown = now, policy.cooldown
            entry.trial = None

    def answered(self, service: str) -> None:
        """``service`` answered a call in time: its breaker closes."""
        with self._lock:
            entry = self._services.get(service)
            if entry is not None:
                entry.timeouts, entry.opened, entry.trial = 0, None, None
                self._forget_if_idle(service, entry)

    def released(self, service: str) -> None:
        """A call ended with no verdict on the service's speed (the connection broke, the step was halted):
        a trial it was is no longer out."""
        with self._lock:
            entry = self._services.get(service)
            if entry is not None:
                entry.trial = None

    def given_up(
        self,
        service: str,
        component: str,
        pending: Future[dict[str, Any]],
        sent: float,
        timeout: float,
        late: Late | None = None,
        awaited: bool = True,
    ) -> None:
        """An actuator's call that is still out was given up (its step was halted); ``late`` as for
        :meth:`timed_out`. Not ``awaited``: its answer is dropped (a Stop abandoned the call), so
        :meth:`settle` does not wait for it; the service stays busy until it ends all the same."""
        with self._lock:
            entry = self._services.setdefault(service, _Service(component))
            entry.given_up = (pending, sent, timeout)
            self._watch(
                service,
                pending,
                sent + timeout * _late_window(),
                late or _say_when_late(service, component, timeout),
                awaited,
            )

    def _watch(
        self, service: str, pending: Future[dict[str, Any]], ends: float, late: Late, awaited: bool = True
    ) -> None:
        """Have ``late`` take ``pending`` when it ends, in a thread of its own, and remember the call until
        then (:meth:`settle`, if ``awaited``). ``ends``: when the transport ends it at the latest."""
        settled = threading.Event()
        self._settling = [entry for entry in self._settling if not entry[2].is_set()]
        if awaited:
            self._settling.append((service, ends, settled))

        def take(done: Future[dict[str, Any]]) -> None:
            try:
                late(done)
            finally:
                settled.set()

        pending.add_done_callback(
            lambda done: threading.Thread(target=take, args=(done,), name="cbrs-late-answer", daemon=True).start()
        )

    def settle(
        self, now: float, limit: float, grace: float = 5.0, clock: Callable[[], float] | None = None
    ) -> list[str]:
        """Wait until every actuator's call given up has ended and what it answered has been taken
        (:mod:`actions.late_answers`): each at most until the transport ends it and ``grace`` seconds more,
        and all at most ``limit`` seconds. ``now``: the time on the clock the calls were sent by; ``clock``
        the one to wait by."""
        clock = clock or time.monotonic
        start = clock()
        with self._lock:
            waiting = list(self._settling)
        for _service, ends, settled in waiting:
            settled.wait(max(0.0, start + min(ends - now + grace, limit) - clock()))
        with self._lock:
            self._settling = [entry for entry in self._settling if not entry[2].is_set()]
            return sorted({service for service, _, _ in self._settling})

    def awaited(self) -> list[str]:
        """The services whose calls given up are still out, their answers awaited."""
        with self._lock:
            return sorted({service for service, _, settled in self._settling if not settled.is_set()})

    def busy(self, service: str, now: float) -> str:
        with self._lock:
            entry = self._services.get(service)
            return _busy(service, entry, now) if entry is not None else ""

    def passed_over(self, now: float, sessions: Mapping[str, str | None] | None = None) -> dict[str, str]:
        """The components not to plan with now, by IRI, with why: an open breaker, a trial call out, an
        actuator still executing a call given up. ``sessions``: each live component's registration, so a
        component registered again by a restarted program is not held to its predecessor's timeouts."""
        found: dict[str, str] = {}
        with self._lock:
            for service, entry in list(self._services.items()):
                session = sessions.get(entry.component) if sessions is not None else None
                current = self._current(service, entry.component, session)
                if current is None:
                    continue
                why = _busy(service, current, now) or _open(service, current, now)
                if why:
                    found[current.component] = why
        return found

    def _current(self, service: str, component: str, session: str | None) -> _Service | None:
        """The entry of ``service``, forgotten first if another component or registration holds it now."""
        entry = self._services.get(service)
        if entry is None:
            return None
        if entry.component != component or (session is not None and entry.session not in (None, session)):
            del self._services[service]
            return None
        if session is not None:
            entry.session = session
        return entry

    def _forget_if_idle(self, service: str, entry: _Service) -> None:
        if entry.given_up is None or entry.given_up[0].done():
            del self._services[service]


def _say_when_late(service: str, component: str, timeout: float) -> Late:
    """A callback that logs an actuator's answer to a call given up, when it comes: the device may have
    acted (a door motor opened the door 15 s after a 10 s timeout). Used when nothing records the answer
    in the belief (no store to write: :mod:`actions.late_answers` does it otherwise), so that a person
    learns that what is believed of the device's effects may be stale."""

    def late(done: Future[dict[str, Any]]) -> None:
        error = done.exception() if not done.cancelled() else None
        if done.cancelled() or error is not None:
            what = f"ended without an answer ({error or 'cancelled'})"
        else:
            what = "answered"
        log.warning(
            "%s (%s) %s after its call was given up (no answer within %g s): the run acted on none of it, "
            "and what it believes of the device's effects may be stale; check the device "
            "(docs/execution.md, 'An actuator is sent one command at a time')",
            shorten(component),
            service,
            what,
            timeout,
        )

    return late


def _late_window() -> float:
    from cbrs.actions.remote import LATE_WINDOW

    return LATE_WINDOW


def _busy(service: str, entry: _Service, now: float) -> str:
    from cbrs.actions.remote import LATE_WINDOW

    if entry.given_up is None:
        return ""
    pending, sent, timeout = entry.given_up
    if pending.done():
        entry.given_up = None
        return ""
    return (
        f"{service} is still executing the call sent {now - sent:.1f} s ago, given up after {timeout:g} s"
        f" without an answer: no new call is sent until it answers (or {timeout * LATE_WINDOW:g} s after it was"
        " sent, when the bridge ends it)"
    )


def _open(service: str, entry: _Service, now: float) -> str:
    """Why the breaker of ``service`` keeps calls off it now ("" when a call may go)."""
    if entry.opened is None:
        return ""
    name = shorten(entry.component)
    if entry.trial is not None:
        sent, window = entry.trial
        if now < sent + window:
            return (
                f"{name} is passed over: a trial call to {service} is out since {now - sent:.1f} s ago, after its"
                " calls timed out; no other call goes to it until that one answers or times out"
            )
        entry.trial = None  # a trial nobody followed to its end (its run broke off): another may go
    left = entry.opened + entry.cooldown - now
    if left <= 0:
        return ""
    return (
        f"{name} is passed over: its last {entry.timeouts} call(s) to {service} timed out (no answer within"
        f" {entry.timeout:g} s), the last {now - entry.opened:.1f} s ago; one trial call goes to it in {left:.1f} s"
        f" (a cool-down of {entry.cooldown:g} s, setting remote_breaker_cooldown)"
    )


_tables: weakref.WeakKeyDictionary[_Transport, ServiceCalls] = weakref.WeakKeyDictionary()
_tables_lock = threading.Lock()


def calls_of(transport: _Transport) -> ServiceCalls:
    """The table of ``transport``'s services (made at first use, kept while the transport lives)."""
    with _tables_lock:
        try:
            table = _tables.get(transport)
            if table is None:
                table = _tables[transport] = ServiceCalls()
        except TypeError:  # a transport that cannot be referred to weakly: a table for this caller alone
            return ServiceCalls()
        return table


def passed_over(transport: _Transport, now: float, sessions: Mapping[str, str | None] | None = None) -> dict[str, str]:
    """The components reached over ``transport`` that composition passes over now, with why."""
    table = _table(transport)
    return table.passed_over(now, sessions) if table is not None else {}


def busy(transport: _Transport, service: str, now: float) -> str:
    """Why no new call may go to the actuator ``service`` over ``transport`` now (``remote.given_up``)."""
    table = _table(transport)
    return table.busy(service, now) if table is not None else ""


def settle_late_answers(transport: _Transport, limit: float) -> list[str]:
    """Wait, at most ``limit`` seconds, for the actuators' calls given up over ``transport`` to end and
    their answers to be taken in the belief, before a program closes the transport (which would end
    them unanswered): ``cbrs run`` gives up a door motor's call at 10 s and exits while the motor opens
    the door. The services still out after it (empty: none)."""
    table = _table(transport)
    return table.settle(time.monotonic(), limit) if table is not None else []


def late_answers_awaited(transport: _Transport) -> list[str]:
    """The services whose calls over ``transport`` were given up and may still answer: what
    :func:`settle_late_answers` would wait for (a program says so before it waits)."""
    table = _table(transport)
    return table.awaited() if table is not None else []


def _table(transport: _Transport) -> ServiceCalls | None:
    with _tables_lock:
        try:
            return _tables.get(transport)
        except TypeError:
            return None
