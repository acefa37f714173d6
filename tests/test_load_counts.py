"""A load says what it added, apart from what the files gave: a reload gives the same triples again and
adds none of them, and a user reads the counts `cbrs load` prints as what changed."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase, Store
from cbrs.kb import loader as loader_module

pytestmark = pytest.mark.both_stores

DATA = Path(__file__).parent / "data"
OWLS = DATA / "owls"
ONTOLOGY = OWLS / "ontology"
NAVIGATE = OWLS / "services" / "navigate.owls"
OPEN_DOOR = OWLS / "services" / "open_door.owls"
SERVICES = GraphName.SERVICES.iri

THREE = """@prefix ex: <http://example.org/counts#> .
ex:a ex:p ex:b . ex:c ex:p ex:d . ex:e ex:p ex:f .
"""
# two of THREE's triples and one of its own
OVERLAP = """@prefix ex: <http://example.org/counts#> .
ex:a ex:p ex:b . ex:c ex:p ex:d . ex:g ex:p ex:h .
"""
TRIG = """@prefix ex: <http://example.org/counts#> .
ex:a ex:p ex:b .
ex:g1 { ex:c ex:p ex:d . ex:e ex:p ex:f . }
"""


@pytest.fixture
def kb(store_location: str) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase(Store.open(store_location))
    yield kb
    kb.close()


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_first_load_adds_everything_and_a_reload_nothing(kb: KnowledgeBase, tmp_path: Path) -> None:
    path = _write(tmp_path, "three.ttl", THREE)
    first = kb.load([path])
    assert (first.quads, first.added, first.already_present) == (3, {SERVICES: 3}, 0)
    again = kb.load([path])
    assert again.quads == 3  # what the file gave, as before: the existing figure is kept
    assert (again.added_quads, again.already_present) == (0, 3)
    assert all(n == 0 for n in again.added.values())
    if again.files[0].added is not None:  # counted per file (embedded store)
        assert again.files[0].added_triples == 0 and first.files[0].added_triples == 3


def test_a_partly_overlapping_file_counts_only_its_new_triple(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([_write(tmp_path, "three.ttl", THREE)])
    before = kb.store.count()
    report = kb.load([_write(tmp_path, "overlap.ttl", OVERLAP)])
    assert kb.store.count() - before == 1
    assert (report.quads, report.added_quads, report.already_present) == (3, 1, 2)
    assert report.added == {SERVICES: 1}
    if report.files[0].added is not None:
        assert report.files[0].added == {SERVICES: 1}


def test_a_triple_two_files_of_one_load_give_counts_for_the_first(kb: KnowledgeBase, tmp_path: Path) -> None:
    first, second = _write(tmp_path, "a_three.ttl", THREE), _write(tmp_path, "b_overlap.ttl", OVERLAP)
    report = kb.load([first, second])
    assert (report.quads, report.added_quads, report.already_present) == (6, 4, 2)
    if report.files[0].added is not None:
        assert [item.added_triples for item in report.files] == [3, 1]


def test_each_graph_of_a_trig_file_is_counted(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([_write(tmp_path, "three.ttl", THREE)])  # ex:a ex:p ex:b is in the services graph already
    report = kb.load([_write(tmp_path, "lab.trig", TRIG)])
    assert report.added == {SERVICES: 0, "http://example.org/counts#g1": 2} or report.added == {
        "http://example.org/counts#g1": 2
    }
    if report.files[0].added is not None:
        assert report.files[0].added == {"http://example.org/counts#g1": 2}


def test_imports_of_a_reload_add_nothing(kb: KnowledgeBase) -> None:
    first = kb.load([NAVIGATE], catalogue=ONTOLOGY)
    assert first.imports and first.added_quads == first.quads - first.already_present > 0
    again = kb.load([NAVIGATE], catalogue=ONTOLOGY)
    assert len(again.imports) == len(first.imports) and again.quads == first.quads
    assert again.added_quads == 0 and again.already_present == again.quads


def test_a_bulk_load_counts_a_triple_given_twice_once(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(loader_module, "BULK_BYTES", 1)
    path = _write(
        tmp_path,
        "big.nt",
        "<http://e/a> <http://e/p> <http://e/b> .\n" * 2 + "<http://e/c> <http://e/p> <http://e/d> .\n",
    )
    kb = KnowledgeBase(Store.open(":memory:"))
    report = kb.load([path], graph="map")
    assert report.files[0].bulk == 3  # took the bulk path: the file's own count
    assert (report.quads, report.added_quads, report.already_present) == (3, 2, 1)


# -- the command line ------------------------------------------------------------------------------


def _cbrs(store: str, *args: str) -> list[str]:
    result = CliRunner().invoke(cli, ["--store", store, "load", *args])
    assert result.exit_code == 0, result.output
    return result.output.splitlines()


def test_cli_first_load_reload_and_overlap(tmp_path: Path) -> None:
    store = str(tmp_path / "s")
    three, overlap = _write(tmp_path, "three.ttl", THREE), _write(tmp_path, "overlap.ttl", OVERLAP)
    first = _cbrs(store, str(three))
    assert first[0] == f"loaded {three}: 3 triples into graph:services"  # the existing line, unchanged
    assert first[-1] == "added 3 triples into graph:services; 0 already present"
    again = _cbrs(store, str(three))
    assert again[0] == first[0]
    assert again[-2:] == [
        "added 0 triples; 3 already present",
        f"  all already present, nothing added: 1 file ({three})",
    ]
    partly = _cbrs(store, str(overlap))
    assert partly[-2:] == [
        "added 1 triple into graph:services; 2 already present",
        f"  {overlap}: added 1 of 3 triples, 2 already present",
    ]


def test_cli_reload_with_a_catalogue_says_the_imports_added_nothing(tmp_path: Path) -> None:
    store = str(tmp_path / "s")
    first = _cbrs(store, "--catalog", str(ONTOLOGY), str(NAVIGATE), str(OPEN_DOOR))
    again = _cbrs(store, "--catalog", str(ONTOLOGY), str(NAVIGATE), str(OPEN_DOOR))
    imported = "imported 2 ontologies (21 triples) into graph:ontology"
    assert imported in first and imported in again  # what the catalogue resolved, as before
    assert first[-1].startswith("added ") and not first[-1].startswith("added 0 ")
    assert again[-3].startswith("added 0 triples; ")
    assert again[-2].startswith("  all already present, nothing added: 2 files (")
    assert again[-1].startswith("  all already present, nothing added: 2 imported ontologies (")


def test_cli_imports_not_followed_that_the_store_holds(tmp_path: Path) -> None:
    store = str(tmp_path / "s")
    alone = _cbrs(store, str(NAVIGATE))
    assert not any(line.startswith("  of which already in the store") for line in alone)
    _cbrs(store, "--catalog", str(ONTOLOGY), str(NAVIGATE))
    after = _cbrs(store, str(NAVIGATE))
    at = next(i for i, line in enumerate(after) if line.startswith("imports not followed (no --catalog): "))
    assert after[at + 1].startswith("  of which already in the store: ")
