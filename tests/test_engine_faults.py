"""A query that crashes Oxigraph itself (a Rust panic, which aborts the process) is told as the engine's fault.

The query guard's checker, the endpoint's query workers and ``cbrs query`` (for a text that sorts) run such
a text in processes of their own; when one dies, what it wrote to its standard error says why
(``kb.engine_faults``). The real crashes used here are ``ORDER BY`` over dateTimes some with a time zone and
some without, which pyoxigraph 0.5.13 cannot sort: in a text (``tests/data/engine_faults/ordering_panic.rq``)
and in a store's data (``mixed_times.ttl``). Where a later pyoxigraph sorts them, those tests skip saying so.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.isolated_queries import IsolatedQueries
from cbrs.kb import KnowledgeBase
from cbrs.kb.engine_faults import read_death, sorts
from cbrs.kb.errors import EngineFaultError, QuerySyntaxError
from cbrs.kb.store import EmbeddedStore
from cbrs.output import render_result
from cbrs.sparql_service import EndpointConfig, SparqlService

FAULTS = Path(__file__).parent / "data" / "engine_faults"
ORDERING_PANIC = (FAULTS / "ordering_panic.rq").read_text(encoding="utf-8")
SHORT_PANIC = (FAULTS / "short_ordering_panic.rq").read_text(encoding="utf-8")
MIXED_TIMES = FAULTS / "mixed_times.ttl"
READINGS = "http://example.org/lab#readings"
SORTED_READINGS = "SELECT ?s ?t WHERE { ?s <http://example.org/lab#seenAt> ?t } ORDER BY ?t"
JSON = "application/sparql-results+json"
PANIC_OUTPUT = (
    "\nthread '<unnamed>' (4806) panicked at /rustc/58cf8f9c/library/core/src/slice/sort/shared/smallsort.rs:854:5:\n"
    "user-provided comparison function does not correctly implement a total order\n"
    "note: run with `RUST_BACKTRACE=1` environment variable to display a backtrace\n"
)


def test_a_panic_is_read_with_its_message_and_a_failed_allocation_as_memory() -> None:
    death = read_death("some earlier line\n" + PANIC_OUTPUT)
    assert death.panic == "user-provided comparison function does not correctly implement a total order"
    assert death.ordering_panic and not death.out_of_memory
    assert "give every one a time zone" in death.explain() and "STR(" in death.explain()
    oom = read_death("memory allocation of 1073741824 bytes failed\n")
    assert oom.panic is None and oom.out_of_memory and "memory" in oom.explain()
    other = read_death("thread 'main' panicked at src/lib.rs:10:3:\nindex out of bounds\n")
    assert other.panic == "index out of bounds" and not other.ordering_panic
    assert "time zone" not in other.explain()
    assert read_death("") == read_death("Segmentation fault\n") and read_death("").panic is None


@pytest.fixture(scope="module")
def engine_panics() -> None:
    """Skip unless this pyoxigraph still aborts on the text (run in a process of its own, which dies)."""
    code = "import pyoxigraph, sys; list(pyoxigraph.Store().query(sys.stdin.read()))"
    done = subprocess.run(
        [sys.executable, "-c", code], input=ORDERING_PANIC, text=True, capture_output=True, timeout=60
    )
    if done.returncode == 0:
        pytest.skip("this pyoxigraph sorts dateTimes with and without a time zone without panicking")
    assert "total order" in done.stderr


@pytest.fixture(scope="module")
def disk_kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(tmp_path_factory.mktemp("engine-faults") / "store")
    yield kb
    kb.close()


def test_the_guard_refuses_a_text_that_panics_the_engine_naming_the_panic(
    engine_panics: None, disk_kb: KnowledgeBase
) -> None:
    crashes = EmbeddedStore.guard.crashes
    with pytest.raises(EngineFaultError, match="panicked: 'user-provided comparison") as refused:
        disk_kb.store.query(ORDERING_PANIC)
    assert refused.value.query == ORDERING_PANIC and refused.value.http_status == 500
    assert "time zone" in str(refused.value) and "nested too deeply" not in str(refused.value)
    assert EmbeddedStore.guard.crashes == crashes + 1
    assert disk_kb.store.query("ASK { ?s ?p ?o }")  # this process never ran it


def test_a_worker_the_engine_aborts_in_is_its_fault_not_the_memory_cap(
    engine_panics: None, disk_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The guard let through (as it does a short text that panics only on the store's data): the worker dies."""
    monkeypatch.setattr(EmbeddedStore.guard, "direct_chars", len(ORDERING_PANIC) + 1)
    service = SparqlService(disk_kb, EndpointConfig(workers=1, timeout=30.0))
    try:
        assert service.processes is not None and service.processes.memory > 0
        with pytest.raises(EngineFaultError, match="total order") as failed:
            service.query(ORDERING_PANIC, JSON, None, "127.0.0.1")
        assert failed.value.query == ORDERING_PANIC
        answer = service.query("ASK { ?s ?p ?o }", JSON, None, "127.0.0.1")
        assert answer is not None and b'"boolean":true' in answer.body
    finally:
        service.close()


