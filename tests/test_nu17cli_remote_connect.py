"""An https:// store URL at a server that never finishes the handshake (a plain-HTTP oxigraph serve) says
what it waited for and tries no second layout at the same address (new-user CLI repro 10: it waited twice
the connect timeout, then said it "did not answer within 60 s")."""

from __future__ import annotations

import socket
import threading
from collections.abc import Iterator

import pytest

from cbrs.kb.errors import StoreError
from cbrs.kb.remote_store import RemoteStore


@pytest.fixture
def silent() -> Iterator[tuple[int, list[socket.socket]]]:
    """A loopback port that accepts connections and never says a word."""
    listener = socket.create_server(("127.0.0.1", 0))
    accepted: list[socket.socket] = []
    stop = threading.Event()

    def accept() -> None:
        listener.settimeout(0.05)
        while not stop.is_set():
            try:
                accepted.append(listener.accept()[0])
            except TimeoutError:
                continue

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    yield listener.getsockname()[1], accepted
    stop.set()
    thread.join(timeout=5)
    for connection in accepted:
        connection.close()
    listener.close()


def test_a_handshake_that_never_comes_is_named_once(silent: tuple[int, list[socket.socket]]) -> None:
    port, accepted = silent
    with pytest.raises(StoreError) as caught:
        RemoteStore.open(f"https://127.0.0.1:{port}", timeout=0.3)
    message = str(caught.value)
    assert f"no connection to https://127.0.0.1:{port}/query within 0.3 s" in message
    assert "needs a server that speaks TLS" in message
    assert len(accepted) == 1  # not again at /sparql
