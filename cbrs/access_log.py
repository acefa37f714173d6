"""The access log of ``cbrs serve``: one line a request, written beside the event loop, in batches.

Granian's own access log (``log_access``) built each line on the event loop that answers the requests:
a dictionary, the request's time formatted by ``strftime`` (which cbrs's format does not show), a
record through ``Logger.info`` and a write and a flush of the log's stream, all holding the GIL. A
profile of ``cbrs serve`` answering point lookups from 4 clients put 16 % of that thread's samples
there (docs/serving.md, "The access log"). Here the loop only notes the request (a tuple on a deque);
a thread of its own turns the notes into records of the ``granian.access`` logger, with the time the
request was answered as the record's time. A line is written at once when the log was idle, so a lone
request is in the log as soon as it is answered; the lines of a busy moment wait at most
:attr:`AccessLog.interval` and go out together, each its own record as before.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Awaitable, Callable
from typing import Any

log = logging.getLogger("cbrs.server")

ACCESS_LOGGER = "granian.access"
ACCESS_FORMAT = '%s "%s %s" %d %.1f ms'
"""One line a request: the client's address, the method and path, the status and the time taken. No query
string (a query's text, up to 1 MiB) and no header: the update token travels in ``Authorization`` and is
never written (docs/serving.md, "Logs")."""

App = Callable[[dict[str, Any], Any, Any], Awaitable[None]]
Line = tuple[str, str, str, int, float, float]  # address, method, path, status, milliseconds, when (epoch s)


class AccessLog:
    """Lines noted on the event loop (:meth:`wrap`), written to :attr:`logger` by a thread (:meth:`start`)."""

    def __init__(
        self,
        logger: logging.Logger | None = None,
        interval: float = 0.1,
        most: int = 100_000,
        batched: frozenset[str] = frozenset({"/sparql"}),
    ) -> None:
        self.logger = logger or logging.getLogger(ACCESS_LOGGER)
        self.batched = batched  # the paths whose lines the writer thread writes; others' are written at once
        self.interval = interval  # how long a busy moment's lines wait to be written together
        self.most = most  # lines waiting at most (a log stream that blocks must not grow the server's memory)
        self.dropped = 0  # lines not kept since the start
        self._reported = 0
        self._lines: deque[Line] = deque()
        self._wake = threading.Event()
        self._idle = True  # the writer waits for _wake; the first line noted sets it
        self._closed = False
        self._thread: threading.Thread | None = None

    def wrap(self, app: App) -> App:
        """``app`` with a line noted for each HTTP request it answers. The status is the one Granian
        sent (its protocol's ``sent_response_code``: 500 when the app sent none), as Granian's log had it."""
        note, batched = self.note, self.batched
        clock = time.perf_counter

        async def logged(scope: dict[str, Any], receive: Any, send: Any) -> None:
            if scope["type"] != "http":
                await app(scope, receive, send)
                return
            started = clock()
            sent = None if hasattr(getattr(send, "__self__", None), "sent_response_code") else _Sent(send)
            try:
                await app(scope, receive, send if sent is None else sent)
            finally:
                status = send.__self__.sent_response_code if sent is None else sent.status
                client, path = scope.get("client"), scope.get("path", "")
                note(client[0] if client else "-", scope.get("method", "-"), path, status, (clock() - started) * 1000)
                if path not in batched:  # a page, a write: its line now, after those noted before it
                    self.write()

        return logged

    def note(self, address: str, method: str, path: str, status: int, milliseconds: float) -> None:
        """Keep a request's line for the writer; on the event loop's thread."""
        if len(self._lines) >= self.most:
            self.dropped += 1  # only this thread counts; the writer reports what it has not reported yet
            return
        self._lines.append((address, method, path, status, milliseconds, time.time()))
        if self._idle:
            self._idle = False
            self._wake.set()

    def start(self) -> None:
        """Start the writer thread."""
        self._thread = threading.Thread(target=self._run, name="cbrs-access-log", daemon=True)
        self._thread.start()

    def close(self, timeout: float = 5.0) -> None:
        """Write what is noted and stop the writer."""
        self._closed = True
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None
        self.write()

    def _run(self) -> None:
        while not self._closed:
            self._wake.wait()
            self._wake.clear()
            while not self._closed:
                self.write()
                time.sleep(self.interval)
                if not self._lines:
                    self._idle = True
                    if not self._lines:  # a line noted after the test above found _idle False: look again
                        break
                    self._idle = False

    def write(self) -> None:
        """Write the lines noted so far, each as a record of its own."""
        logger = self.logger
        lines = self._lines
        while lines:
            try:
                address, method, path, status, milliseconds, when = lines.popleft()
            except IndexError:
                break
            if not logger.isEnabledFor(logging.INFO):
                continue
            record = logger.makeRecord(
                logger.name,
                logging.INFO,
                __file__,
                0,
                ACCESS_FORMAT,
                (address, method, path, status, milliseconds),
                None,
            )
            late = record.created - when
            record.created, record.msecs = when, int((when - int(when)) * 1000) + 0.0
            record.relativeCreated -= late * 1000
            try:
                logger.handle(record)
            except Exception:  # a handler that raises (its own handleError did not catch it) loses its line only
                continue
        dropped = self.dropped
        if dropped > self._reported:
            log.warning("%d lines of the access log were dropped: the log did not keep up", dropped - self._reported)
            self._reported = dropped


class _Sent:
    """A ``send`` that remembers the status it sent, for a server whose ``send`` does not say it."""

    def __init__(self, send: Callable[[dict[str, Any]], Awaitable[None]]) -> None:
        self.send = send
        self.status = 500

    def __call__(self, message: dict[str, Any]) -> Awaitable[None]:
        if message.get("type") == "http.response.start":
            self.status = int(message["status"])
        return self.send(message)
