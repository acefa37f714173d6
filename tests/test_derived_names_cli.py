"""The CLI takes and prints the names the browser shows for a store's own namespaces (``books1:Novel``,
:mod:`cbrs.kb.derived_prefixes`), so a name copied from a page works in a command and back; ``--json``
keeps whole IRIs, and a name that names nothing gets the nearest names."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import CACHE_FILE, _files_key
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from cbrs.web.links import short
from cbrs.web.prefixes import derived

BOOKS = "http://127.0.0.1/ontology/books.owl#"
MIRROR = "http://example.com/mirror/books.owl#"  # the same file name as BOOKS': the two are numbered
SERVICE = "http://127.0.0.1/services/1.1/novel_price_service.owls#"
LAB = "http://example.org/lab#"
PROLOGUE = """@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix cbrs: <https://w3id.org/cbrs/core#> .
"""
GRAPHS = {
    "ontology": f"""<{BOOKS}Book> a owl:Class .
<{BOOKS}Novel> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> .
<{MIRROR}Novel> a owl:Class ; rdfs:subClassOf <{BOOKS}Book> .
""",
    "services": f"""<{SERVICE}NOVEL_PRICE> a cbrs:MethodInvocationComponent ; rdfs:label "novel price" ;
    cbrs:deviceName "novel_price_service" ; cbrs:serviceName "NovelPrice" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "_NOVEL" ; cbrs:parameterType <{BOOKS}Novel> ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "_BOOK" ; cbrs:parameterType <{BOOKS}Book> ] ] .
""",
    "requirements": f"""<{LAB}NovelPrice> a cbrs:Requirement ;
    cbrs:deviceName "P3DX01" ; cbrs:serviceName "NovelPrice" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType <{BOOKS}Novel> ] ;
                        cbrs:hasOutput [ cbrs:parameterType <{BOOKS}Book> ] ] .
""",
}


def run(store: Path, *args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["--store", str(store), *args])
    return result.exit_code, result.output


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("derived")
    store = folder / "store"
    for graph, text in GRAPHS.items():
        (folder / f"{graph}.ttl").write_text(PROLOGUE + text, encoding="utf-8")
        code, out = run(store, "load", "--graph", graph, str(folder / f"{graph}.ttl"))
        assert code == 0, out
    return store


@pytest.fixture
def store(made: Path, tmp_path: Path) -> Path:
    """A copy of the store for one test: some write to it, and each starts without a kept table."""
    copy = tmp_path / "store"
    shutil.copytree(made, copy)
    (copy / CACHE_FILE).unlink(missing_ok=True)
    return copy


@pytest.fixture(scope="module")
def browser(made: Path) -> dict[str, str]:
    """How the browser names this store's IRIs (cbrs.web.links.short), read from a copy of it."""
    copy = made.parent / "browser-copy"
    shutil.copytree(made, copy)
    kb = KnowledgeBase.open(copy)
    try:
        with create_app(SparqlService(kb)).app_context():
            named = (BOOKS + "Novel", MIRROR + "Novel", SERVICE + "NOVEL_PRICE", LAB + "NovelPrice")
            return {iri: short(iri) for iri in named}
    finally:
        kb.close()


def test_the_browser_derives_the_names_this_test_types(browser: dict[str, str]) -> None:
    assert browser[BOOKS + "Novel"] != browser[MIRROR + "Novel"]
    assert all(":" in name and "://" not in name for name in browser.values()), browser


def test_show_takes_and_prints_the_browsers_names(store: Path, browser: dict[str, str]) -> None:
    code, out = run(store, "show", browser[SERVICE + "NOVEL_PRICE"])
    assert code == 0, out
    assert out.splitlines()[0].startswith(browser[SERVICE + "NOVEL_PRICE"] + "  (cbrs:MethodInvocationComponent)")
    assert f"input        {browser[BOOKS + 'Novel']} _NOVEL" in out and "http://" not in out
    code, out = run(store, "show", browser[MIRROR + "Novel"])  # the numbered one of the two books namespaces
    assert code == 0, out
    assert out.splitlines()[0] == browser[MIRROR + "Novel"]


def test_services_prints_names_that_paste_back_and_json_keeps_iris(store: Path, browser: dict[str, str]) -> None:
    code, out = run(store, "services", "--full")
    assert code == 0, out
    row = next(line for line in out.splitlines() if "novel_price_service" in line)
    name = row.split()[0]
    assert name == browser[SERVICE + "NOVEL_PRICE"] and browser[BOOKS + "Novel"] in row.split()
    assert run(store, "show", name)[0] == 0
    code, out = run(store, "services", "--json")
    assert code == 0, out
    ours = next(item for item in json.loads(out) if item["deviceName"] == "novel_price_service")
    assert ours["service"] == SERVICE + "NOVEL_PRICE" and ours["inputs"] == [BOOKS + "Novel"]


