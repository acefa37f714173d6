"""The semantic map is upgraded as the ontologies are (kb/upgrade.py, docs/ontologies.md#upgrading-a-store):
a three-way merge of the stored map and the bundled world.ttl against what the stored version said
(ontologies/history/world-*.ttl). What the bundle added comes in and what it withdrew goes; a thing the
lab moved stays moved, a bundled statement the lab deleted stays deleted, the lab's own statements stay.

The old store is a fresh seed whose map is world.ttl 0.1.0 as commit a568d7c had it
(tests/data/legacy/world-0.1.0.ttl): before the walls, the dispenser's spout, the cameras' poses, the
hands and the colour of water."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import GraphName, KnowledgeBase, Store, upgrade
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import OWL, PREFIXES, RDFS
from cbrs.kb.resources import bundled_files, ontology_dir
from cbrs.kb.semantic_map import SemanticMap

OLD_MAP = Path(__file__).parent / "data" / "legacy" / "world-0.1.0.ttl"
MAP = GraphName.MAP.node
WORLD, HOME = PREFIXES["world"], PREFIXES["home"]
DECIMAL = ox.NamedNode(PREFIXES["xsd"] + "decimal")
HEAD, VERSION = ox.NamedNode(WORLD.rstrip("#")), ox.NamedNode(OWL + "versionInfo")
MAP_FILE = next(item.path for item in bundled_files() if item.graph is GraphName.MAP)
CUP, X = ox.NamedNode(WORLD + "Cup"), ox.NamedNode(HOME + "x")


def _x(value: str) -> ox.Quad:
    return ox.Quad(CUP, X, ox.Literal(value, datatype=DECIMAL), MAP)


BUNDLED_X, MOVED = _x("7.45"), _x("7.6")  # the lab moved the cup (to a value that sorts after the bundle's)
LAB_ADDED = ox.Quad(CUP, ox.NamedNode(RDFS + "comment"), ox.Literal("Ours has a chipped rim.", language="en"), MAP)
# a bundled statement the lab deleted, which world.ttl 0.1.0 said and says still
LAB_DELETED = ox.Quad(
    ox.NamedNode(WORLD + "Tap01"),
    ox.NamedNode(RDFS + "comment"),
    ox.Literal("Pushing the lever towards the dispenser opens the tap.", language="en"),
    MAP,
)


@pytest.fixture(scope="module")
def fresh() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


def _edit_map(location: str, remove: list[ox.Quad], add: list[ox.Quad]) -> None:
    store = Store.open(location)
    store.replace(remove, add)
    store.close()


def _set_version(location: str, version: str) -> None:
    store = Store.open(location)
    store.replace(list(store.quads(HEAD, VERSION, None, MAP)), [ox.Quad(HEAD, VERSION, ox.Literal(version), MAP)])
    store.close()


def _seed_with_old_map(location: str) -> None:
    """A current seed whose map is world.ttl 0.1.0, with the lab's edits."""
    KnowledgeBase.open(location).close()
    store = Store.open(location)
    assert LAB_DELETED in set(store.quads(graph=MAP))  # (the lab deletes a statement the store holds)
    store.replace(list(store.quads(graph=MAP)), parse_file(OLD_MAP, GraphName.MAP).quads)
    assert not list(store.quads(None, None, ox.NamedNode(HOME + "Wall"), MAP))  # 0.1.0 had no walls
    store.replace([BUNDLED_X, LAB_DELETED], [MOVED, LAB_ADDED])
    store.close()


@pytest.fixture(scope="module")
def old_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An embedded store with map 0.1.0 and the lab's edits, closed: each test opens a copy."""
    folder = tmp_path_factory.mktemp("old-map") / "store"
    _seed_with_old_map(str(folder))
    return folder


@pytest.fixture
def location(store_location: str, old_store: Path, tmp_path: Path) -> str:
    if store_location == ":memory:":
        return str(shutil.copytree(old_store, tmp_path / "store"))
    _seed_with_old_map(store_location)
    return store_location


