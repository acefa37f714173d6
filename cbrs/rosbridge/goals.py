"""Action goals in flight: run by a handler on a worker thread, or forwarded to the client that provides the action.

Every goal ends in exactly one ``action_result`` to the client that sent it, with its id, as rosbridge_suite
(ROS 2) sends them: ``result: true`` with the goal's terminal status (``SUCCEEDED``, ``CANCELED`` or
``ABORTED``) and its values when the action ran to an end; ``result: false`` with status ``UNKNOWN`` and
the reason as ``values`` when the bridge could not run it (no such action, a refused goal, a handler
error, the provider gone, the server stopping). ``action_feedback`` goes to the client only if its goal
asked for it (``feedback: true``). Runs on the bridge's loop; only the handler itself runs on a worker
thread, where a :class:`GoalHandle` is its view of the goal.
"""

from __future__ import annotations

import asyncio
import contextlib
import itertools
import json
import logging
import threading
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from cbrs.rosbridge import protocol
from cbrs.rosbridge.errors import ServiceError
from cbrs.rosbridge.protocol import MessageId
from cbrs.rosbridge.session import _CALLER, Caller, Session
from cbrs.rosbridge.workers import WorkerPool

log = logging.getLogger("cbrs.rosbridge")


class GoalStatus(IntEnum):
    """ROS 2's ``action_msgs/msg/GoalStatus`` values, which ``action_result``'s ``status`` carries."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6


#: The statuses a goal can end with (what a provider's result is mapped onto, as ROS 2 does).
TERMINAL = (GoalStatus.SUCCEEDED, GoalStatus.CANCELED, GoalStatus.ABORTED)


@dataclass(frozen=True)
class GoalResult:
    """What an action handler returns when its goal did not simply succeed: the end status and values."""

    status: GoalStatus
    values: dict[str, Any]


class GoalHandle:
    """One goal as its action's handler sees it, on a worker thread.

    ``args`` is the goal; ``caller`` who sent it (as :func:`current_caller` gives it too).
    ``publish_feedback`` may be called from any thread; ``on_cancel`` callbacks run on the bridge's event
    loop (keep them short: set a flag, signal a thread), or at once if the cancel came first.
    """

    def __init__(
        self, action: str, args: dict[str, Any], caller: Caller, send: Callable[[str], None], non_finite: str = "null"
    ) -> None:
        self.action = action
        self.non_finite = non_finite  # how feedback's NaNs are written (protocol.NON_FINITE)
        self.args = args
        self.caller = caller
        self._send = send
        self._cancelled = threading.Event()
        self._callbacks: list[Callable[[], None]] = []
        self._lock = threading.Lock()

    @property
    def cancel_requested(self) -> bool:
        return self._cancelled.is_set()

    def wait_cancel(self, timeout: float) -> bool:
        """Block up to ``timeout`` seconds for a cancel request; True if one came."""
        return self._cancelled.wait(timeout)

    def publish_feedback(self, values: dict[str, Any]) -> None:
        """Send one ``action_feedback`` to the goal's client (if it asked for feedback)."""
        if not isinstance(values, dict):
            raise TypeError(f"feedback must be a dict, not {type(values).__name__}")
        self._send(protocol.dumps(values, self.non_finite))

    def on_cancel(self, callback: Callable[[], None]) -> None:
        """Call ``callback()`` when the client cancels the goal (now, if it already has)."""
        with self._lock:
            if not self._cancelled.is_set():
                self._callbacks.append(callback)
                return
        _run_callback(callback, self.action)

    def request_cancel(self) -> None:
        """The client (or the server stopping) asks the goal to stop."""
        with self._lock:
            if self._cancelled.is_set():
                return
            self._cancelled.set()
            callbacks, self._callbacks = self._callbacks, []
        for callback in callbacks:
            _run_callback(callback, self.action)


def _run_callback(callback: Callable[[], None], action: str) -> None:
    try:
        callback()
    except Exception:  # a handler's bug must not break the bridge's loop
        log.exception("a cancel callback of action %s failed", action)