def test_a_short_text_that_panics_the_engine_costs_a_library_user_a_worker_only(
    engine_panics: None, disk_kb: KnowledgeBase
) -> None:
    """The guard runs a text this short in the caller's process; IsolatedQueries runs it in a worker."""
    assert len(SHORT_PANIC) <= EmbeddedStore.guard.direct_chars and sorts(SHORT_PANIC)
    assert isinstance(disk_kb.store, EmbeddedStore)
    with IsolatedQueries(disk_kb.store, keep=1) as isolated:
        with pytest.raises(EngineFaultError, match="total order") as failed:
            isolated.query(SHORT_PANIC)
        assert failed.value.query == SHORT_PANIC
        assert isolated.query("ASK { ?s ?p ?o }")  # a new worker, this process untouched


def test_a_text_that_may_sort_is_told_by_its_order_by_wherever_it_stands() -> None:
    assert sorts(SORTED_READINGS) and sorts("select * { { select ?t { ?s ?p ?t } order\n  by ?t limit 1 } }")
    assert sorts("SELECT ?t { ?s ?p ?t } ORDER # by time\nBY ?t")
    assert not sorts("SELECT ?t { ?s ?p ?t } GROUP BY ?t") and not sorts("SELECT (MIN(?t) AS ?m) { ?s ?p ?t }")
    assert sorts('ASK { ?s ?p "ORDER BY" }')  # a string's words cost a worker, never a missed sort


@pytest.fixture(scope="module")
def lab_store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A seeded on-disk store that also holds a lab's readings: dateTimes with and without a time zone."""
    location = str(tmp_path_factory.mktemp("engine-faults-lab") / "store")
    kb = KnowledgeBase.open(location)
    triples = ox.parse(MIXED_TIMES.read_bytes(), format=ox.RdfFormat.TURTLE)
    kb.store.add([ox.Quad(t.subject, t.predicate, t.object, ox.NamedNode(READINGS)) for t in triples])
    kb.close()
    return location


def test_cbrs_query_on_data_the_engine_cannot_sort_says_so_in_one_line(lab_store: str) -> None:
    """Before, the command died with Rust's panic line and "Aborted" (exit 134). Run as a child process, so
    that a regression aborts it, not pytest."""
    code = (
        "import pyoxigraph as ox, sys; store = ox.Store(); store.load(path=sys.argv[1], format=ox.RdfFormat.TURTLE);"
        " list(store.query(sys.argv[2]))"
    )
    probe = subprocess.run([sys.executable, "-c", code, str(MIXED_TIMES), SORTED_READINGS], capture_output=True)
    if probe.returncode == 0:
        pytest.skip("this pyoxigraph sorts the readings' dateTimes with and without a time zone without panicking")
    done = subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", lab_store, "query", SORTED_READINGS],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1 and done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("Error: the query crashed the store's SPARQL engine in an isolated process")
    assert "total order" in lines[0] and "give every one a time zone" in lines[0]
    ordered = SORTED_READINGS.replace("ORDER BY ?t", "ORDER BY STR(?t)")  # what the message says to do
    result = CliRunner().invoke(cli, ["--store", lab_store, "query", ordered, "--format", "csv"])
    assert result.exit_code == 0 and len(result.stdout.split()) == 1 + 24


SORTING_QUERIES = [  # each kind of result in the formats whose printing differs
    ("SELECT ?c ?label WHERE { ?c a owl:Class ; rdfs:label ?label } ORDER BY DESC(?label) ?c LIMIT 12", "table"),
    ("SELECT ?r ?p WHERE { ?r owl:onProperty ?p } ORDER BY ?p ?r LIMIT 6", "csv"),
    ("ASK { { SELECT ?c WHERE { ?c a owl:Class } ORDER BY ?c LIMIT 1 } }", "table"),
    ("CONSTRUCT { ?c rdfs:label ?l } WHERE { ?c a owl:Class ; rdfs:label ?l } ORDER BY ?l LIMIT 5", "table"),
    ("DESCRIBE ?c WHERE { ?c a owl:Class } ORDER BY ?c LIMIT 1", "json"),
]


