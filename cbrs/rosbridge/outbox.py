"""What one client receives from one topic, and when: rosbridge's throttle and queue semantics.

A client may subscribe to a topic several times (with different ids); as in rosbridge, the requests are
merged: the smallest ``throttle_rate`` and the largest ``queue_length`` apply.

- ``throttle_rate`` 0, ``queue_length`` 0: pass-through, every message in order, as fast as the client
  reads. A client that falls more than ``backlog`` messages behind loses the oldest.
- ``throttle_rate`` T > 0, ``queue_length`` 0: at most one message per T ms; within a window only the
  latest message is kept, and it is sent when the window ends (so the last state is never lost).
- ``queue_length`` N > 0: a queue of N messages, drained from its head at most one per T ms (as fast as
  the client reads when T is 0); when full, the oldest message is dropped for the newest.

Whatever the lengths, the messages waiting in one queue hold at most ``max_bytes`` (16 MiB by default):
past that the oldest are dropped too, always keeping the newest.

This module is pure bookkeeping on a clock the caller passes in, so tests can step time by hand.
"""

from __future__ import annotations

import math
from collections import deque

from cbrs.rosbridge.protocol import MessageId

Request = MessageId | None


class TopicQueue:
    """The merged subscription of one client to one topic, with its pending messages."""

    def __init__(self, backlog: int, max_bytes: int = 16 << 20) -> None:
        self.backlog = backlog
        self.max_bytes = max_bytes
        self.size = 0  # bytes of the messages waiting (characters of JSON text, bytes of CBOR)
        self.requests: dict[Request, tuple[int, int]] = {}
        self.throttle = 0.0
        self.dropped = 0
        self._last_sent = -math.inf
        self._pending: deque[tuple[int, str | bytes]] = deque(maxlen=backlog)

    def add(self, request: Request, throttle_rate: int, queue_length: int) -> None:
        """Add (or replace) the subscribe request ``request`` (its id; None for one without id)."""
        self.requests[request] = (throttle_rate, queue_length)
        self._merge()

    def remove(self, request: Request) -> bool:
        """Remove one subscribe request; False if there was none with that id."""
        if request not in self.requests:
            return False
        del self.requests[request]
        if self.requests:
            self._merge()
        return True

    @property
    def capacity(self) -> int:
        """How many messages are kept waiting at most."""
        return self._pending.maxlen or self.backlog

    def push(self, seq: int, text: str | bytes) -> None:
        """Queue a message, JSON text or CBOR (``seq`` orders it among everything else the client receives)."""
        if len(self._pending) == self._pending.maxlen:
            self.dropped += 1
            self.size -= len(self._pending[0][1])
        self._pending.append((seq, text))
        self.size += len(text)
        while self.size > self.max_bytes and len(self._pending) > 1:
            self.size -= len(self._pending.popleft()[1])
            self.dropped += 1

    def clear(self) -> None:
        self._pending.clear()
        self.size = 0

    def ready_at(self) -> float | None:
        """When the next message may be sent (clock seconds), or None if nothing is waiting."""
        if not self._pending:
            return None
        return self._last_sent + self.throttle

    def head(self) -> int:
        """The sequence number of the next message."""
        return self._pending[0][0]

    def pop(self, now: float) -> str | bytes:
        """Take the next message, sent at ``now``."""
        self._last_sent = now
        text = self._pending.popleft()[1]
        self.size -= len(text)
        return text

    def __len__(self) -> int:
        return len(self._pending)

    def _merge(self) -> None:
        throttle_rate = min(rate for rate, _ in self.requests.values())
        queue_length = max(length for _, length in self.requests.values())
        self.throttle = throttle_rate / 1000.0
        if queue_length == 0:  # pass-through, or keep the latest within a throttle window
            queue_length = 1 if throttle_rate > 0 else self.backlog
        capacity = min(queue_length, self.backlog)
        if capacity != self._pending.maxlen:
            self._pending = deque(self._pending, maxlen=capacity)
            self.size = sum(len(text) for _, text in self._pending)