ActionHandler = Callable[[GoalHandle], "dict[str, Any] | GoalResult"]


def run_action_handler(handler: ActionHandler, goal: GoalHandle) -> tuple[bool, GoalStatus, str]:
    """Run a handler to the goal's end: (result, status, encoded values), the values being the reason
    when ``result`` is False."""
    token = _CALLER.set(goal.caller)
    try:
        outcome = handler(goal)
        if isinstance(outcome, GoalResult):
            if outcome.status not in TERMINAL or not isinstance(outcome.values, dict):
                raise TypeError(f"a GoalResult needs a terminal status and dict values, not {outcome!r}")
            return True, GoalStatus(outcome.status), protocol.dumps(outcome.values, goal.non_finite)
        if not isinstance(outcome, dict):
            raise TypeError(f"the handler returned {type(outcome).__name__}, not a dict or a GoalResult")
        return True, GoalStatus.SUCCEEDED, protocol.dumps(outcome, goal.non_finite)
    except ServiceError as error:
        log.info("action %s: goal failed: %s", goal.action, error)
        return False, GoalStatus.UNKNOWN, protocol.dumps(str(error))
    except Exception as error:
        log.exception("action %s: handler raised", goal.action)
        return False, GoalStatus.UNKNOWN, protocol.dumps(f"internal error: {type(error).__name__}: {error}")
    finally:
        _CALLER.reset(token)


@dataclass(eq=False)
class Goal:
    """One goal in flight."""

    key: str  # the id the provider sees: action_goal:<action>:<n>, as rosbridge_suite names them
    action: str  # global name
    caller: Session
    caller_id: MessageId | None
    spelling: str  # the action name as the caller wrote it
    feedback: bool  # the caller asked for action_feedback
    provider: Session | None = None  # None: a server handler
    provider_spelling: str = ""
    handle: GoalHandle | None = None
    done: bool = False


