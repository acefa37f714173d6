"""A load writes only the triples the store does not hold. A load only adds, and the loader names every
node from its file's content (skolemisation), so the store ends as it would had every triple been
written again; a reload of what the store holds writes nothing, so the embedded store's generation
(what snapshots and cached descriptions are checked against) stays as it was. ``Store.contains`` is
the membership test the loader asks of each triple, on either store."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase, RdfParseError, Store
from cbrs.kb.store import EmbeddedStore

from .test_load_counts import NAVIGATE, ONTOLOGY, OVERLAP, THREE, _write, kb

__all__ = ["kb"]  # the fixture, used by name

pytestmark = pytest.mark.both_stores

EX = "http://example.org/counts#"
G1, G2 = ox.NamedNode("http://example.org/counts#g1"), ox.NamedNode("http://example.org/counts#g2")
# a blank node: skolemised under a name made from the file's content, the same at every load; and a
# decimal the store keeps in another form ("0.5"), held all the same
BLANK = """@prefix ex: <http://example.org/counts#> .
ex:a ex:q [ ex:r ex:s ; ex:t "one" ; ex:u 0.50 ] .
"""


@pytest.fixture
def embedded_kb() -> Iterator[KnowledgeBase]:
    """The write-counting tests watch the embedded store's writes; a remote store's load, which asks the
    server in batches what it lacks, is tested in tests/test_kb16_remote_load.py."""
    kb = KnowledgeBase(Store.open(":memory:"))
    assert isinstance(kb.store, EmbeddedStore)
    yield kb
    kb.close()


def _node(name: str) -> ox.NamedNode:
    return ox.NamedNode(EX + name)


def test_the_store_says_whether_it_holds_a_quad(kb: KnowledgeBase) -> None:
    held = ox.Quad(_node("a"), _node("p"), ox.Literal("x"), G1)
    kb.store.add([held])
    assert kb.store.contains(held)
    assert not kb.store.contains(ox.Quad(_node("a"), _node("p"), ox.Literal("x"), G2))  # another graph
    assert not kb.store.contains(ox.Quad(_node("a"), _node("p"), ox.Literal("y"), G1))
    assert not kb.store.contains(ox.Quad(_node("a"), _node("p"), ox.Literal("x", language="en"), G1))
    decimal = ox.NamedNode("http://www.w3.org/2001/XMLSchema#decimal")
    kb.store.add([ox.Quad(_node("a"), _node("q"), ox.Literal("0.50", datatype=decimal), G1)])  # kept as "0.5"
    assert kb.store.contains(ox.Quad(_node("a"), _node("q"), ox.Literal("0.50", datatype=decimal), G1))
    assert kb.store.contains(ox.Quad(_node("a"), _node("q"), ox.Literal("0.5", datatype=decimal), G1))


def test_a_reload_leaves_the_store_as_it_was(kb: KnowledgeBase, tmp_path: Path) -> None:
    files = [_write(tmp_path, "three.ttl", THREE), _write(tmp_path, "blank.ttl", BLANK)]
    kb.load(files)
    kb.load([NAVIGATE], catalogue=ONTOLOGY)  # OWL-S: converted, blank nodes, imports, graph:entailed
    before = kb.store.dump()
    again = kb.load([*files, NAVIGATE], catalogue=ONTOLOGY)
    assert again.added_quads == 0 and again.quads > 0
    assert kb.store.dump() == before


def _spy(store: Store, monkeypatch: pytest.MonkeyPatch) -> list[list[ox.Quad]]:
    """The quads each ``store.add`` call of the load is given."""
    calls: list[list[ox.Quad]] = []
    add = store.add

    def recorded(quads: Iterable[ox.Quad]) -> None:
        quads = list(quads)
        calls.append(quads)
        add(quads)

    monkeypatch.setattr(store, "add", recorded)
    return calls


def test_a_reload_writes_nothing_and_keeps_the_generation(
    embedded_kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kb = embedded_kb
    files = [_write(tmp_path, "three.ttl", THREE), _write(tmp_path, "blank.ttl", BLANK), NAVIGATE]
    kb.load(files, catalogue=ONTOLOGY)
    generation = kb.store.generation
    calls = _spy(kb.store, monkeypatch)
    kb.load(files, catalogue=ONTOLOGY)
    assert calls == []
    assert kb.store.generation == generation


def test_a_partly_held_file_writes_only_its_new_triple(
    embedded_kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kb = embedded_kb
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    calls = _spy(kb.store, monkeypatch)
    kb.load([_write(tmp_path, "overlap.ttl", OVERLAP)])
    services = ox.NamedNode("https://w3id.org/cbrs/graph/services")
    assert calls == [[ox.Quad(_node("g"), _node("p"), _node("h"), services)]]


def test_a_failed_load_of_partly_held_files_leaves_the_store_as_it_was(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    before = kb.store.dump()
    broken = _write(tmp_path, "z_broken.ttl", "@prefix ex: <http://example.org/counts#> .\nex:x ex:p .\n")
    with pytest.raises(RdfParseError, match=r"z_broken\.ttl"):
        kb.load([_write(tmp_path, "overlap.ttl", OVERLAP), broken])
    assert kb.store.dump() == before


def test_a_reload_that_adds_nothing_leaves_the_entailed_graph_alone(
    embedded_kb: KnowledgeBase, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kb = embedded_kb
    files = [_write(tmp_path, "three.ttl", THREE)]
    kb.load(files)
    refreshed: list[bool] = []
    monkeypatch.setattr(kb.standard_terms, "refresh", lambda: refreshed.append(True))
    kb.load(files)
    assert refreshed == []
    kb.load([_write(tmp_path, "overlap.ttl", OVERLAP)])  # one new triple: entailed again
    assert refreshed == [True]
