"""A child program for tests/test_crash_safety.py: one write to an on-disk store, to be killed mid-way.

    python tests/helpers_crash.py load STORE FILE      # `cbrs --store STORE load FILE`, the CLI itself
    python tests/helpers_crash.py update STORE TEXT    # KnowledgeBase.update, as /update runs it
    python tests/helpers_crash.py serve STORE TOKEN    # cbrs's Server on free ports, with that update token

It prints one line per milestone, flushed, so the parent can time its SIGKILL: ``started`` before the
operation, ``writing`` just before the store's transaction is handed to Oxigraph (a wrapper around
``EmbeddedStore.add`` / ``update``), and ``done`` once the call returned. ``serve`` prints
``port N`` when it listens, and exits by itself after a minute, so a child the parent failed to kill
does not outlive the test run.
"""

from __future__ import annotations

import functools
import sys
import time
from collections.abc import Callable
from typing import Any

from cbrs.kb.store import EmbeddedStore

SERVE_LIFETIME = 60.0


def say(line: str) -> None:
    print(line, flush=True)


def announce_writes() -> None:
    """Print ``writing`` as each transaction starts, the last moment Python sees before Oxigraph runs it."""

    def marked(method: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(method)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            say("writing")
            result = method(*args, **kwargs)
            say("done")
            return result

        return wrapper

    EmbeddedStore.add = marked(EmbeddedStore.add)  # type: ignore[method-assign]
    EmbeddedStore.update = marked(EmbeddedStore.update)  # type: ignore[method-assign]


def load(store: str, file: str) -> None:
    from cbrs.cli import main

    sys.argv = ["cbrs", "--store", store, "load", "--graph", "services", file]
    say("started")
    main()


def update(store: str, text: str) -> None:
    from cbrs.kb import KnowledgeBase

    kb = KnowledgeBase.open(store, seed=False)
    say("started")
    kb.update(text)
    kb.close()


def serve(store: str, token: str) -> None:
    from cbrs.kb import KnowledgeBase
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig

    config = ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=token))
    server = Server(KnowledgeBase.open(store, seed=False), config)
    server.start()
    say(f"port {server.http_port}")
    time.sleep(SERVE_LIFETIME)
    server.stop()


if __name__ == "__main__":
    mode, location, argument = sys.argv[1:4]
    announce_writes()
    {"load": load, "update": update, "serve": serve}[mode](location, argument)
