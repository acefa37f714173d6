"""The bridge: the rosbridge v2 ops over a graph of topics, services and actions, without any transport.

The server side (``add_service``, ``add_action``, ``add_topic``, ``publish``, ``params``) may be used
from any thread.
A transport (``server.py`` for websockets) attaches the bridge to its event loop, opens one
:class:`Session` per client, feeds it the client's text frames and closes it when the client goes.
"""

from __future__ import annotations

import asyncio
import contextlib
import functools
import hmac
import itertools
import logging
import math
from collections.abc import Awaitable, Callable, Mapping, Sequence
from importlib.resources import files
from typing import TYPE_CHECKING, Any

from cbrs.rosbridge import protocol, rosapi, wire
from cbrs.rosbridge.calls import Call, Calls, run_handler
from cbrs.rosbridge.errors import ProtocolError, RosbridgeError, UnknownTopicError
from cbrs.rosbridge.goals import ActionHandler, Goal, Goals, GoalStatus
from cbrs.rosbridge.graph import Action, Graph, Handler, Service, Topic
from cbrs.rosbridge.interfaces import Interfaces
from cbrs.rosbridge.params import ParamStore
from cbrs.rosbridge.protocol import LEVELS, Message, MessageId
from cbrs.rosbridge.session import Session
from cbrs.rosbridge.workers import WorkerPool

if TYPE_CHECKING:
    from cbrs.rosbridge.server import RunningBridge

log = logging.getLogger("cbrs.rosbridge")

MIB = 1 << 20

#: rosapi's own service types (ROS 1's), so a call may give its args as a list in field order and the
#: details services describe them.
ROSAPI_DEFINITIONS = files("cbrs.rosbridge") / "definitions" / "rosapi"

#: The status a binary frame that holds no UTF-8 JSON gets.
BINARY_REFUSED = (
    "binary frames are not supported unless they hold UTF-8 JSON text (as rosbridge_suite reads them):"
    " CBOR or BSON from a client is not read; send the message as JSON"
)


@functools.cache
def _rosapi_interfaces() -> Interfaces:
    interfaces = Interfaces()
    interfaces.load(ROSAPI_DEFINITIONS, "rosapi")
    return interfaces


def _json_in_binary(frame: bytes) -> str | None:
    """A binary frame's text if it can be JSON: UTF-8 with no NUL (JSON has none; BSON ends with one,
    and CBOR's maps start with a byte no UTF-8 text starts with)."""
    if b"\x00" in frame:
        return None
    try:
        return frame.decode("utf-8")
    except UnicodeDecodeError:
        return None


def _message_id(value: Any) -> MessageId | None:
    """``value`` if it can be a message's id (a string or an integer), else None."""
    return value if isinstance(value, str | int) and not isinstance(value, bool) else None


def _api_name(name: str, what: str) -> str:
    if not isinstance(name, str) or not name.strip("/ "):
        raise ValueError(f"{what} name must be a non-empty string like '/cbrs/query', not {name!r}")
    return protocol.resolve(name)


