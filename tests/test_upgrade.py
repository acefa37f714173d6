"""A store seeded with an older bundled ontology gets what the file says now when it is opened, and keeps
the lab's own statements (kb/upgrade.py, docs/ontologies.md#upgrading-a-store).

The old store is a fresh seed whose home.ttl statements are those of home.ttl 0.1.0 as commit ea502cf
had it (tests/data/legacy/home-0.1.0.ttl): before the area roles, the disjoint statuses, the hands'
geometry, and with the cup taken from the side only."""

from __future__ import annotations

import hashlib
import shutil
import tomllib
import urllib.parse
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import GraphName, KnowledgeBase, Store, knowledge_base
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import GENID, OWL, PREFIXES, RDFS
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.remote_store import RemoteStore
from cbrs.kb.resources import bundled_files, ontology_dir
from cbrs.kb.upgrade import StoreCheck, statement_keys
from cbrs.kb.vocab import CBRS

OLD_HOME = Path(__file__).parent / "data" / "legacy" / "home-0.1.0.ttl"
HOME = PREFIXES["home"]
LAB = "https://example.org/lab#"
ONTOLOGY = GraphName.ONTOLOGY.node
HOME_FILE = next(item.path for item in bundled_files() if item.path.name == "home.ttl")


def _q(subject: str, predicate: str, obj: ox.NamedNode | ox.Literal) -> ox.Quad:
    return ox.Quad(ox.NamedNode(subject), ox.NamedNode(predicate), obj, ONTOLOGY)


# the lab's own statements: its class marked to inform, and a comment on a bundled class
LAB_ADDED = [
    _q(LAB + "Reading", PREFIXES["rdf"] + "type", ox.NamedNode(OWL + "Class")),
    _q(LAB + "Reading", RDFS + "subClassOf", ox.NamedNode(HOME + "SpatialData")),
    _q(LAB + "Reading", CBRS.areaRole, ox.NamedNode(CBRS.InformsOfThing)),
    _q(HOME + "Cup", RDFS + "comment", ox.Literal("Our lab's cups are the blue ones.", language="en")),
]
# a bundled statement the lab deleted, which every home.ttl 0.1.0 said and 0.2.0 still says
LAB_DELETED = _q(HOME + "Cupboard", RDFS + "comment", ox.Literal("A cabinet with doors.", language="en"))


def _canonical(quads: Iterable[ox.Quad]) -> set[str]:
    """The quads with their skolem IRIs as blank nodes, canonicalised: equal whatever file digest named them."""

    def blank(term: ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple) -> ox.NamedNode | ox.BlankNode | ox.Literal:
        if isinstance(term, ox.NamedNode) and term.value.startswith(GENID):
            return ox.BlankNode(hashlib.sha256(term.value.encode()).hexdigest()[:24])
        assert not isinstance(term, ox.Triple)
        return term

    dataset = ox.Dataset(ox.Quad(blank(q.subject), q.predicate, blank(q.object)) for q in quads)
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    return {str(quad) for quad in dataset}


def _roles(kb: KnowledgeBase) -> dict[str, str]:
    return {row["class"].value: row["role"].value for row in kb.select("area_roles")}


@pytest.fixture(scope="module")
def fresh() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def old_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An embedded store seeded with home.ttl 0.1.0 and the lab's edits, closed: each test opens a copy."""
    folder = tmp_path_factory.mktemp("old") / "store"
    _seed_with_old_home(str(folder))
    return folder


@pytest.fixture
def old_copy(old_store: Path, tmp_path: Path) -> str:
    return str(shutil.copytree(old_store, tmp_path / "store"))


@pytest.fixture
def location(store_location: str, old_store: Path, tmp_path: Path) -> str:
    """The old store: a copy of it for the embedded store, built again on the cleared server for the remote."""
    if store_location == ":memory:":
        return str(shutil.copytree(old_store, tmp_path / "store"))
    _seed_with_old_home(store_location)
    return store_location


def _seed_with_old_home(location: str) -> None:
    """A current seed whose home.ttl statements are 0.1.0's, with the lab's edits."""
    KnowledgeBase.open(location).close()
    old = Store.open(location)
    assert LAB_DELETED in set(old.quads(graph=ONTOLOGY))  # (the lab deletes a statement the store holds)
    old.replace(parse_file(HOME_FILE, GraphName.ONTOLOGY).quads, parse_file(OLD_HOME, GraphName.ONTOLOGY).quads)
    assert not list(old.quads(None, ox.NamedNode(CBRS.areaRole), None, ONTOLOGY))  # 0.1.0 had no area roles
    old.replace([LAB_DELETED], LAB_ADDED)
    old.close()


