"""A component that runs in another process, invoked through a transport (the rosbridge protocol).

The executor treats it like any other component: ``begin`` sends the call with the step's inputs as
the request's fields, ``update`` polls for the answer (waiting a few milliseconds per tick, so that a
tick is bounded in time), and the answer's fields become the outputs. Whatever the remote side does
(answers with an error, with the wrong fields or types, never, or goes away) ends the invocation
with a reason; nothing it sends can reach the plan unchecked.

A component that acts (an advertisement with effects or delete effects) whose call was sent and whose step
then ends without a checked success leaves what its effects would set unknown (:func:`actions.late_answers.unsettle`;
docs/execution.md, "The belief after a failed step"): the device may have acted, whoever runs it.

A Stop of the run while the call is out ends the wait within :data:`STOP_POLL` seconds, however long the
tick's wait: the call is abandoned, what it would set made unknown, and its answer dropped when it comes
(:meth:`RemoteComponent.halt`). The provider is not told: a component's call is a rosbridge service call,
and the protocol has no cancel for one (only an action's goal has, ``cancel_action_goal``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from typing import Any, Protocol

from cbrs.actions.answers import Classes, ContradictedEffectError, StoreClasses, check_quantities, read_answer
from cbrs.actions.breaker import BreakerPolicy, Late, busy, calls_of
from cbrs.actions.components import Component, Status
from cbrs.actions.errors import ActionsError
from cbrs.actions.late_answers import GivenUp, SentAndFailed, unsettle, watch
from cbrs.actions.remote_errors import RemoteCallError
from cbrs.kb import KnowledgeBase, Statement

__all__ = [
    "LATE_WINDOW",
    "MAX_CALL_SECONDS",
    "MAX_POLLS",
    "POLL_SECONDS",
    "STOP_POLL",
    "AnswerRefusedError",
    "RemoteCallError",
    "RemoteComponent",
    "Transport",
    "given_up",
]

log = logging.getLogger("cbrs.actions.remote")

POLL_SECONDS = 0.005
"""How long one tick waits for the answer at least: short, so a run's other work is not held up."""
MAX_POLLS = 1000
"""A call's timeout is spread over at most this many ticks (a tick waits ``timeout / MAX_POLLS`` when
that is longer than POLL_SECONDS), so that the executor's bound on a step's ticks (10,000) never cuts
a call short before its own timeout, however long the timeout."""
STOP_POLL = 0.1
"""A tick that waits longer than this (a call's timeout over MAX_POLLS: 0.1 s from a 100 s timeout, 86 s for
a day's) waits in parts this long, between which it asks whether the run was asked to stop."""
LATE_WINDOW = 2.0
"""The transport is given this many times the component's timeout: a call the component has given up
stays open at the bridge for as long again, so that the provider's late answer is still heard and,
until it is, no new call is sent to a service that may still be executing the last one (an actuator)."""
MAX_CALL_SECONDS = 86400.0
"""The longest one call is waited for: a day. A description may state any ``cbrs:responseTime``, and three
times a mistyped one (``1e308`` for ``1e3``) is no time a clock or a lock can wait (infinity, or past the
platform's ``time_t``): its call failed with an ``OverflowError`` before it could be answered, said to have
been sent. Such a component is waited for a day, with a warning naming it and the time it states."""


class Transport(Protocol):
    """Something that can call a service in another process."""

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        """Send the call; the future gets the answer's values, or raises RemoteCallError or another error."""


class AnswerRefusedError(ActionsError):
    """An answer the checks refuse: not an object of named outputs, an output missing or of the wrong
    type. Keeps the service; the message is the step's reason."""

    def __init__(self, service: str, reason: str) -> None:
        super().__init__(reason)
        self.service, self.reason = service, reason


OutputCheck = Callable[[str, Any], Any]
"""(port type, value) -> the value to pass on; raises ValueError (or a subclass) for a wrong one."""


