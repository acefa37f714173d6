"""One connected client: what it advertises, provides and subscribes to, and its single writer.

Everything the client receives goes through one writer task, in the order it was produced, except that
a throttled topic waits for its window. Replies (statuses, service responses, forwarded calls) are never
dropped; topic messages wait in their :class:`TopicQueue`, so a client that reads slowly only ever has
its queues' worth of messages pending. The transport hands in ``send`` (await one frame: text for a
``str``, binary for ``bytes``, which only a topic message sent as CBOR is), optionally ``send_many``
(await several, in order: the writer hands it what is due at once), and ``abort`` (drop the
connection, with a reason); nothing here knows about websockets.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections import deque
from collections.abc import Awaitable, Callable
from contextvars import ContextVar
from dataclasses import dataclass

from cbrs.rosbridge.outbox import Request, TopicQueue
from cbrs.rosbridge.protocol import LEVELS, MessageId, status
from cbrs.rosbridge.wire import Reassembly, fragments, png_message

#: What the writer sends: a text frame, or a binary one (a topic message as CBOR).
Frame = str | bytes

log = logging.getLogger("cbrs.rosbridge")

#: Replies a client may leave unread before it is disconnected (it is not reading its socket).
REPLY_BACKLOG = 10_000
#: Bytes of replies a client may leave unread before it is disconnected.
REPLY_BYTES = 64 << 20
#: Bytes of topic messages, all its queues together, a client may leave unsent before it is disconnected:
#: each queue is bounded (``max_queue_bytes``), but a client may hold a thousand of them.
QUEUED_BYTES = 256 << 20
#: Messages the writer hands the transport at once when several are due (with ``send_many``), so the
#: transport can write a burst together instead of message by message. Bounded, so a burst held outside
#: the queues (where the queues' drop-oldest rule no longer reaches it) stays small.
WRITE_BATCH = 64
#: Characters of messages in one such burst (a burst always takes at least one message, whatever its size).
WRITE_BATCH_CHARS = 256 << 10


@dataclass(frozen=True)
class Caller:
    """Who made a service call, as a handler sees it through :func:`current_caller`."""

    peer: str  # the client's address (IP), which per-client limits count by
    origin: str | None  # the Origin header of its websocket handshake: a web page's, or None for a program
    authorised: bool  # it sent the server's token with the auth op
    session: str = ""  # the connection's name, unique in the server (what outlives a call: a registration)
    token_refused: bool = False  # its last auth op sent a token that is not the server's


_CALLER: ContextVar[Caller | None] = ContextVar("cbrs_rosbridge_caller", default=None)


#: what a write refused to a session whose token was refused says, rather than "send the token first"
TOKEN_REFUSED = (
    "the token this connection sent with the auth op is not this server's update token (its error status said"
    " so): send the token cbrs serve was started with (CBRS_UPDATE_TOKEN or its --update-token-file)"
)


def current_caller() -> Caller | None:
    """The client whose service call the running handler answers (None outside a bridge call)."""
    return _CALLER.get()


class Session:
    """A client of the bridge, confined to the bridge's event loop."""

    def __init__(
        self,
        name: str,
        send: Callable[[Frame], Awaitable[None]],
        abort: Callable[[str], None],
        backlog: int,
        clock: Callable[[], float] = time.monotonic,
        *,
        peer: str = "",
        origin: str | None = None,
        backlog_bytes: int = 16 << 20,
        send_many: Callable[[list[Frame]], Awaitable[None]] | None = None,
    ) -> None:
        self.name = name
        self.peer = peer
        self.origin = origin
        self.authorised = False
        self.token_refused = False  # its last auth op's token was not the server's: a refusal says so
        self.level = "error"
        self.closed = False
        #: topics this client advertised (global name -> the name as the client wrote it), likewise
        #: services and actions it provides, and the spelling it subscribed with (messages go out under that name)
        self.advertised: dict[str, str] = {}
        self.provided: dict[str, str] = {}
        self.provided_actions: dict[str, str] = {}
        self.spelling: dict[str, str] = {}
        self.queues: dict[str, TopicQueue] = {}
        #: the queues that may hold a message: the writer looks only at these, so a client subscribed to
        #: many quiet topics costs each message nothing more (a queue found empty leaves)
        self._waiting: dict[str, TopicQueue] = {}
        #: how a subscribed topic's messages go out when a subscription asked (cbrs.rosbridge.wire): per
        #: subscribe request (compression, fragment_size), and merged per topic as rosbridge merges them
        #: (CBOR if any asks, else PNG if any asks; the smallest fragment size); topics sent as plain JSON
        #: are not in ``wire``, and those sent as CBOR are in ``cbor`` too (the bridge encodes them)
        self._wire_requests: dict[str, dict[Request, tuple[str, int | None]]] = {}
        self.wire: dict[str, tuple[str, int | None]] = {}
        self.cbor: set[str] = set()
        self.reassembly: Reassembly | None = None  # the client's messages arriving in pieces, once it sends one
        self._pieces: deque[str] = deque()  # the rest of a topic message being sent in pieces
        self._piece_ids = 0
        self._send = send
        self._send_many = send_many
        self._abort = abort
        self._backlog = backlog
        self._backlog_bytes = backlog_bytes
        self._clock = clock
        self._replies: deque[tuple[int, str]] = deque()
        self._reply_bytes = 0
        self._topic_bytes = 0  # the sizes of every topic queue, together
        self._seq = 0
        self._waiter: asyncio.Future[None] | None = None  # the writer waiting for something to send

    def __repr__(self) -> str:
        return f"<Session {self.name}>"

    def identity(self) -> Caller:
        return Caller(self.peer, self.origin, self.authorised, self.name, self.token_refused)

    @property
    def pending_bytes(self) -> int:
        """Bytes of messages waiting to be sent to this client (replies and topic queues)."""
        return self._reply_bytes + self._topic_bytes

    # -- what the bridge calls -------------------------------------------------------------------

    def reply(self, text: str) -> None:
        """Queue a message that must arrive (a status, a service response, a forwarded call)."""
        if self.closed:
            return
        if len(self._replies) >= REPLY_BACKLOG or self._reply_bytes + len(text) > REPLY_BYTES:
            self.closed = True
            self._abort(f"{len(self._replies)} replies ({self._reply_bytes} bytes) unread")
            self.drop()
            return
        self._replies.append((self._next_seq(), text))
        self._reply_bytes += len(text)
        self._wake()

    def reply_in_pieces(self, text: str, size: int, message_id: MessageId) -> None:
        """Queue a reply as ``fragment`` ops of at most ``size`` characters (whole if it fits)."""
        for piece in fragments(text, size, message_id):
            self.reply(piece)

    def report(self, level: str, text: str, message_id: MessageId | None = None) -> None:
        """Send a ``status`` message if the client's level asks for it."""
        if LEVELS.index(level) <= LEVELS.index(self.level):
            self.reply(status(level, text, message_id))

    def subscribe(
        self,
        topic: str,
        spelling: str,
        request: Request,
        throttle_rate: int,
        queue_length: int,
        compression: str = "none",
        fragment_size: int | None = None,
    ) -> None:
        """Add (or replace) a subscribe request; ``compression`` is "none", "png" or "cbor"."""
        queue = self.queues.get(topic)
        if queue is None:
            queue = self.queues[topic] = TopicQueue(self._backlog, self._backlog_bytes)
        before = queue.size
        queue.add(request, throttle_rate, queue_length)  # a shorter queue may drop messages
        self._topic_bytes += queue.size - before
        self.spelling[topic] = spelling
        self._wire_requests.setdefault(topic, {})[request] = (compression, fragment_size)
        self._merge_wire(topic)

    def _merge_wire(self, topic: str) -> None:
        requests = self._wire_requests.get(topic, {}).values()
        asked = {compression for compression, _ in requests}
        compression = "cbor" if "cbor" in asked else "png" if "png" in asked else "none"
        sizes = [size for _, size in requests if size is not None]
        if compression != "none" or sizes:
            self.wire[topic] = (compression, min(sizes) if sizes else None)
        else:
            self.wire.pop(topic, None)
        if compression == "cbor":
            self.cbor.add(topic)
        else:
            self.cbor.discard(topic)

    def unsubscribe(self, topic: str, request: Request | None, every: bool) -> bool:
        """Drop one subscribe request (or ``every`` one); True if the client no longer subscribes."""
        queue = self.queues[topic]
        wire = self._wire_requests.get(topic, {})
        before = queue.size
        if every:
            queue.requests.clear()
            wire.clear()
        else:
            queue.remove(request)
            wire.pop(request, None)
        self._topic_bytes += queue.size - before
        self._merge_wire(topic)
        if queue.requests:
            return False
        self._topic_bytes -= queue.size
        del self.queues[topic]
        self._waiting.pop(topic, None)
        del self.spelling[topic]
        self._wire_requests.pop(topic, None)
        return True

    def offer(self, topic: str, text: Frame) -> None:
        """Queue a ``publish`` message of a subscribed topic (JSON text, or CBOR)."""
        queue = self.queues.get(topic)
        if queue is None or self.closed:
            return
        before, size = queue.dropped, queue.size
        self._seq += 1
        queue.push(self._seq, text)
        self._waiting[topic] = queue
        self._topic_bytes += queue.size - size
        if self._topic_bytes > QUEUED_BYTES:
            self.closed = True
            self._abort(f"{self._topic_bytes} bytes of topic messages unsent in {len(self._waiting)} queues")
            self.drop()
            return
        if queue.dropped != before and (queue.dropped & (queue.dropped - 1)) == 0:
            log.debug("%s: dropped %d messages of %s (queue of %d)", self.name, queue.dropped, topic, queue.capacity)
        self._wake()

    def close(self) -> None:
        self.closed = True
        self.drop()
        self._wake()

    def drop(self) -> None:
        """Forget every message waiting: a client that has gone holds no memory."""
        self._replies.clear()
        self._reply_bytes = 0
        self._pieces.clear()
        if self.reassembly is not None:
            self.reassembly.clear()
        for queue in self.queues.values():
            queue.clear()
        self._waiting.clear()
        self._topic_bytes = 0

    # -- the writer --------------------------------------------------------------------------------

    async def run(self) -> None:
        """Send queued messages until closed (or until the transport fails)."""
        try:
            while not self.closed:
                now = self._clock()
                text, wait = self._take(now)
                if text is not None:
                    await (self._send(text) if self._send_many is None else self._send_due(text, now))
                    continue
                # nothing to send now: sleep until woken, or until a throttled message is due
                self._waiter = waiter = asyncio.get_running_loop().create_future()
                try:
                    if wait is None:  # no timer to arm and cancel: the common case, woken per message
                        await waiter
                    else:
                        async with asyncio.timeout(wait):
                            await waiter
                except TimeoutError:
                    pass
                finally:
                    self._waiter = None
        except Exception as error:  # the connection went away under a send
            log.debug("%s: writer stopped: %r", self.name, error)
            self.closed = True

    async def _send_due(self, first: Frame, now: float) -> None:
        """Send ``first`` with the other messages due ``now`` (up to a batch) in one ``send_many`` call."""
        assert self._send_many is not None
        batch: list[Frame] = [first]
        size = len(first)
        while len(batch) < WRITE_BATCH and size < WRITE_BATCH_CHARS:
            text, _ = self._take(now)
            if text is None:
                break
            batch.append(text)
            size += len(text)
        await (self._send(first) if len(batch) == 1 else self._send_many(batch))

    def _take(self, now: float) -> tuple[Frame | None, float | None]:
        """The next message due (oldest first), else how long until one is due (None: nothing waits)."""
        if self._pieces:  # a topic message in pieces goes out whole before anything else
            return self._pieces.popleft(), None
        best: TopicQueue | None = None
        best_topic = ""
        best_seq = self._replies[0][0] if self._replies else None
        wait: float | None = None
        empty: list[str] = []
        for topic, queue in self._waiting.items():
            ready = queue.ready_at()
            if ready is None:
                empty.append(topic)
                continue
            if ready > now:
                wait = ready - now if wait is None else min(wait, ready - now)
            elif best_seq is None or queue.head() < best_seq:
                best, best_seq, best_topic = queue, queue.head(), topic
        for topic in empty:
            del self._waiting[topic]
        if best is not None:
            text = best.pop(now)
            self._topic_bytes -= len(text)
            return (self._encoded(best_topic, text) if self.wire else text), None
        if best_seq is not None:
            text = self._replies.popleft()[1]
            self._reply_bytes -= len(text)
            return text, None
        return None, wait

    def _encoded(self, topic: str, text: Frame) -> Frame:
        """A topic message as its subscription asked for it: PNG, in pieces, or as it is (CBOR, already
        encoded by the bridge, always goes whole: ``fragment`` ops carry text)."""
        wire = self.wire.get(topic)
        if wire is None or isinstance(text, bytes):
            return text
        compression, size = wire
        if compression == "png":
            text = png_message(text)
        if size is None:
            return text
        self._piece_ids += 1
        first, *rest = fragments(text, size, f"publish:{self.spelling.get(topic, topic)}:{self._piece_ids}")
        self._pieces.extend(rest)
        return first

    def _wake(self) -> None:
        """Wake the writer if it waits (a bare future: cheaper than an Event, woken once per message)."""
        waiter = self._waiter
        if waiter is not None and not waiter.done():
            waiter.set_result(None)

    def _next_seq(self) -> int:
        self._seq += 1
        return self._seq
