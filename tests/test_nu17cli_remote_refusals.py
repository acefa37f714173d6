"""What a remote write's refusal says (new-user CLI repro 09): Virtuoso's SPARQL user without the update
grant is named as such, and a refused first batch leaves no staging graph to speak of."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator

import pyoxigraph as ox
import pytest

from cbrs.kb.errors import RemoteStoreError, StoreError, StoreEvaluationError
from cbrs.kb.remote_store import Endpoints, RemoteStore
from cbrs.kb.staged_writes import write_staged

QUADS = [
    ox.Quad(
        ox.NamedNode(f"https://example.org/lab#t{i}"),
        ox.NamedNode("https://example.org/lab#i"),
        ox.Literal(str(i)),
        ox.NamedNode("https://w3id.org/cbrs/graph/services"),
    )
    for i in range(6)
]


def _sender(fail_at: int, error: Exception) -> tuple[list[str], object]:
    sent: list[str] = []

    def send(text: str) -> None:
        sent.append(text)
        if len(sent) == fail_at:
            raise error

    return sent, send


def test_a_refused_first_batch_drops_nothing_and_notes_nothing() -> None:
    refusal = RemoteStoreError("http://h:1", "http://h:1/update", 413, "too large")
    sent, send = _sender(1, refusal)
    with pytest.raises(RemoteStoreError) as caught:
        write_staged("http://h:1", QUADS, 2, send)  # type: ignore[arg-type]
    assert len(sent) == 1
    assert not getattr(caught.value, "__notes__", None)


def test_a_refused_later_batch_drops_what_the_earlier_ones_staged() -> None:
    refusal = StoreEvaluationError("http://h:1", "update", "refused", "http://h:1/update", 500)
    sent, send = _sender(2, refusal)
    with pytest.raises(StoreEvaluationError):
        write_staged("http://h:1", QUADS, 2, send)  # type: ignore[arg-type]
    assert len(sent) == 3 and sent[2].startswith("DROP SILENT GRAPH")


def test_a_batch_without_an_answer_may_have_landed_and_is_dropped() -> None:
    lost = StoreError("http://h:1", "request failed: Server disconnected")
    sent, send = _sender(1, lost)
    with pytest.raises(StoreError):
        write_staged("http://h:1", QUADS, 2, send)  # type: ignore[arg-type]
    assert len(sent) == 2 and sent[1].startswith("DROP SILENT GRAPH")


class _Virtuoso(http.server.BaseHTTPRequestHandler):
    """Answers every update as Virtuoso 7 does while its SPARQL user lacks the grant."""

    def do_POST(self) -> None:
        self.rfile.read(int(self.headers.get("Content-Length") or 0))
        body = b"Virtuoso 42000 Error SR186:SECURITY: No permission to execute procedure DB.DBA.SPARUL_DROP"
        self.send_response(500)
        self.send_header("Content-Type", "text/plain")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def version_string(self) -> str:
        return "Virtuoso/07.20.3229 (Linux) x86_64-pc-linux-gnu"

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def virtuoso_without_grant() -> Iterator[str]:
    server = http.server.HTTPServer(("127.0.0.1", 0), _Virtuoso)
    thread = threading.Thread(target=server.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_port}/sparql"
    server.shutdown()
    server.server_close()
    thread.join(timeout=5)


def test_virtuoso_without_the_update_grant_is_named(virtuoso_without_grant: str) -> None:
    url = virtuoso_without_grant
    store = RemoteStore(url, Endpoints(url, url))
    try:
        with pytest.raises(StoreEvaluationError) as caught:
            store.update("DROP SILENT GRAPH <https://example.org/g>")
    finally:
        store.close()
    assert str(caught.value).startswith(f"store {url}: update failed: Virtuoso's SPARQL user may not update")
    assert "grant SPARQL_UPDATE" in str(caught.value)
