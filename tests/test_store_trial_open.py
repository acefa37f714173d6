"""Opening a seeded store asks for the map's version, not the list of graphs (on Virtuoso holding OWLS-TC
the list took 6.9 s of a 7.7 s open; docs/remote-store.md). A store whose map is gone gets it back on open
as before (tests/test_knowledge_driven.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import EmbeddedStore


def test_an_open_lists_no_graphs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    kb = KnowledgeBase.open(tmp_path / "store")
    map_quads = kb.store.count(GraphName.MAP)
    kb.close()
    listed: list[str] = []
    real = EmbeddedStore.graphs
    monkeypatch.setattr(EmbeddedStore, "graphs", lambda store: listed.append(store.location) or real(store))
    reopened = KnowledgeBase.open(tmp_path / "store")
    assert reopened.store.count(GraphName.MAP) == map_quads and listed == []
    reopened.close()