class Bridge:
    """A rosbridge v2 server core: topics, services and parameters shared by its clients.

    ``max_message_bytes`` bounds one incoming message (larger ones get a status error);
    ``call_timeout`` (seconds) bounds every service call unless the call sets its own ``timeout``;
    ``params`` seeds the parameter store; ``max_queue_length`` bounds every subscription's queue (and
    how far a pass-through subscriber may fall behind) and ``max_queue_bytes`` the characters it holds;
    ``service_workers`` threads run service handlers and ``action_workers`` other threads action handlers
    (goals run long: they must not hold up service calls). ``token``, when set, is what a client sends with the
    ``auth`` op to be :attr:`Caller.authorised`; topics and services whose names start with one of
    ``reserved`` (and every topic added with :meth:`add_topic`) belong to the server: clients may
    subscribe, call and send goals, but not advertise, publish or provide them. One client address may hold
    ``connections_per_client`` connections; the next is closed at once (code 1013, try again later).
    ``non_finite`` says how JSON text carries a NaN or an infinity, which JSON has no number for:
    ``"null"`` (rosbridge_suite's way, which roslibjs can parse) or ``"tokens"`` (``NaN``, ``Infinity``,
    ``-Infinity``, which roslibpy reads back as floats and roslibjs cannot parse); CBOR carries them as
    they are (:data:`protocol.NON_FINITE`, docs/rosbridge.md).
    """

    def __init__(
        self,
        *,
        max_message_bytes: int = MIB,
        call_timeout: float = 30.0,
        params: Mapping[str, Any] | None = None,
        max_queue_length: int = 1000,
        service_workers: int = 8,
        max_queue_bytes: int = 16 * MIB,
        token: str | None = None,
        reserved: Sequence[str] = (),
        connections_per_client: int = 64,
        action_workers: int = 4,
        non_finite: str = "null",
        max_calls_per_client: int = 256,
        max_names_per_client: int = 1000,
    ) -> None:
        for label, value in [
            ("max_message_bytes", max_message_bytes),
            ("call_timeout", call_timeout),
            ("max_queue_length", max_queue_length),
            ("service_workers", service_workers),
            ("max_queue_bytes", max_queue_bytes),
            ("connections_per_client", connections_per_client),
            ("action_workers", action_workers),
            ("max_calls_per_client", max_calls_per_client),
            ("max_names_per_client", max_names_per_client),
        ]:
            if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
                raise ValueError(f"{label} must be a positive number, not {value!r}")
        self.max_message_bytes = int(max_message_bytes)
        self.call_timeout = float(call_timeout)
        self.max_queue_length = int(max_queue_length)
        self.service_workers = int(service_workers)
        self.max_queue_bytes = int(max_queue_bytes)
        self.connections_per_client = int(connections_per_client)
        self.action_workers = int(action_workers)
        self.max_calls_per_client = int(max_calls_per_client)
        self.max_names_per_client = int(max_names_per_client)
        self.token = token
        self.non_finite = protocol.check_non_finite(non_finite)
        self.reserved = tuple(protocol.resolve(prefix) for prefix in reserved)
        self.params = ParamStore(params)
        self.interfaces = Interfaces()
        """The message and service types rosapi describes: add a package's with ``interfaces.load``."""
        rosapi_types = _rosapi_interfaces()  # read once per process: the definitions are immutable
        self.interfaces.messages.update(rosapi_types.messages)
        self.interfaces.services.update(rosapi_types.services)
        self._graph = Graph()
        services = rosapi.services(self._graph, self.params, self.non_finite, self.interfaces)
        for name, (kind, handler) in services.items():
            self._graph.services[name] = Service(name, kind, handler, inline=True)
        self._loop: asyncio.AbstractEventLoop | None = None
        self._calls: Calls | None = None
        self._workers: WorkerPool | None = None
        self._goals: Goals | None = None
        self._goal_workers: WorkerPool | None = None
        self._writers: dict[Session, asyncio.Task[None]] = {}
        self._clients = itertools.count(1)
        self._disconnect_listeners: list[Callable[[str], None]] = []
        self._holders: list[Callable[[str, str], str | None]] = []
        self._verdicts: list[Callable[[str], bool]] = []
        self._ops: dict[str, Callable[[Session, Message], None]] = {
            "advertise": self._advertise,
            "unadvertise": self._unadvertise,
            "publish": self._publish,
            "subscribe": self._subscribe,
            "unsubscribe": self._unsubscribe,
            "call_service": self._call_service,
            "service_response": self._service_response,
            "advertise_service": self._advertise_service,
            "unadvertise_service": self._unadvertise_service,
            "advertise_action": self._advertise_action,
            "unadvertise_action": self._unadvertise_action,
            "send_action_goal": self._send_action_goal,
            "cancel_action_goal": self._cancel_action_goal,
            "action_feedback": self._action_feedback,
            "action_result": self._action_result,
            "set_level": self._set_level,
            "auth": self._auth,
            "fragment": self._fragment,
        }

    # -- the server side ----------------------------------------------------------------------------

    def add_service(self, name: str, type: str, handler: Handler) -> None:
        """Offer a service answered by ``handler(args) -> values`` on a worker thread.

        Raising :class:`ServiceError` fails the call with that text; any other exception fails it with
        ``internal error: <type>: <message>`` (and is logged).
        """
        name = _api_name(name, "service")
        if not callable(handler):
            raise TypeError(f"the handler of {name} must be callable, not {handler!r}")
        with self._graph.lock:
            existing = self._graph.services.get(name)
            if existing is not None:
                owner = existing.provider.name if existing.provider else "the server"
                raise RosbridgeError(f"service {name!r} is already provided by {owner}")
            self._graph.services[name] = Service(name, type, handler)

    def remove_service(self, name: str) -> None:
        """Withdraw a service added with :meth:`add_service`; calls in flight still get their answer."""
        name = _api_name(name, "service")
        with self._graph.lock:
            service = self._graph.services.get(name)
            if service is None or service.handler is None or service.inline:
                raise RosbridgeError(f"service {name!r} was not added by add_service")
            del self._graph.services[name]

    def add_action(self, name: str, type: str, handler: ActionHandler) -> None:
        """Offer an action whose goals ``handler(goal: GoalHandle)`` runs to the end on a worker thread.

        The handler returns the result values (the goal succeeded) or a :class:`GoalResult` with the end
        status (CANCELED, ABORTED); it may send ``goal.publish_feedback(values)`` and should stop when
        ``goal.cancel_requested``. Raising :class:`ServiceError` fails the goal with that text, as
        rosbridge fails it (``result: false``, status UNKNOWN); any other exception too, as an internal
        error (and is logged).
        """
        name = _api_name(name, "action")
        if not callable(handler):
            raise TypeError(f"the handler of {name} must be callable, not {handler!r}")
        with self._graph.lock:
            existing = self._graph.actions.get(name)
            if existing is not None:
                owner = existing.provider.name if existing.provider else "the server"
                raise RosbridgeError(f"action {name!r} is already provided by {owner}")
            self._graph.actions[name] = Action(name, type, handler)

    def remove_action(self, name: str) -> None:
        """Withdraw an action added with :meth:`add_action`; goals in flight run to their end."""
        name = _api_name(name, "action")
        with self._graph.lock:
            action = self._graph.actions.get(name)
            if action is None or action.handler is None:
                raise RosbridgeError(f"action {name!r} was not added by add_action")
            del self._graph.actions[name]

    def add_topic(self, name: str, type: str, *, latch: bool = False) -> None:
        """Declare a topic the server publishes on; with ``latch``, new subscribers get its last message."""
        name = _api_name(name, "topic")
        with self._graph.lock:
            topic = self._graph.topics.get(name)
            if topic is None:
                topic = self._graph.topics[name] = Topic(name, type)
            elif topic.type and not protocol.same_type(topic.type, type):
                raise RosbridgeError(f"topic {name!r} already has type {topic.type!r}, not {type!r}")
            topic.type, topic.server, topic.latch = type, True, topic.latch or latch

    def publish(self, topic: str, msg: dict[str, Any]) -> None:
        """Publish ``msg`` on a topic added with :meth:`add_topic`; may be called from any thread.

        Besides JSON values, ``msg`` may hold numeric arrays (``array.array``, 1-D numpy arrays) and
        ``bytes``: JSON subscribers get them as lists and base64 text, ``compression: "cbor"`` ones as
        RFC 8746 typed arrays and byte strings, as rosbridge_suite sends a ROS message's arrays. NaNs and
        infinities go to JSON subscribers as ``non_finite`` says and to CBOR ones as they are.
        """
        name = _api_name(topic, "topic")
        if not isinstance(msg, dict):
            raise TypeError(f"a message must be a dict, not {type(msg).__name__}")
        values = None  # JSON holds all of it: a CBOR subscriber's values are read back from the text
        try:
            text, exact = protocol.encode(msg, self.non_finite)
        except TypeError:  # typed arrays or bytes (else the same TypeError again): kept for CBOR, copied
            text, exact = wire.typed_encode(msg, self.non_finite)
            values = wire.cbor_values(msg)
        if not exact and values is None:  # NaN written as null: CBOR subscribers get the floats, copied
            values = wire.cbor_values(msg)
        with self._graph.lock:
            entry = self._graph.topics.get(name)
            if entry is None or not entry.server:
                raise UnknownTopicError(topic)
            if entry.latch:
                entry.latched, entry.latched_values = text, values
            loop = self._loop
        if loop is not None:
            with contextlib.suppress(RuntimeError):  # the loop closed under us: the server is stopping
                loop.call_soon_threadsafe(self._fan_out, name, text, None, values)

    def fail_calls(self, service: str, reason: str) -> None:
        """Fail every call waiting on the client that provides ``service``, with ``reason``; from any
        thread. What a disconnect does, for a provider the server has given up on while it stays
        connected (a live component whose lease lapsed: its late answer would act on a plan that has
        moved on). Nothing when no client provides the service or the bridge is not serving."""
        name = protocol.resolve(service, "service")
        with self._graph.lock:
            found = self._graph.services.get(name)
            provider = found.provider if found is not None else None
            loop, calls = self._loop, self._calls
        if provider is None or loop is None or calls is None:
            return
        with contextlib.suppress(RuntimeError):  # the loop closed under us: the server is stopping
            loop.call_soon_threadsafe(calls.fail_provider, provider, name, reason)

    def provider(self, service: str) -> str | None:
        """The name of the client that provides ``service`` (its session's, as logs and holders name
        it); None when the server does or nobody."""
        name = protocol.resolve(service, "service")
        with self._graph.lock:
            found = self._graph.services.get(name)
            return found.provider.name if found is not None and found.provider is not None else None

    def topics(self) -> list[tuple[str, str]]:
        """(name, type) of every topic: the server's, advertised and subscribed ones."""
        return self._graph.topic_list()

    def services(self) -> list[tuple[str, str]]:
        """(name, type) of every service: rosapi, the server's and those clients provide."""
        return self._graph.service_list()

    def actions(self) -> list[tuple[str, str]]:
        """(name, type) of every action: the server's and those clients provide."""
        return self._graph.action_list()

    def start(
        self, host: str = "127.0.0.1", port: int = 9090, *, origins: Sequence[str | None] | None = None
    ) -> RunningBridge:
        """Serve on a websocket in a background thread with its own event loop (port 0 picks a free one).

        ``origins`` limits which web pages may connect (see :func:`cbrs.rosbridge.server.serve`).
        """
        from cbrs.rosbridge.server import start

        return start(self, host, port, origins=origins)

    async def serve(
        self, host: str = "127.0.0.1", port: int = 9090, *, ready: Callable[[int], None] | None = None
    ) -> None:
        """Serve on a websocket in the running event loop until cancelled; ``ready(port)`` once bound."""
        from cbrs.rosbridge.server import serve

        await serve(self, host, port, ready=ready)

    # -- the transport interface --------------------------------------------------------------------

    @property
    def running(self) -> bool:
        return self._loop is not None

    def attach(self, loop: asyncio.AbstractEventLoop) -> None:
        """Bind to the event loop that will run the sessions (one at a time)."""
        if self._loop is not None:
            raise RosbridgeError("this bridge is already being served; stop it before serving it again")
        self._workers = WorkerPool(self.service_workers)
        self._goal_workers = WorkerPool(self.action_workers, name="cbrs-rosbridge-action")
        self._calls = Calls(loop, self._workers, self.non_finite, self._strict)
        self._goals = Goals(loop, self._goal_workers, self.non_finite)
        self._loop = loop

    async def detach(self) -> list[WorkerPool]:
        """Close every session, fail the calls and goals in flight (asking action handlers to stop);
        returns the (shut down) worker pools to join."""
        for session in list(self._writers):
            self.close_session(session)
        assert self._calls is not None and self._workers is not None
        assert self._goals is not None and self._goal_workers is not None
        self._calls.fail_all("the server is shutting down")
        self._goals.stop_all("the server is shutting down")
        pools = [self._workers, self._goal_workers]
        for pool in pools:
            pool.shutdown()
        self._loop = self._calls = self._workers = self._goals = self._goal_workers = None
        return pools

    def open_session(
        self,
        peer: str,
        send: Callable[[str | bytes], Awaitable[None]],
        abort: Callable[[str], None],
        origin: str | None = None,
        address: str | None = None,
        send_many: Callable[[list[str | bytes]], Awaitable[None]] | None = None,
    ) -> Session:
        """A new client (``peer`` names it in logs, ``address`` is its IP address, ``origin`` its
        handshake's Origin header); its writer task starts on the attached loop. ``send`` sends one
        message; ``send_many``, if the transport has it, several in order with fewer writes."""
        if self._loop is None:
            raise RosbridgeError("the bridge is not attached to an event loop")
        session = Session(
            f"client {next(self._clients)} ({peer})",
            send,
            abort,
            self.max_queue_length,
            peer=address if address is not None else peer,
            origin=origin,
            backlog_bytes=self.max_queue_bytes,
            send_many=send_many,
        )
        self._writers[session] = self._loop.create_task(session.run(), name=f"rosbridge writer {session.name}")
        log.info("%s connected", session.name)
        return session

    def receive(self, session: Session, frame: str | bytes) -> None:
        """Handle one frame from a client; a bad one gets a status error, never an exception.

        A binary frame is read as UTF-8 JSON, as rosbridge_suite reads one; CBOR or BSON is not read
        (rosbridge_suite reads neither from a client, bar BSON in its bson_only_mode) and is refused.
        """
        if not isinstance(frame, str):
            text = _json_in_binary(frame)
            if text is None:
                session.report("error", BINARY_REFUSED)
                return
            frame = text
        self._handle(session, frame)

    def _handle(self, session: Session, frame: str, whole: bool = False) -> None:
        """Decode, check and act on one message's text (``whole``: put together from fragments)."""
        op: str | None = None
        message_id = None
        message: Message | None = None
        try:
            try:
                message = protocol.decode(frame, self.max_message_bytes)
            except ProtocolError as error:
                texts = protocol.several(frame) if "Extra data" in error.reason else None
                if texts is None:
                    raise
                for text in texts:  # as rosbridge_suite reads a frame of several messages: one by one
                    self._handle(session, text, whole)
                return
            message_id = message.get("id")
            op = protocol.check(message)
            if whole and op == "fragment":
                raise ProtocolError("the pieces of a message put together must not be a fragment again", op)
            self._ops[op](session, message)
        except ProtocolError as error:
            request = message if message is not None else protocol.leading_fields(frame)
            if message is None:  # not read (too large, not JSON): its leading fields may still say what it was
                op = request["op"] if isinstance(request.get("op"), str) else None
                message_id = _message_id(request.get("id"))
            op = error.op or op
            text = f"{op}: {error.reason}" if op else error.reason
            log.info("%s: %s", session.name, text)
            session.report("error", text, error.message_id if error.message_id is not None else message_id)
            named = request.get("service")
            self._refuse_answer(session, frame, op, message_id, error.reason, message is not None, named)
            if op == "call_service" and message_id is not None:  # its caller waits for an answer: this is it
                self._refuse_call(session, request, message_id, text)
            if op == "send_action_goal" and (message is not None or message_id is not None):  # its callbacks too
                self._refuse_goal(session, {**request, "id": message_id}, text)
        except Exception as error:
            log.exception("%s: %s failed", session.name, op)
            session.report("error", f"{op or 'message'}: internal error: {type(error).__name__}: {error}", message_id)

    def _refuse_answer(
        self,
        session: Session,
        frame: str,
        op: str | None,
        message_id: MessageId | None,
        reason: str,
        read: bool,
        named: Any = None,
    ) -> None:
        """A provider's answer the bridge refused (a field of the wrong type, too large to read) fails the
        call it answers at once, with the reason the provider is told: the caller would otherwise wait
        for the call's timeout with the reason known here. Not when it ``named`` another service than
        that call's: it is not that call's answer."""
        if self._calls is None or not session.provided:
            return
        if op == "service_response" and message_id is not None:
            self._calls.refuse(session, message_id, reason, named)
        elif op in (None, "service_response") and message_id is None and not read:  # its id comes late, if at all
            self._calls.refuse_unread(session, frame, reason)

    def _refuse_call(self, session: Session, request: Message, message_id: MessageId, reason: str) -> None:
        """Answer a ``call_service`` that could not be read or checked (too large, a field of the wrong
        type) with a failed ``service_response``: roslibjs waits for the answer without a timeout."""
        spelling = request.get("service")
        spelling = spelling if isinstance(spelling, str) else ""
        session.reply(protocol.service_response(spelling, False, protocol.dumps(reason), message_id))

    def close_session(self, session: Session) -> None:
        """The client has gone: drop its topics, services and subscriptions, fail calls waiting on it."""
        if session not in self._writers:
            return
        session.close()
        self._writers.pop(session).cancel()
        with self._graph.lock:
            for name in session.advertised:
                self._graph.topics[name].publishers.discard(session)
                self._graph.prune(name)
            for name in session.queues:
                self._graph.topics[name].subscribers.discard(session)
                self._graph.prune(name)
            for name in session.provided:
                service = self._graph.services.get(name)
                if service is not None and service.provider is session:
                    del self._graph.services[name]
            for name in session.provided_actions:
                action = self._graph.actions.get(name)
                if action is not None and action.provider is session:
                    del self._graph.actions[name]
        if self._calls is not None:
            self._calls.fail_provider(session, None, "the provider of {service!r} disconnected")
        if self._goals is not None:
            self._goals.fail_provider(session, None, "the provider of {action!r} disconnected")
        log.info("%s disconnected", session.name)
        for listener in list(self._disconnect_listeners):
            try:
                listener(session.name)
            except Exception:  # a listener's bug must not keep the session open
                log.exception("a disconnect listener failed for %s", session.name)

    def hold_services(self, holder: Callable[[str, str], str | None]) -> None:
        """Ask ``holder(service, session name)`` on the bridge's loop (keep it short) whenever a client
        advertises a service: a text refuses the advertisement with that reason. ``cbrs serve`` keeps a
        live component's service for the session that registered it; another client would otherwise take
        its calls (a client may take a service over from another, as in rosbridge_suite)."""
        self._holders.append(holder)

    def strict_results(self, predicate: Callable[[str], bool]) -> None:
        """A provider's ``result: false`` fails the call of a service ``predicate(service)`` is true for,
        even with an object of values, which rosbridge_suite takes as the answer (below): roslibpy
        answers ``{}`` with a handler's ``False``, and a live component that cannot act must not be
        taken for one that acted. Such a service's answer holding a NaN or an infinity (roslibpy sends the
        tokens) fails too, naming the field: JSON callers would get ``null``, a broken reading taken for a
        missing one. Asked on the bridge's loop: keep it short."""
        self._verdicts.append(predicate)

    def _strict(self, service: str) -> bool:
        return any(predicate(service) for predicate in self._verdicts)

    def on_disconnect(self, listener: Callable[[str], None]) -> None:
        """Call ``listener(session name)`` on the bridge's loop when a client disconnects (a live
        component's registration ends with its session)."""
        self._disconnect_listeners.append(listener)

    # -- ops ----------------------------------------------------------------------------------------

    def _hold_name(self, session: Session, held: Mapping[str, Any], name: str) -> None:
        """Refuse a new topic, service or action name to a client that holds ``max_names_per_client``
        already: each costs the server memory, and every rosapi listing, for as long as it stays."""
        if name in held:
            return
        count = len(session.queues) + len(session.advertised) + len(session.provided) + len(session.provided_actions)
        if count >= self.max_names_per_client:
            raise ProtocolError(
                f"this client holds {count} topics, services and actions already (max_names_per_client):"
                " unsubscribe or unadvertise some first"
            )

    def _owned(self, name: str) -> bool:
        return bool(self.reserved) and name.startswith(self.reserved)

    def _refuse_owned_topic(self, name: str, topic: Topic | None) -> None:
        if (topic is not None and topic.server) or self._owned(name):
            raise ProtocolError(
                f"topic {name!r} belongs to this server: clients may subscribe to it, not advertise or publish on it"
            )

    def _advertise(self, session: Session, message: Message) -> None:
        name, kind = protocol.resolve(message["topic"], "topic"), message["type"]
        if not kind:
            raise ProtocolError("field 'type' must name the message type, e.g. 'std_msgs/String'")
        self._hold_name(session, session.advertised, name)
        with self._graph.lock:
            topic = self._graph.topics.get(name)
            self._refuse_owned_topic(name, topic)
            if topic is None:
                topic = self._graph.topics[name] = Topic(name, kind)
            elif topic.type and not protocol.same_type(topic.type, kind):
                raise ProtocolError(f"topic {name!r} already has type {topic.type!r}, not {kind!r}")
            topic.type = kind
            topic.latch = topic.latch or bool(message.get("latch"))
            topic.publishers.add(session)
        session.advertised[name] = message["topic"]
        session.report("info", f"advertised {name} ({kind})", message.get("id"))

    def _unadvertise(self, session: Session, message: Message) -> None:
        name = protocol.resolve(message["topic"], "topic")
        if session.advertised.pop(name, None) is None:
            session.report("warning", f"unadvertise: this client does not advertise {name!r}", message.get("id"))
            return
        with self._graph.lock:
            self._graph.topics[name].publishers.discard(session)
            self._graph.prune(name)
        session.report("info", f"unadvertised {name}", message.get("id"))

    def _publish(self, session: Session, message: Message) -> None:
        # every message a client publishes passes here: keep it lean (bench/rosbridge_relay.py)
        spelling = message["topic"]
        name = spelling if spelling[:1] == "/" else protocol.resolve(spelling, "topic")
        with self._graph.lock:
            topic = self._graph.topics.get(name)
            # a publisher of the topic has passed the checks: only the server may take the topic since
            if topic is None or topic.server or session not in topic.publishers:
                self._refuse_owned_topic(name, topic)
                if topic is None:
                    raise ProtocolError(f"topic {name!r} is not advertised: send advertise (with its type) first")
                self._hold_name(session, session.advertised, name)
                topic.publishers.add(session)
                session.advertised.setdefault(name, spelling)
            latch = topic.latch or message.get("latch")
            subscribers = list(topic.subscribers)
        if not (subscribers or latch):  # nobody to send it to, now or later: not even encoded
            return
        values = message.get("msg")
        if values is None:  # rosbridge_suite publishes a message of defaults (std_msgs/Empty: nothing)
            values = {}
        text, exact = protocol.encode_decoded(values, self.non_finite)
        if latch:  # the text if it holds every number (a late CBOR subscriber reads it back): a map costs more
            with self._graph.lock:
                topic.latched, topic.latched_values = text, None if exact else values
        self._fan_out(name, text, subscribers, values)

    def _subscribe(self, session: Session, message: Message) -> None:
        name, kind, message_id = protocol.resolve(message["topic"], "topic"), message.get("type"), message.get("id")
        self._hold_name(session, session.queues, name)
        throttle_rate, queue_length = message.get("throttle_rate", 0), message.get("queue_length", 0)
        if throttle_rate < 0 or queue_length < 0:
            raise ProtocolError("throttle_rate and queue_length must not be negative")
        if queue_length > self.max_queue_length:
            session.report("warning", f"queue_length {queue_length} lowered to {self.max_queue_length}", message_id)
            queue_length = self.max_queue_length
        compression = message.get("compression") or "none"
        if compression == "cbor-raw":
            raise ProtocolError(
                f"compression 'cbor-raw' sends each message in its ROS serialization, and topic {name!r} has none"
                " here: this server relays JSON values without ROS message definitions; subscribe with"
                " compression 'cbor' (the same values as CBOR) or 'none'"
            )
        if compression not in ("none", "png", "cbor"):
            session.report("warning", f"compression {compression!r} is not supported; sending JSON", message_id)
            compression = "none"
        fragment_size = self._fragment_size(session, message)
        if compression == "cbor" and fragment_size is not None:
            text = "fragment_size does not apply to compression 'cbor': fragments carry JSON text, so each CBOR"
            session.report("warning", f"{text} message goes whole, in one binary frame", message_id)
        with self._graph.lock:
            topic = self._graph.topics.get(name)
            if topic is None:
                topic = self._graph.topics[name] = Topic(name, kind or "")
            elif kind and topic.type and not protocol.same_type(topic.type, kind):
                raise ProtocolError(f"topic {name!r} has type {topic.type!r}, not {kind!r}")
            topic.type = topic.type or kind or ""
            topic.subscribers.add(session)
            latched, latched_values = topic.latched, topic.latched_values
        session.subscribe(name, message["topic"], message_id, throttle_rate, queue_length, compression, fragment_size)
        if latched is not None:
            if name in session.cbor:
                values = protocol.loads(latched) if latched_values is None else latched_values
                session.offer(name, wire.cbor_publish(message["topic"], values))
            else:
                session.offer(name, protocol.publish_text(message["topic"], latched))
        session.report("info", f"subscribed to {name}", message_id)

    def _unsubscribe(self, session: Session, message: Message) -> None:
        name, message_id = protocol.resolve(message["topic"], "topic"), message.get("id")
        queue = session.queues.get(name)
        if queue is None or (message_id is not None and message_id not in queue.requests):
            which = "" if message_id is None else f" with id {message_id!r}"
            session.report("warning", f"unsubscribe: no subscription to {name!r}{which}", message_id)
            return
        if session.unsubscribe(name, message_id, every=message_id is None):
            with self._graph.lock:
                self._graph.topics[name].subscribers.discard(session)
                self._graph.prune(name)
        session.report("info", f"unsubscribed from {name}", message_id)

    def _call_service(self, session: Session, message: Message) -> None:
        assert self._calls is not None
        name = protocol.resolve(message["service"], "service")
        args = message.get("args") or {}
        timeout = message.get("timeout") or 0.0
        if not math.isfinite(timeout):  # JSON has no infinity, but a client may send Python's token for one
            raise ProtocolError(f"timeout must be a finite number of seconds (0: the server's), not {timeout}")
        timeout = timeout if timeout > 0 else self.call_timeout
        call = Call(self._calls.new_key(name), name, session, message.get("id"), message["service"])
        call.fragment_size = self._fragment_size(session, message)
        with self._graph.lock:
            service = self._graph.services.get(name)
        if service is None:
            self._calls.finish(call, False, protocol.dumps(f"service {name!r} does not exist"))
            return
        if isinstance(args, list):
            args = self._named_args(service, args)
        if not service.inline and self._calls.in_flight(session) >= self.max_calls_per_client:
            reason = (
                f"this client has {self.max_calls_per_client} calls waiting for answers already"
                " (max_calls_per_client): wait for their answers before sending more"
            )
            self._calls.finish(call, False, protocol.dumps(reason))
        elif service.provider is not None:
            provider = service.provider
            self._calls.to_provider(call, provider, provider.provided[name], args, timeout)
        elif not isinstance(args, dict):
            reason = f"service {name!r} takes its args as an object of named fields, not an array"
            self._calls.finish(call, False, protocol.dumps(reason))
        elif service.inline:
            assert service.handler is not None
            self._calls.finish(call, *run_handler(service.handler, args, name, session.identity(), self.non_finite))
        else:
            assert service.handler is not None
            self._calls.to_handler(call, service.handler, args, timeout)

    def _named_args(self, service: Service, args: list[Any]) -> dict[str, Any] | list[Any]:
        """``args`` given as a list, as rosbridge_suite takes them: the request's fields in the order its
        definition lists them (the service's type must be one ``interfaces`` defines). A list for a
        type not defined here goes as it is to a providing client, and is refused by a server handler."""
        fields = self.interfaces.request_fields(service.type)
        if fields is None:
            return args
        if len(args) > len(fields):
            listed = ", ".join(fields) or "none"
            raise ProtocolError(
                f"service {service.name!r} ({service.type}) takes {len(fields)} request fields ({listed}),"
                f" not the {len(args)} values of args"
            )
        return dict(zip(fields, args, strict=False))

    def _service_response(self, session: Session, message: Message) -> None:
        assert self._calls is not None
        message_id = message.get("id")
        if message_id is None:
            name = protocol.resolve(message["service"], "service")
            failed = self._calls.refuse_sole(session, name, "it has no 'id'")
            raise ProtocolError(
                "missing field 'id': a service_response carries the id of the call_service it answers"
                + (f" (the one call of {name} waiting on this client failed)" if failed else "")
            )
        name = protocol.resolve(message["service"], "service")
        if not self._calls.answer(session, message_id, message["result"], message.get("values"), name):
            raise ProtocolError(f"no call with id {message_id!r} is waiting for this client's answer")

    def _advertise_service(self, session: Session, message: Message) -> None:
        name, kind = protocol.resolve(message["service"], "service"), message["type"]
        self._hold_name(session, session.provided, name)
        if self._owned(name):
            raise ProtocolError(f"service {name!r} is in a namespace of this server; clients cannot provide it")
        for holder in self._holders:
            held = holder(name, session.name)
            if held is not None:
                raise ProtocolError(held)
        with self._graph.lock:
            service = self._graph.services.get(name)
            if service is not None and service.provider is None:
                raise ProtocolError(f"service {name!r} is provided by the server and cannot be advertised")
            previous = service.provider if service is not None else None
            self._graph.services[name] = Service(name, kind, provider=session)
        if previous is not None and previous is not session:
            previous.provided.pop(name, None)
            log.warning("%s took over service %s from %s", session.name, name, previous.name)
            session.report("warning", f"took over {name} from {previous.name}", message.get("id"))
        session.provided[name] = message["service"]
        session.report("info", f"advertised service {name} ({kind})", message.get("id"))

    def _unadvertise_service(self, session: Session, message: Message) -> None:
        assert self._calls is not None
        name = protocol.resolve(message["service"], "service")
        if session.provided.pop(name, None) is None:  # an error, as rosbridge_suite reports it
            raise ProtocolError(f"this client does not provide service {name!r}")
        with self._graph.lock:
            del self._graph.services[name]
        self._calls.fail_provider(session, name, "service {service!r} was unadvertised by its provider")
        session.report("info", f"unadvertised service {name}", message.get("id"))

    def _advertise_action(self, session: Session, message: Message) -> None:
        name, kind = protocol.resolve(message["action"], "action"), message["type"]
        self._hold_name(session, session.provided_actions, name)
        if self._owned(name):
            raise ProtocolError(f"action {name!r} is in a namespace of this server; clients cannot provide it")
        with self._graph.lock:
            action = self._graph.actions.get(name)
            if action is not None and action.provider is None:
                raise ProtocolError(f"action {name!r} is provided by the server and cannot be advertised")
            previous = action.provider if action is not None else None
            self._graph.actions[name] = Action(name, kind, provider=session, spelling=message["action"])
        if previous is not None and previous is not session:  # goals in flight stay with the old provider
            previous.provided_actions.pop(name, None)
            log.warning("%s took over action %s from %s", session.name, name, previous.name)
            session.report("warning", f"took over action {name} from {previous.name}", message.get("id"))
        session.provided_actions[name] = message["action"]
        session.report("info", f"advertised action {name} ({kind})", message.get("id"))

    def _unadvertise_action(self, session: Session, message: Message) -> None:
        assert self._goals is not None
        name = protocol.resolve(message["action"], "action")
        if session.provided_actions.pop(name, None) is None:
            raise ProtocolError(f"this client does not provide action {name!r}")
        with self._graph.lock:
            del self._graph.actions[name]
        self._goals.fail_provider(session, name, "action {action!r} was unadvertised by its provider")
        session.report("info", f"unadvertised action {name}", message.get("id"))

    def _send_action_goal(self, session: Session, message: Message) -> None:
        assert self._goals is not None
        name = protocol.resolve(message["action"], "action")
        goal = self._goals.new(session, message, name)
        args = message.get("args")
        args = {} if args is None else args
        with self._graph.lock:
            action = self._graph.actions.get(name)
        if self._goals.sent(session, goal.caller_id) is not None:
            self._goals.fail(goal, f"a goal with id {goal.caller_id!r} is already running; give each goal its own id")
        elif action is None:
            self._goals.fail(goal, f"action {name!r} does not exist")
        elif self._goals.in_flight(session) >= self.max_calls_per_client:
            reason = f"this client has {self.max_calls_per_client} goals in progress already (max_calls_per_client)"
            self._goals.fail(goal, f"{reason}: wait for their results before sending more")
        elif action.provider is not None:
            self._goals.to_provider(goal, action.provider, action.spelling, action.type, args)
        elif not isinstance(args, dict):
            self._goals.fail(goal, f"action {name!r} takes its goal as an object of named fields, not an array")
        else:
            assert action.handler is not None
            self._goals.to_handler(goal, action.handler, args)

    def _refuse_goal(self, session: Session, message: Message, reason: str) -> None:
        """Answer a ``send_action_goal`` that could not be read with a failed ``action_result``."""
        spelling = message.get("action")
        spelling = spelling if isinstance(spelling, str) else ""
        values = protocol.dumps(reason)
        session.reply(protocol.action_result(spelling, False, GoalStatus.UNKNOWN, values, message.get("id")))

    def _cancel_action_goal(self, session: Session, message: Message) -> None:
        assert self._goals is not None
        message_id = message.get("id")
        if message_id is None:
            raise ProtocolError("missing field 'id': the id of the goal to cancel")
        goal = self._goals.sent(session, message_id)
        if goal is None:
            text = f"cancel_action_goal: no goal with id {message_id!r} of this client is in progress"
            session.report("warning", text, message_id)
            return
        self._goals.cancel(goal)

    def _provided_goal(self, session: Session, message: Message) -> Goal:
        assert self._goals is not None
        goal = self._goals.provided(session, message.get("id"))
        if goal is None:
            raise ProtocolError(f"no goal with id {message.get('id')!r} is waiting for this client")
        return goal

    def _action_feedback(self, session: Session, message: Message) -> None:
        assert self._goals is not None
        self._goals.provider_feedback(self._provided_goal(session, message), message.get("values") or {})

    def _action_result(self, session: Session, message: Message) -> None:
        assert self._goals is not None
        goal = self._provided_goal(session, message)
        self._goals.provider_result(goal, message["result"], message["status"], message.get("values"))

    def _auth(self, session: Session, message: Message) -> None:
        given = message.get("mac") or message.get("token")
        given = given.strip() if isinstance(given, str) else given  # a token file read whole keeps its line end
        if self.token is None:
            raise ProtocolError("this server takes no token: it is read-only for every client", "auth")
        if not given or not hmac.compare_digest(str(given).encode("utf-8"), self.token.encode("utf-8")):
            session.authorised, session.token_refused = False, True
            raise ProtocolError("the token is not this server's update token", "auth")
        session.authorised, session.token_refused = True, False
        session.report("info", "authorised: this client may write", message.get("id"))

    def _fragment_size(self, session: Session, message: Message) -> int | None:
        """The ``fragment_size`` a subscribe or call asks for (None: whole messages), raised to the least
        the server sends (:data:`wire.MIN_FRAGMENT`, with a warning)."""
        size: int | None = message.get("fragment_size")
        if size is None:
            return None
        if size < 1:
            raise ProtocolError(f"fragment_size must be at least 1, not {size}")
        if size < wire.MIN_FRAGMENT:
            text = f"fragment_size {size} raised to {wire.MIN_FRAGMENT}"
            session.report("warning", text, message.get("id"))
        return max(size, wire.MIN_FRAGMENT)

    def _fragment(self, session: Session, message: Message) -> None:
        if session.reassembly is None:
            session.reassembly = wire.Reassembly(self.max_message_bytes)
        text, warning = session.reassembly.add(message)
        if warning is not None:
            session.report("warning", f"fragment: {warning}", message.get("id"))
        if text is not None:
            self._handle(session, text, whole=True)

    def _set_level(self, session: Session, message: Message) -> None:
        if message["level"] not in LEVELS:
            raise ProtocolError(f"level must be one of {', '.join(LEVELS)}, not {message['level']!r}")
        session.level = message["level"]

    def _fan_out(self, name: str, text: str, subscribers: list[Session] | None = None, values: Any = None) -> None:
        """Queue a message for every subscriber (those given, or the topic's now), under the name each
        one subscribed with: its JSON ``text``, or CBOR of its ``values`` (None: read back from the text)
        for those that asked for it."""
        if subscribers is None:
            with self._graph.lock:
                topic = self._graph.topics.get(name)
                subscribers = list(topic.subscribers) if topic is not None else []
        if len(subscribers) == 1 and name not in subscribers[0].cbor:  # the usual case: no table to keep
            session = subscribers[0]
            session.offer(name, protocol.publish_text(session.spelling.get(name, name), text))
            return
        framed: dict[str, str] = {}
        binary: dict[str, bytes] = {}  # for the subscribers that asked for CBOR
        for session in subscribers:
            spelling = session.spelling.get(name, name)
            if name in session.cbor:
                if spelling not in binary:
                    if values is None:
                        values = protocol.loads(text)
                    binary[spelling] = wire.cbor_publish(spelling, values)
                session.offer(name, binary[spelling])
                continue
            if spelling not in framed:
                framed[spelling] = protocol.publish_text(spelling, text)
            session.offer(name, framed[spelling])