def test_match_and_plan_take_a_derived_name(store: Path, browser: dict[str, str]) -> None:
    requirement = browser[LAB + "NovelPrice"]
    code, out = run(store, "match", requirement, "--top", "1")
    assert code == 0, out
    assert out.startswith(f"{requirement}: matched") and browser[SERVICE + "NOVEL_PRICE"] in out
    code, out = run(store, "match", requirement, "--json")
    assert code == 0, out
    assert json.loads(out)["requirement"] == LAB + "NovelPrice"
    code, out = run(store, "plan", requirement, "--no-store")
    assert code == 0, out
    assert out.startswith(f"{requirement}: planned")


def test_deregister_takes_a_derived_name(store: Path, browser: dict[str, str]) -> None:
    code, out = run(store, "deregister", browser[SERVICE + "NOVEL_PRICE"])
    assert code == 0, out
    assert out.startswith(f"deregistered {browser[SERVICE + 'NOVEL_PRICE']} (")


def test_a_name_that_names_nothing_gets_the_nearest(store: Path, browser: dict[str, str]) -> None:
    service = browser[SERVICE + "NOVEL_PRICE"]
    code, out = run(store, "show", service[:-1])  # NOVEL_PRIC
    assert code == 1
    assert f"nothing in the store mentions <{SERVICE}NOVEL_PRIC>; did you mean {service}?" in out
    prefix, _, local = service.partition(":")
    code, out = run(store, "show", f"{prefix[:-1]}:{local}")  # a prefix no scheme can be (it has a _)
    assert code == 2
    assert "derived prefixes" in out and f"did you mean {service}" in out
    code, out = run(store, "match", browser[LAB + "NovelPrice"] + "s")
    assert code == 1 and f"did you mean {browser[LAB + 'NovelPrice']}?" in out


def test_the_next_command_takes_the_table_kept_in_the_store_folder(store: Path, browser: dict[str, str]) -> None:
    for _ in range(5):  # until RocksDB has compacted what the load wrote (a new key, and a new read, each time)
        before = _files_key(store)
        assert run(store, "show", browser[LAB + "NovelPrice"])[0] == 0
        if _files_key(store) == before:
            break
    kept = json.loads((store / CACHE_FILE).read_text(encoding="utf-8"))
    assert kept["key"] == _files_key(store)
    assert kept["prefixes"][browser[BOOKS + "Novel"].split(":")[0]] == BOOKS
    kept["prefixes"]["kept_only"] = BOOKS  # a prefix only the kept table has: only a command that reads it knows it
    (store / CACHE_FILE).write_text(json.dumps(kept), encoding="utf-8")
    code, out = run(store, "show", "kept_only:Novel")
    assert code == 0, out


def test_the_browser_takes_the_table_kept_in_the_store_folder(store: Path, browser: dict[str, str]) -> None:
    """``cbrs serve`` on an on-disk store starts from the table a command kept (it read every term of the
    store at each start: 12.5 s of a core for a million triples)."""
    for _ in range(5):  # until RocksDB has compacted what the load wrote, as above
        before = _files_key(store)
        assert run(store, "show", browser[LAB + "NovelPrice"])[0] == 0
        if _files_key(store) == before:
            break
    kept = json.loads((store / CACHE_FILE).read_text(encoding="utf-8"))
    kept["prefixes"]["kept_only"] = "http://example.org/kept-only#"  # only a browser taking the kept table knows it
    (store / CACHE_FILE).write_text(json.dumps(kept), encoding="utf-8")
    kb = KnowledgeBase.open(store)
    try:
        with create_app(SparqlService(kb)).app_context():
            assert short(BOOKS + "Novel") == browser[BOOKS + "Novel"]
            assert derived()["kept_only"] == "http://example.org/kept-only#"
    finally:
        kb.close()


def test_a_write_makes_the_kept_table_new(store: Path, tmp_path: Path, browser: dict[str, str]) -> None:
    """The table kept in the store's folder is keyed by its data files: after a load that brings a new
    namespace, the next command knows its prefix (a stale table would refuse the name)."""
    assert run(store, "show", browser[LAB + "NovelPrice"])[0] == 0
    assert (store / CACHE_FILE).is_file()
    extra = tmp_path / "extra.ttl"
    extra.write_text("<http://example.org/shelf/extra.owl#Shelf> a <http://www.w3.org/2002/07/owl#Class> .\n")
    assert run(store, "load", str(extra))[0] == 0
    code, out = run(store, "show", "extra:Shelf")
    assert code == 0, out
    assert out.splitlines()[0] == "extra:Shelf"


def test_a_named_querys_bind_takes_a_derived_name_and_its_rows_keep_whole_iris(
    store: Path, browser: dict[str, str]
) -> None:
    service = browser[SERVICE + "NOVEL_PRICE"]
    code, out = run(store, "query", "--name", "description_parameters", "--bind", f"description={service}")
    assert code == 0, out
    assert "_NOVEL" in out and BOOKS + "Novel" in out and browser[BOOKS + "Novel"] not in out
    code, out = run(store, "query", "--name", "description_parameters", "--bind", f"description={service[:-1]}")
    assert code == 0, out
    assert "(0 rows)" in out and f"did you mean {service}?" in out