@pytest.mark.both_stores
def test_a_store_seeded_with_an_older_home_gets_what_home_says_now(location: str, fresh: KnowledgeBase) -> None:
    kb = KnowledgeBase.open(location)
    # the area roles are there, the bundle's and the lab's, and composition's area rule reads them
    assert _roles(kb) == {**_roles(fresh), LAB + "Reading": CBRS.InformsOfThing}
    rule = Composer(kb).area_roles()
    assert not rule(HOME + "Temperature") and rule(HOME + "ObjectPosition3D") and not rule(LAB + "Reading")
    # a value the bundle changed is replaced, not doubled; the lab's edits stand
    drinkware = kb.store.quads(ox.NamedNode(HOME + "Drinkware"), ox.NamedNode(HOME + "graspApproach"), None, ONTOLOGY)
    assert [quad.object.value for quad in drinkware] == ["side top"]
    # the ontology graph is a fresh seed's, with the lab's statements and without the one it deleted
    expected = (set(fresh.store.quads(graph=ONTOLOGY)) | set(LAB_ADDED)) - {LAB_DELETED}
    assert _canonical(kb.store.quads(graph=ONTOLOGY)) == _canonical(expected)
    assert not kb.upgrade().changed
    kb.close()


def test_a_second_open_writes_nothing(old_copy: str) -> None:
    location = old_copy
    KnowledgeBase.open(location).close()
    before = Store.open(location)
    dump = before.dump()
    before.close()
    kb = KnowledgeBase.open(location)
    assert kb.store.generation == 0  # type: ignore[attr-defined]
    assert kb.store.dump() == dump
    kb.close()


def test_an_older_store_the_lab_loaded_home_ttl_into_again_is_merged_against_the_older(
    old_copy: str, fresh: KnowledgeBase, caplog: pytest.LogCaptureFixture
) -> None:
    """Loading the bundled home.ttl by hand into an older store leaves both versions' statements (a load
    only adds): the next open removes what the older said and the bundled one withdrew."""
    location = old_copy
    old = Store.open(location)
    old.add(parse_file(HOME_FILE, GraphName.ONTOLOGY).quads)
    old.close()
    kb = KnowledgeBase.open(location)
    drinkware = kb.store.quads(ox.NamedNode(HOME + "Drinkware"), ox.NamedNode(HOME + "graspApproach"), None, ONTOLOGY)
    assert [quad.object.value for quad in drinkware] == ["side top"]
    assert _roles(kb) == {**_roles(fresh), LAB + "Reading": CBRS.InformsOfThing}
    assert "not in history.toml" not in caplog.text
    kb.close()


def test_an_ontology_the_store_holds_at_a_newer_version_is_left_alone(old_copy: str) -> None:
    """A store a newer cbrs upgraded, opened by this one: its home stays as the newer cbrs left it (here
    without the area roles, which the older cbrs would add)."""
    location = old_copy
    store = Store.open(location)
    head, version = ox.NamedNode("https://w3id.org/cbrs/home"), ox.NamedNode(OWL + "versionInfo")
    store.replace(
        list(store.quads(head, version, None, ONTOLOGY)), [ox.Quad(head, version, ox.Literal("9.0.0"), ONTOLOGY)]
    )
    dump = store.dump()
    store.close()
    kb = KnowledgeBase.open(location)
    assert kb.store.dump() == dump
    kb.close()


def _history() -> list[dict[str, str]]:
    return list(tomllib.loads((ontology_dir() / "history.toml").read_text(encoding="utf-8"))["version"])


def _version_of(path: Path) -> str:
    (version,) = [t.object.value for t in ox.parse(path=str(path)) if t.predicate.value == OWL + "versionInfo"]
    return str(version)


def _bundled_version(name: str) -> tuple[int, ...]:
    path = next(item.path for item in bundled_files() if item.path.name == name)
    return tuple(int(part) for part in _version_of(path).split("."))


@pytest.mark.parametrize("entry", _history(), ids=lambda e: f"{e['file']}-{e['version']}")
def test_each_recorded_version_is_older_than_the_bundled_file(entry: dict[str, str]) -> None:
    """An upgrade to the bundled file merges against the version the store holds: it must be an older one,
    and its record must read."""
    assert tuple(int(part) for part in entry["version"].split(".")) < _bundled_version(entry["file"])
    for name in (entry["said"], entry.get("sometimes")):
        if name:
            assert statement_keys(parse_file(ontology_dir() / name, GraphName.ONTOLOGY).quads)


VERSIONS = Path(__file__).parent / "data" / "ontology_versions.toml"
# the files whose version says what they say: the ontology graph's and the map's, which a store upgrade
# merges, and the shapes, which no store holds (the version tells a reader which shapes checked a file)
VERSIONED_FILES = [item.path for item in bundled_files() if item.graph in (GraphName.ONTOLOGY, GraphName.MAP)]
VERSIONED_FILES.append(ontology_dir() / "shapes.ttl")
# the files whose older versions need no record in history.toml: core.ttl's terms are replaced, not
# merged, and the shapes are not stored
UNRECORDED = {"core.ttl", "shapes.ttl"}


