"""cbrs.access_log: a line a request, noted on the loop, written by a thread (queries) or at once (others)."""

from __future__ import annotations

import asyncio
import http.client
import logging
import time
from typing import Any

import pytest

from cbrs.access_log import ACCESS_LOGGER, AccessLog
from cbrs.http_listener import HttpListener, ListenerConfig


async def _app(scope: dict[str, Any], receive: Any, send: Any) -> None:
    status = 404 if scope["path"] == "/missing" else 200
    await send({"type": "http.response.start", "status": status, "headers": []})
    await send({"type": "http.response.body", "body": b"ok"})


async def _send(message: dict[str, Any]) -> None:
    return None


def _request(app: Any, path: str, client: str = "10.0.0.7", method: str = "GET") -> None:
    scope = {"type": "http", "path": path, "method": method, "client": (client, 5555)}
    asyncio.run(app(scope, None, _send))


def _lines(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [record.getMessage() for record in caplog.records if record.name == ACCESS_LOGGER]


def _wait_for(caplog: pytest.LogCaptureFixture, count: int, seconds: float = 5.0) -> list[str]:
    deadline = time.monotonic() + seconds
    while len(_lines(caplog)) < count and time.monotonic() < deadline:
        time.sleep(0.01)
    return _lines(caplog)


def test_query_lines_are_written_by_the_thread_with_the_time_they_were_answered(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger=ACCESS_LOGGER)
    access = AccessLog(interval=0.3)
    app = access.wrap(_app)
    access.start()
    try:
        before = time.time()
        for _ in range(3):
            _request(app, "/sparql")
        answered = time.time()
        lines = _wait_for(caplog, 3)
    finally:
        access.close()
    assert len(lines) == 3, lines
    assert all(line.startswith('10.0.0.7 "GET /sparql" 200 ') and line.endswith(" ms") for line in lines), lines
    records = [record for record in caplog.records if record.name == ACCESS_LOGGER]
    assert all(before <= record.created <= answered for record in records)  # not when the thread wrote them


def test_other_requests_are_written_at_once_after_the_lines_before_them(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger=ACCESS_LOGGER)
    access = AccessLog(interval=60.0)  # the thread is never started: only the loop's own writes show
    app = access.wrap(_app)
    _request(app, "/sparql")
    assert _lines(caplog) == []
    _request(app, "/missing", method="POST")
    lines = _lines(caplog)
    assert [line.rsplit(" ", 2)[0] for line in lines] == ['10.0.0.7 "GET /sparql" 200', '10.0.0.7 "POST /missing" 404']


def test_close_writes_what_is_left_and_a_full_queue_says_how_many_it_dropped(
    caplog: pytest.LogCaptureFixture,
) -> None:
    caplog.set_level(logging.INFO, logger=ACCESS_LOGGER)
    access = AccessLog(most=2)
    app = access.wrap(_app)
    for _ in range(5):
        _request(app, "/sparql")
    access.close()
    assert len(_lines(caplog)) == 2
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert warnings == ["3 lines of the access log were dropped: the log did not keep up"]


def test_a_served_request_is_logged_with_the_status_granian_sent(caplog: pytest.LogCaptureFixture) -> None:
    caplog.set_level(logging.INFO, logger=ACCESS_LOGGER)
    listener = HttpListener(_app, ListenerConfig(port=0))
    listener.start()
    try:
        for path in ("/missing", "/sparql"):
            connection = http.client.HTTPConnection("127.0.0.1", listener.port, timeout=10)
            connection.request("GET", f"{path}?query=secret")
            assert connection.getresponse().read() == b"ok"
            connection.close()
        lines = _wait_for(caplog, 2)
    finally:
        listener.stop()
    assert [line.rsplit(" ", 2)[0] for line in lines] == ['127.0.0.1 "GET /missing" 404', '127.0.0.1 "GET /sparql" 200']
    assert "secret" not in caplog.text  # no query string