def test_a_query_that_sorts_prints_from_its_worker_what_it_printed_in_process(
    lab_store: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    isolated: list[str] = []
    query = IsolatedQueries.query

    def counted(self: IsolatedQueries, text: str) -> object:
        isolated.append(text)
        return query(self, text)

    monkeypatch.setattr(IsolatedQueries, "query", counted)
    printed: dict[tuple[str, str], bytes] = {}
    for text, fmt in SORTING_QUERIES:
        result = CliRunner().invoke(cli, ["--store", lab_store, "query", text, "--format", fmt])
        assert result.exit_code == 0, result.output
        printed[text, fmt] = result.stdout_bytes
    assert len(isolated) == len(printed)
    unsorted = "SELECT ?c WHERE { ?c a owl:Class } LIMIT 1"
    assert CliRunner().invoke(cli, ["--store", lab_store, "query", unsorted]).exit_code == 0
    assert len(isolated) == len(printed)  # a text that does not sort runs in this process, as before
    kb = KnowledgeBase.open(lab_store)
    try:
        for (text, fmt), output in printed.items():
            assert output == (render_result(kb.query(text), fmt) + "\n").encode(), (text, fmt)
    finally:
        kb.close()


# -- updates whose WHERE sorts: evaluated on a copy in a child process, the effect written here (kb.sorting_updates)

UPDATE_PANIC = (FAULTS / "update_ordering_panic.ru").read_text(encoding="utf-8")
FIRST_READING = (
    "PREFIX lab: <http://example.org/lab#> INSERT { GRAPH lab:first { lab:first lab:seenAt ?t } }"
    " WHERE { { SELECT ?t { GRAPH ?g { ?s lab:seenAt ?t } } ORDER BY ?t LIMIT 1 } }"
)
SORTING_UPDATE = """
INSERT { <http://example.org/first> rdfs:label ?label } WHERE {
  { SELECT ?label { GRAPH ?g { ?c a owl:Class ; rdfs:label ?label } } ORDER BY DESC(?label) LIMIT 2 } } ;
DELETE { GRAPH ?g { ?r ?p ?o } } WHERE {
  { SELECT ?r ?g { GRAPH ?g { ?r owl:onProperty ?x } FILTER isBlank(?r) } ORDER BY ?x LIMIT 3 }
  GRAPH ?g { ?r ?p ?o } } ;
DELETE { GRAPH ?g { ?c rdfs:label ?l } } INSERT { GRAPH <http://example.org/labels> { ?c rdfs:label ?l } } WHERE {
  { SELECT ?c ?l ?g { GRAPH ?g { ?c a owl:Class ; rdfs:label ?l } } ORDER BY ?l LIMIT 4 } }
"""
"""Three operations that sort: one adds to the default graph, one removes statements about blank nodes (whose
ids must match the store's; one is a graph's name), one moves labels between named graphs."""


@pytest.fixture(scope="module")
def update_panics() -> None:
    """Skip unless this pyoxigraph still aborts on the update (run in a process of its own, which dies)."""
    code = "import pyoxigraph, sys; pyoxigraph.Store().update(sys.stdin.read())"
    done = subprocess.run([sys.executable, "-c", code], input=UPDATE_PANIC, text=True, capture_output=True, timeout=60)
    if done.returncode == 0:
        pytest.skip("this pyoxigraph runs an update sorting dateTimes with and without a time zone without panicking")
    assert "total order" in done.stderr


def test_an_update_that_panics_the_engine_costs_a_child_process_and_writes_nothing(update_panics: None) -> None:
    """Before, the process running KnowledgeBase.update died (exit 134), and so did a server sent it on /update
    by a token holder. Run in a child process all the same, so that a regression aborts it, not pytest."""
    assert len(UPDATE_PANIC) <= EmbeddedStore.guard.direct_chars  # the guard's checker never sees it
    code = """if True:
        import sys
        from cbrs.kb import KnowledgeBase
        from cbrs.kb.errors import EngineFaultError
        kb = KnowledgeBase.open(":memory:")
        before = set(kb.store.quads())
        text = sys.stdin.read()
        try:
            kb.update(text)
        except EngineFaultError as error:
            print("refused", "total order" in error.reason, "time zone" in str(error))
        print("unchanged", set(kb.store.quads()) == before)
        kb.update("INSERT DATA { <http://example.org/a> <http://example.org/b> 1 }")
        print("writable", len(set(kb.store.quads()) - before))
        from cbrs.sparql_service import EndpointConfig, SparqlService
        service = SparqlService(kb, EndpointConfig(workers=1, update_token="t"))
        try:
            service.update(text, "t")
        except EngineFaultError as error:
            print("endpoint refused", error.http_status)
        finally:
            service.close()
    """
    done = subprocess.run([sys.executable, "-c", code], input=UPDATE_PANIC, text=True, capture_output=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n") == ["refused True True", "unchanged True", "writable 1", "endpoint refused 500", ""]


def test_cbrs_update_of_data_the_engine_cannot_sort_says_so_and_changes_nothing(
    update_panics: None, lab_store: str
) -> None:
    """An on-disk store whose readings the update's subquery sorts: the command says why in one line."""
    before = subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", lab_store, "query", "SELECT (COUNT(*) AS ?n) { ?s ?p ?o }"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    done = subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", lab_store, "update", FIRST_READING],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 1, done.stderr
    lines = done.stderr.splitlines()
    assert lines[0].startswith("Error: the update crashed the store's SPARQL engine in an isolated process")
    assert "total order" in lines[0] and "give every one a time zone" in lines[0]
    assert "panicked at" not in done.stderr and "Aborted" not in done.stderr
    after = subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", lab_store, "query", "SELECT (COUNT(*) AS ?n) { ?s ?p ?o }"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert before.returncode == 0 and after.stdout == before.stdout


def test_a_sorting_update_leaves_the_store_as_it_did_in_process_and_others_run_in_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same updates on three stores seeded alike: in this process as before this change (``sorts`` said no
    to all), and through a child process on an on-disk store's checkpoint and on an in-memory store's dump;
    every quad the same, blank nodes too."""
    import cbrs.kb.knowledge_base as knowledge_base
    from cbrs.kb import sorting_updates

    isolated: list[str] = []
    run = sorting_updates.update

    def counted(store: EmbeddedStore, text: str) -> None:
        isolated.append(text)
        run(store, text)

    monkeypatch.setattr(sorting_updates, "update", counted)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # where the copies go
    old = KnowledgeBase.open(":memory:")
    disk = KnowledgeBase.open(tmp_path / "store")
    memory = KnowledgeBase.open(":memory:")
    unsorted = "DELETE WHERE { GRAPH ?g { ?c a owl:Class ; rdfs:comment ?comment } }"
    restriction, graph = ox.BlankNode(), ox.BlankNode()  # the bundled store's are skolemised: these are not
    on, blank = ox.NamedNode("http://www.w3.org/2002/07/owl#onProperty"), ox.NamedNode("http://example.org/blank")
    blank_nodes = [
        ox.Quad(restriction, on, ox.NamedNode("http://example.org/p"), blank),
        ox.Quad(restriction, on, ox.NamedNode("http://example.org/q"), graph),
        ox.Quad(ox.NamedNode("http://example.org/r"), on, restriction),
    ]
    try:
        for kb in (old, disk, memory):
            kb.store.add(blank_nodes)
        assert set(old.store.quads()) == set(disk.store.quads()) == set(memory.store.quads())
        with monkeypatch.context() as patched:
            patched.setattr(knowledge_base, "sorts", lambda text: False)
            old.update(SORTING_UPDATE)
            old.update(unsorted)
        expected = set(old.store.quads())
        assert not expected & set(blank_nodes[:2]) and blank_nodes[2] in expected  # it did remove blank nodes'
        assert next(iter(old.store.quads(subject=ox.NamedNode("http://example.org/first"))), None) is not None
        for kb in (disk, memory):
            kb.update(SORTING_UPDATE)
            assert isolated == [SORTING_UPDATE]
            kb.update(unsorted)
            assert isolated == [SORTING_UPDATE]  # a text that does not sort runs in this process, as before
            assert set(kb.store.quads()) == expected
            isolated.clear()
        with pytest.raises(QuerySyntaxError):
            disk.update("INSERT { ?s ?p ?o } WHERE { { SELECT * { ?s ?p ?o } ORDER BY ?s LIMIT 1 } ")
        assert set(disk.store.quads()) == expected
    finally:
        for kb in (old, disk, memory):
            kb.close()
    assert not list(tmp_path.glob("cbrs-update-copy-*"))  # the copies are gone