class Goals:
    """The goals in flight on one running bridge."""

    def __init__(self, loop: asyncio.AbstractEventLoop, workers: WorkerPool, non_finite: str = "null") -> None:
        self._loop = loop
        self._workers = workers
        self._non_finite = non_finite  # how values' NaNs are written (protocol.NON_FINITE)
        self._pending: dict[str, Goal] = {}
        self._by_caller: dict[tuple[Session, MessageId], Goal] = {}
        self._keys = itertools.count(1)
        self._per_caller: Counter[Session] = Counter()

    def __len__(self) -> int:
        return len(self._pending)

    def in_flight(self, caller: Session) -> int:
        """How many of ``caller``'s goals have not ended."""
        return self._per_caller[caller]

    def new(self, caller: Session, message: protocol.Message, action: str) -> Goal:
        """A goal for a ``send_action_goal`` message (not yet started)."""
        key = f"action_goal:{action}:{next(self._keys)}"
        return Goal(key, action, caller, message.get("id"), message["action"], bool(message.get("feedback")))

    def sent(self, caller: Session, caller_id: MessageId | None) -> Goal | None:
        """The goal in flight that ``caller`` sent with id ``caller_id``."""
        return None if caller_id is None else self._by_caller.get((caller, caller_id))

    def to_handler(self, goal: Goal, handler: ActionHandler, args: dict[str, Any]) -> None:
        """Run ``handler`` on a worker thread; its outcome goes to the caller."""

        def send_feedback(values_json: str) -> None:
            with contextlib.suppress(RuntimeError):  # the loop has closed: the server stopped meanwhile
                self._loop.call_soon_threadsafe(self._feedback, goal, values_json)

        goal.handle = GoalHandle(goal.action, args, goal.caller.identity(), send_feedback, self._non_finite)
        self._start(goal)
        handle = goal.handle

        def job() -> None:
            if goal.done:  # ended (the server stopping) while waiting for a free worker
                return
            if handle.cancel_requested:  # cancelled before it started: the handler never runs
                outcome: tuple[bool, GoalStatus, str] = (True, GoalStatus.CANCELED, "{}")
            else:
                outcome = run_action_handler(handler, handle)
            with contextlib.suppress(RuntimeError):
                self._loop.call_soon_threadsafe(self.finish, goal, *outcome)

        try:
            self._workers.submit(job)
        except RuntimeError:
            self.fail(goal, "the server is shutting down")

    def to_provider(self, goal: Goal, provider: Session, spelling: str, kind: str, args: Any) -> None:
        """Forward the goal to the client ``provider`` under its key; it always gets feedback."""
        goal.provider, goal.provider_spelling = provider, spelling
        self._start(goal)
        provider.reply(protocol.send_action_goal(spelling, kind, args, goal.key, self._non_finite))

    def cancel(self, goal: Goal) -> None:
        """The caller asks its goal to stop: tell the handler, or forward to the provider."""
        if goal.handle is not None:
            goal.handle.request_cancel()
        elif goal.provider is not None:
            goal.provider.reply(protocol.cancel_action_goal(goal.provider_spelling, goal.key))

    def provided(self, provider: Session, key: MessageId | None) -> Goal | None:
        """The goal ``provider`` was forwarded under ``key``."""
        goal = self._pending.get(str(key))
        return goal if goal is not None and goal.provider is provider else None

    def provider_feedback(self, goal: Goal, values: dict[str, Any]) -> None:
        self._feedback(goal, protocol.dumps(values, self._non_finite))

    def provider_result(self, goal: Goal, result: bool, status: int, values: dict[str, Any] | None) -> None:
        """A provider's ``action_result``, mapped as ROS 2 ends the goal: SUCCEEDED and CANCELED stay,
        any other status, and ``result: false``, abort it."""
        ended = GoalStatus(status) if result and status in (GoalStatus.SUCCEEDED, GoalStatus.CANCELED) else None
        self.finish(goal, True, ended or GoalStatus.ABORTED, protocol.dumps(values or {}, self._non_finite))

    def fail_provider(self, provider: Session, action: str | None, reason: str) -> None:
        """End the goals forwarded to ``provider`` (for ``action``, or all of them)."""
        for goal in list(self._pending.values()):
            if goal.provider is provider and action in (None, goal.action):
                self.fail(goal, reason.format(action=goal.action))

    def stop_all(self, reason: str) -> None:
        """The server stops: every goal fails, and handlers are asked to stop."""
        for goal in list(self._pending.values()):
            if goal.handle is not None:
                goal.handle.request_cancel()
            self.fail(goal, reason)

    def fail(self, goal: Goal, reason: str) -> None:
        """End ``goal`` with rosbridge's failure: result false, status UNKNOWN, the reason as values."""
        self.finish(goal, False, GoalStatus.UNKNOWN, protocol.dumps(reason))

    def finish(self, goal: Goal, result: bool, status: GoalStatus, values_json: str) -> None:
        """Answer the caller once; later outcomes (a late handler, a late provider) are dropped."""
        if goal.done:
            return
        goal.done = True
        if self._pending.pop(goal.key, None) is not None:
            self._per_caller[goal.caller] -= 1
            if self._per_caller[goal.caller] <= 0:
                del self._per_caller[goal.caller]
        if goal.caller_id is not None and self._by_caller.get((goal.caller, goal.caller_id)) is goal:
            del self._by_caller[(goal.caller, goal.caller_id)]
        if not result:  # rosbridge logs its failures: an error status besides the result
            goal.caller.report("error", f"send_action_goal: {_reason(values_json)}", goal.caller_id)
        goal.caller.reply(protocol.action_result(goal.spelling, result, int(status), values_json, goal.caller_id))

    def _start(self, goal: Goal) -> None:
        self._pending[goal.key] = goal
        self._per_caller[goal.caller] += 1
        if goal.caller_id is not None:
            self._by_caller[(goal.caller, goal.caller_id)] = goal

    def _feedback(self, goal: Goal, values_json: str) -> None:
        if goal.feedback and not goal.done:
            goal.caller.reply(protocol.action_feedback(goal.spelling, values_json, goal.caller_id))


def _reason(values_json: str) -> str:
    decoded = json.loads(values_json)
    return decoded if isinstance(decoded, str) else values_json