def _statements_digest(path: Path) -> str:
    """A digest of what a file says (not how it is written: comments, order, blank node labels)."""
    dataset = ox.Dataset(ox.Quad(t.subject, t.predicate, t.object) for t in ox.parse(path=str(path)))
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    return hashlib.sha256("".join(sorted(f"{quad} .\n" for quad in dataset)).encode()).hexdigest()[:16]


@pytest.mark.parametrize("path", VERSIONED_FILES, ids=lambda p: str(p.relative_to(ontology_dir())))
def test_a_bundled_ontology_changes_only_with_a_new_version(path: Path) -> None:
    """A store is upgraded only when a file's version rises (docs/ontologies.md#upgrading-a-store): a
    changed file under its old version would never reach the stores seeded with that version."""
    name = str(path.relative_to(ontology_dir()))
    record = tomllib.loads(VERSIONS.read_text(encoding="utf-8"))["file"].get(name)
    version = _version_of(path)
    digest = _statements_digest(path)
    fix = f'record it in {VERSIONS.name}: "{name}" = {{ version = "{version}", statements = "{digest}" }}'
    assert record is not None, f"{name} is not in {VERSIONS.name}: {fix}"
    if record["version"] == version:
        assert record["statements"] == digest, (
            f"{name} says something else than version {version} did: raise its owl:versionInfo and record the "
            f"old file in ontologies/history.toml (docs/ontologies.md, Changing a bundled ontology), then {fix}"
        )
    else:
        recorded = {(entry["file"], entry["version"]) for entry in _history()}
        assert path.name in UNRECORDED or (path.name, record["version"]) in recorded, (
            f"{name} rose from {record['version']} to {version}: list the file as {record['version']} had it in "
            "ontologies/history.toml, the base of the stores seeded with it"
        )
        pytest.fail(f"{name} is at a new version: {fix}")


@pytest.mark.both_stores
def test_a_bundled_ontology_whose_header_is_gone_is_added_back_and_a_newer_one_left_alone(
    fresh_bundled_kb: KnowledgeBase,
) -> None:
    """The check's two findings, on either store (a remote one is asked them in one request): an
    ontology its graph does not declare comes back whole, one at a newer version stays as it is."""
    kb = fresh_bundled_kb
    sosa, home = ox.NamedNode("https://w3id.org/cbrs/standards/sosa"), ox.NamedNode(HOME.rstrip("#"))
    header = list(kb.store.quads(sosa, None, None, ONTOLOGY))
    assert header
    version = ox.NamedNode(OWL + "versionInfo")
    newer = ox.Quad(home, version, ox.Literal("9.0.0"), ONTOLOGY)
    kb.store.replace([*header, *kb.store.quads(home, version, None, ONTOLOGY)], [newer])
    report = kb.upgrade()
    assert report.added >= len(header) and not report.merged
    assert set(kb.store.quads(sosa, None, None, ONTOLOGY)) == set(header)
    assert list(kb.store.quads(home, version, None, ONTOLOGY)) == [newer]
    assert not kb.upgrade().changed


def test_opening_an_up_to_date_remote_store_sends_its_checks_in_one_request(remote_location: str) -> None:
    """Every open asks a remote store once, besides the union check of connecting: seeded or not, the
    upgrade check, the map, graph:entailed (they were 4 requests, and the upgrade check 19 before that:
    docs/remote-store.md, "Requests of a plan and a run")."""
    KnowledgeBase.open(remote_location).close()  # seeded
    sent: list[tuple[str, bool]] = []
    checking = [False]
    post, check = RemoteStore._post, knowledge_base.check_store

    def counted(self: RemoteStore, url: str, body: str, content_type: str, *args: Any, **kw: Any) -> Any:
        sent.append((urllib.parse.unquote_plus(body), checking[0]))
        return post(self, url, body, content_type, *args, **kw)

    def checked(store: Store, queries: QueryLibrary) -> StoreCheck:
        checking[0] = True
        try:
            return check(store, queries)
        finally:
            checking[0] = False

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(RemoteStore, "_post", counted)
        patch.setattr(knowledge_base, "check_store", checked)
        KnowledgeBase.open(remote_location).close()
    by_check = [body for body, during in sent if during]
    assert len(by_check) == 1
    assert all(text in by_check[0] for text in ("cbrs__part", "owl:versionInfo", GraphName.ENTAILED.iri))
    others = [body for body, during in sent if not during]
    assert len(others) == 1 and "?seen" in others[0], [body[:200] for body in others]  # the union check
