"""A knowledge base's quads put on an Oxigraph server in one request, for tests whose subject is not how they
got there: seeding a server through cbrs writes the seed, then works graph:entailed out with some 140
queries (about 3 s; the seed itself is checked in test_remote_servers.py and test_remote_store.py)."""

from __future__ import annotations

import functools

from cbrs.kb import KnowledgeBase
from tests.conftest import OxigraphServer


@functools.cache
def seeded_quads() -> bytes:
    """A new seeded store, as N-Quads (what a seed writes to a server is the same: test_remote_servers.py)."""
    kb = KnowledgeBase.open(":memory:")
    try:
        return kb.store.dump()
    finally:
        kb.close()


def put_quads(server: OxigraphServer, quads: bytes) -> None:
    """Add ``quads`` (N-Quads) to ``server`` in one request to its graph store endpoint."""
    answer = server.client.post(server.url + "/store", content=quads, headers={"Content-Type": "application/n-quads"})
    answer.raise_for_status()
