from __future__ import annotations

from pathlib import Path

import pytest

from kb import KnowledgeBase, Store
from kb.resources import ontology_dir

DATA = Path(__file__).parent / "data"
MINI_FILES = [DATA / "mini_ontology.ttl", DATA / "mini_services.ttl", DATA / "mini_requirements.ttl"]


def make_mini_kb() -> KnowledgeBase:
    """The core ontology plus the mini test data, in memory (not the bundled home data)."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    kb.load(MINI_FILES)
    return kb


@pytest.fixture
def mini_kb() -> KnowledgeBase:
    return make_mini_kb()


@pytest.fixture(scope="session")
def bundled_kb() -> KnowledgeBase:
    """A seeded in-memory knowledge base, shared: tests that use it must not write to it."""
    return KnowledgeBase.open(":memory:")


@pytest.fixture
def fresh_bundled_kb() -> KnowledgeBase:
    return KnowledgeBase.open(":memory:")