@pytest.fixture(scope="module")
def seeded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("seeded") / "store"
    KnowledgeBase.open(str(folder)).close()
    return folder


@pytest.fixture
def current(seeded: Path, tmp_path: Path) -> str:
    """A current embedded store, closed (a copy of one seeded once)."""
    return str(shutil.copytree(seeded, tmp_path / "current"))


@pytest.mark.both_stores
def test_a_store_with_the_first_map_gets_what_the_map_says_now_and_keeps_the_labs_edits(
    location: str, fresh: KnowledgeBase
) -> None:
    kb = KnowledgeBase.open(location)
    expected = (set(fresh.store.quads(graph=MAP)) - {BUNDLED_X, LAB_DELETED}) | {MOVED, LAB_ADDED}
    assert set(kb.store.quads(graph=MAP)) == expected
    home = SemanticMap.read(kb)
    assert home.objects[WORLD + "Cup"].start.x == pytest.approx(7.6)
    assert not kb.upgrade().changed
    kb.close()


def test_a_bundled_map_statement_the_lab_deleted_stays_deleted(current: str) -> None:
    """The rule before the merge brought it back: the stored map gave the lever no comment any more."""
    _edit_map(current, [LAB_DELETED], [])
    _set_version(current, "0.2.0")
    kb = KnowledgeBase.open(current)
    assert LAB_DELETED not in set(kb.store.quads(graph=MAP))
    assert [quad.object.value for quad in kb.store.quads(HEAD, VERSION, None, MAP)] == [_version_of(MAP_FILE)]
    kb.close()


def _version_of(path: Path) -> str:
    return next(str(t.object.value) for t in ox.parse(path=str(path)) if t.predicate == VERSION)


@pytest.mark.parametrize(
    ("held", "after"),
    [pytest.param("7.3", "7.45", id="where-the-bundle-had-it"), pytest.param("7.6", "7.6", id="moved-by-the-lab")],
)
def test_a_value_the_bundle_changed_is_replaced_unless_the_lab_had_changed_it(
    current: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, held: str, after: str
) -> None:
    """As if map 0.2.0 had put the cup at x 7.3 and withdrawn a comment on it: a store holding 0.2.0's
    cup gets the bundle's, one where the lab moved it keeps the lab's (one position), and the withdrawn
    comment goes from both."""
    withdrawn = ox.Quad(CUP, ox.NamedNode(RDFS + "comment"), ox.Literal("Once the bundle said so.", language="en"), MAP)
    said = tmp_path / "world-0.2.0.ttl"
    text = (ontology_dir() / "history" / "world-0.2.0.ttl").read_text(encoding="utf-8")
    said.write_text(
        text.replace("home:x 7.45", "home:x 7.3") + f"\n{CUP} {withdrawn.predicate} {withdrawn.object} .\n",
        encoding="utf-8",
    )
    assert "home:x 7.3" in said.read_text(encoding="utf-8")
    monkeypatch.setattr(upgrade, "_history", lambda: {("world.ttl", "0.2.0"): (said, None)})
    _edit_map(current, [BUNDLED_X], [_x(held), withdrawn])
    _set_version(current, "0.2.0")
    kb = KnowledgeBase.open(current)
    assert [quad.object.value for quad in kb.store.quads(CUP, X, None, MAP)] == [after]
    assert withdrawn not in set(kb.store.quads(graph=MAP))
    kb.close()


def test_a_map_the_store_holds_at_a_newer_version_is_left_alone(current: str) -> None:
    _edit_map(current, [LAB_DELETED], [])
    _set_version(current, "9.0.0")
    store = Store.open(current)
    dump = store.dump()
    store.close()
    kb = KnowledgeBase.open(current)
    assert kb.store.dump() == dump
    kb.close()