class RemoteComponent(Component):
    """An advertised service provided by ``service`` over ``transport``.

    ``outputs`` maps each output's name to its type (the advertisement's); ``check`` validates each
    answered value against its type (for example :func:`sim.values.check`); ``timeout`` bounds one call
    (the transport is given ``LATE_WINDOW`` times as long, so that its own timeout never comes first and
    a timeout has one reason). ``exclusive`` (an actuator): no new call is sent while a call given up
    unanswered may still be executing (:func:`given_up`); the invocation fails saying so instead.

    ``effects`` (the advertisement's) with ``classes`` (the store's, :class:`actions.answers.StoreClasses`):
    an answer whose value the store says the effect excludes fails the invocation with
    :class:`~actions.answers.ContradictedEffectError` (``contradictions="warn"``: it is logged and taken).
    ``breaker``: after calls time out the service is passed over for a cool-down (:mod:`actions.breaker`);
    None, as before it, calls it whenever asked. ``session``: the registration the component is live
    under now, so that a restarted program is not held to its predecessor's timeouts.

    ``kb``: the store whose belief an actuator's answer to a call given up corrects when it comes
    (:mod:`actions.late_answers`); by default the one ``classes`` reads, if a :class:`StoreClasses`.
    Without one the answer is only logged.

    The failed-step rule: with ``effects`` or ``deletes`` (the advertisement's delete effects) and a
    store, a call that was sent and whose step ends without a checked success (an error answer, a
    malformed or contradicting one, the connection lost, a timeout whose answer nobody awaits, the step
    halted while the call was out, or an answer taken but the step then failed by the executor:
    :meth:`uncounted`) leaves the relations its effects set or delete about the step's things unknown
    (:func:`actions.late_answers.unsettle`). A call refused before it was sent changes no belief, nor does
    an actuator's call given up, whose late answer settles it (:func:`actions.late_answers.watch`).
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
        effects: Iterable[Statement] = (),
        classes: Classes | None = None,
        contradictions: str = "fail",
        breaker: BreakerPolicy | None = None,
        session: str | None = None,
        kb: KnowledgeBase | None = None,
        deletes: Iterable[Statement] = (),
    ) -> None:
        super().__init__(iri)
        self.transport = transport
        self.service = service
        self.output_types = dict(outputs)
        self.check = check
        if not timeout <= MAX_CALL_SECONDS:  # NaN too
            log.warning(
                "%s (%s) would be waited for %g s a call, more than a day: waiting %g s (its description's"
                " cbrs:responseTime is three times less than the wait; is it mistyped?)",
                iri,
                service,
                timeout,
                MAX_CALL_SECONDS,
            )
            timeout = MAX_CALL_SECONDS
        self.timeout = timeout
        self._clock = clock
        self.exclusive = exclusive
        self.effects = tuple(effects)
        self.deletes = tuple(deletes)
        self.classes = classes
        self.contradictions = contradictions
        self.breaker = breaker
        self.session = session
        self.kb = kb if kb is not None else classes.kb if isinstance(classes, StoreClasses) else None
        self._calls = calls_of(transport)
        self._pending: Future[dict[str, Any]] | None = None
        self._inputs: dict[str, Any] = {}
        self._sent = 0.0
        self._deadline = 0.0
        self._sent_call = False  # a call of this invocation went out and has not been accounted for
        self._answered = False  # its answer was taken: the step may still not count (actions.executor.Uncounted)

    def begin(self, inputs: Mapping[str, Any]) -> None:
        """Send the call, unless the service is passed over now (its breaker is open, or an actuator's call
        given up may still be executing): then the invocation fails with that reason and nothing is sent."""
        self.outputs = {}
        self.reason = ""
        self._pending = None
        self._sent_call = self._answered = False
        self._inputs = dict(inputs)
        now = self._clock()
        why = self._calls.admit(self.service, self.iri, now, self.timeout * LATE_WINDOW, self.exclusive, self.session)
        if why:
            self.reason = why
            return
        self._sent = now
        self._deadline = self._sent + self.timeout
        try:
            self._pending = self.transport.call(self.service, dict(inputs), self.timeout * LATE_WINDOW)
        except BaseException:
            self._calls.released(self.service)
            raise
        self._sent_call = True

    def update(self) -> Status:
        try:
            status = self._poll()
        except Exception as error:  # a contradicting answer: refused after it came
            self._unsettle(f"{type(error).__name__}: {error}")
            raise
        if status is Status.FAILED:
            self._unsettle(self.reason)
        elif status is Status.SUCCEEDED:
            self._sent_call, self._answered = False, True
        return status

    def uncounted(self, reason: str) -> None:
        """The executor did not count the step this answered as succeeded (an effect not reached): the
        device may have done part of it, so what its effects set is unknown, as for a failed answer."""
        if self._answered:
            self._answered, self._sent_call = False, True
            self._unsettle(f"its answer was taken, but the step failed: {reason}")

    def _poll(self) -> Status:
        pending = self._pending
        if pending is None:
            self.reason = self.reason or "not started"
            return Status.FAILED
        try:
            values = self._result(pending, max(POLL_SECONDS, self.timeout / MAX_POLLS))
        except FutureTimeout:
            if self._clock() < self._deadline:
                return Status.RUNNING
            self.reason = f"{self.service} did not answer within {self.timeout:g} s"
            return self._timed_out()
        except RemoteCallError as error:
            self._calls.answered(self.service)  # at once, if with an error: it does not hang
            self.reason = f"{self.service} failed: {error}"
            return self._fail()
        except Exception as error:  # the transport broke (the connection closed, the provider left)
            self._calls.released(self.service)
            self.reason = f"{self.service}: {type(error).__name__}: {error}"
            return self._fail()
        self._pending = None
        self._calls.answered(self.service)
        return self._accept(values)

    def _result(self, pending: Future[dict[str, Any]], wait: float) -> dict[str, Any]:
        """``pending``'s answer, waited for ``wait`` seconds at most, in parts of :data:`STOP_POLL`: a Stop of
        the run asked meanwhile ends the wait (``FutureTimeout``), so the run need not wait out the tick."""
        end = time.monotonic() + wait
        while True:
            left = end - time.monotonic()
            try:
                return pending.result(timeout=max(0.0, min(left, STOP_POLL)))
            except FutureTimeout:
                if left <= STOP_POLL or self.stop_asked():
                    raise

    def waiting(self) -> bool:
        pending = self._pending
        return pending is not None and not pending.done()

    def _accept(self, values: Any) -> Status:
        try:
            self.outputs = self._read(values)
        except AnswerRefusedError as refused:
            self.reason = refused.reason
            return Status.FAILED
        return Status.SUCCEEDED

    def _read(self, values: Any) -> dict[str, Any]:
        """The outputs of an answer, checked: every output there and of its type (:attr:`check`), none
        contradicting the effects. :class:`AnswerRefusedError` or :class:`ContradictedEffectError` when
        one is not; an answer that comes after its call was given up is read by this too."""
        if not isinstance(values, dict):
            raise AnswerRefusedError(
                self.service, f"{self.service} answered {type(values).__name__}, not an object of named outputs"
            )
        missing = [name for name in self.output_types if name not in values]
        if missing:
            given = ", ".join(sorted(values)) or "nothing"
            raise AnswerRefusedError(
                self.service, f"{self.service} answered without {', '.join(missing)} (it gave {given})"
            )
        outputs = {}
        for name, concept in self.output_types.items():
            value = values[name]
            if self.check is not None:
                try:
                    value = self.check(concept, value)
                    if self.classes is not None:
                        check_quantities(concept, value, self.classes)  # "47.5 %" for a humidity
                except ValueError as error:
                    raise AnswerRefusedError(
                        self.service, f"{self.service} answered a wrong {name}: {error}"
                    ) from error
            outputs[name] = value
        self._against_effects(outputs)
        return outputs

    def _against_effects(self, outputs: Mapping[str, Any]) -> None:
        """Raise :class:`ContradictedEffectError` when an answered value contradicts the effects
        (:mod:`actions.answers`); a class the store does not know is only noted."""
        if self.classes is None or not self.effects:
            return
        reading = read_answer(outputs, self.output_types, self.effects, self.classes)
        for name, concept in reading.unknown:
            log.info(
                "%s answered %s = %s, a class the store does not know: not checked against its effects",
                self.service,
                name,
                concept,
            )
        if reading.contradiction is None:
            return
        name, answered, effect = reading.contradiction
        error = ContradictedEffectError(self.iri, self.service, name, answered, effect)
        if self.contradictions != "warn":
            raise error
        log.warning("%s (taken, remote_contradictions=warn)", error)

    def _fail(self) -> Status:
        self._pending = None
        return Status.FAILED

    def _timed_out(self) -> Status:
        """Stop waiting for a call that has not answered: the breaker counts it, and an actuator's call is
        kept until it answers, since the provider may still be executing it (a door motor cannot be told
        to stop by a dropped call)."""
        pending = self._pending if self.exclusive else None
        if pending is not None and self.kb is not None:
            self._sent_call = False  # given up: its answer, when it comes, settles the belief
        late = self._late() if pending is not None else None
        self._calls.timed_out(
            self.service, self.iri, self._clock(), self.timeout, self.breaker, self.session, pending, self._sent, late
        )
        return self._fail()

    def _late(self) -> Late | None:
        """What the answer to the call given up now does to the belief if it comes (None: it is logged)."""
        if self.kb is None or self.classes is None:
            return None
        return watch(
            self.kb,
            self.classes,
            GivenUp(self.iri, self.service, self.timeout, self._inputs, self.effects, self.deletes),
            self._read,
        )

    def halt(self) -> None:
        """The step was stopped while the call was out: by the executor's tick bound or the run's end (what
        the call would set is unknown; an actuator's late answer settles it), or by a Stop of the run
        (:meth:`_abandon`)."""
        pending = self._pending
        if pending is not None and not pending.done() and self.stop_asked():
            self._abandon(pending)
            return
        if pending is not None and self.exclusive and not pending.done() and self.kb is not None:
            self._sent_call = False  # given up: its late answer settles the belief
        if pending is not None:
            self._unsettle(f"halted while its call was out ({self.reason or 'the step was stopped'})")
        if pending is not None and not pending.done():
            self._calls.released(self.service)
            if self.exclusive:
                self._calls.given_up(self.service, self.iri, pending, self._sent, self.timeout, self._late())
        self._fail()

    def _abandon(self, pending: Future[dict[str, Any]]) -> None:
        """A Stop of the run while the call was out: the call is abandoned. What it would set becomes unknown,
        as for a call of a component deregistered meanwhile: the provider may act on it, in full or in part,
        and nothing will say how far, since its answer is dropped when it comes (the run that asked for it
        has ended: rosbridge_suite drops an answer no call awaits too), and a service call cannot be cancelled
        over the rosbridge protocol. An actuator's service still takes no new call from this process until
        that answer comes or the bridge ends the call (:func:`given_up`), since the device may be executing it."""
        self._unsettle("the run was stopped while its call was out (the call was abandoned)")
        self._calls.released(self.service)
        dropped = _dropped(self.iri, self.service)
        if self.exclusive:
            self._calls.given_up(self.service, self.iri, pending, self._sent, self.timeout, dropped, awaited=False)
        else:
            pending.add_done_callback(dropped)
        self._fail()

    def _unsettle(self, reason: str) -> None:
        """The failed-step rule, once per call sent: nothing for a component without effects."""
        if not self._sent_call:
            return
        self._sent_call = False
        if self.kb is not None and self.classes is not None and (self.effects or self.deletes):
            unsettle(
                self.kb,
                self.classes,
                SentAndFailed(self.iri, self.service, reason, self._inputs, self.effects, self.deletes),
            )


def _dropped(component: str, service: str) -> Callable[[Future[dict[str, Any]]], None]:
    """What becomes of the answer to a call a Stop abandoned: it is logged, and nothing else."""

    def dropped(done: Future[dict[str, Any]]) -> None:
        error = None if done.cancelled() else done.exception()
        what = "answered" if not done.cancelled() and error is None else f"ended ({error or 'cancelled'})"
        log.info(
            "%s (%s) %s after the run that called it was stopped: dropped; what it would set stays unknown",
            component,
            service,
            what,
        )

    return dropped


def given_up(transport: Transport, service: str, clock: Callable[[], float] = time.monotonic) -> str:
    """Why no new call may be sent to ``service`` over ``transport`` now: its last call was given up
    (it timed out, or its step was halted) and has not answered yet, so the provider may still be
    executing it. Empty when the service is free: it answered late, or the transport ended the call
    (after ``LATE_WINDOW`` times the timeout, or the connection closed)."""
    return busy(transport, service, clock())
