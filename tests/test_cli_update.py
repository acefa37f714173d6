"""cbrs update (kb/update_report.py): a SPARQL update from the command line, all or nothing, graph:entailed
brought up to date, and what changed said graph by graph; a syntax error, a query, a read-only server and a
split update on Virtuoso refused with nothing changed."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, QuerySyntaxError, Store, StoreEvaluationError, knowledge_base
from cbrs.kb.remote_store import Endpoints, RemoteStore
from cbrs.kb.semantic_map import MapError
from cbrs.kb.update_report import NO_SIZE_CHANGED, UpdateSplitError, operations, refuse_split
from tests.conftest import MINI_FILES, OxigraphServer

CAMERA = "INSERT DATA { GRAPH graph:services { <http://example.org/lab#Cam9> a cbrs:DynamicPerceptionComponent } }"


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """One seeded in-memory store for the module's updates."""
    found = KnowledgeBase.open(":memory:")
    yield found
    found.close()


def _cbrs(*args: str, given: str | None = None) -> tuple[int, str, str]:
    """A command on a fresh in-memory store (each command has its own)."""
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args], input=given)
    return result.exit_code, result.stdout, result.stderr


def test_the_cli_says_what_a_data_update_changed_per_graph(tmp_path: Path) -> None:
    code, out, _ = _cbrs("update", CAMERA)
    assert code == 0
    assert out.splitlines() == ["graph:services: 1 added, 0 removed", "graph:entailed: 1 added, 0 removed"]
    code, out, _ = _cbrs("update", "--json", CAMERA)
    assert code == 0 and json.loads(out)["exact"] is True
    changes = {c["graph"].rsplit("/", 1)[1]: (c["added"], c["removed"], c["net"]) for c in json.loads(out)["changes"]}
    assert changes == {"services": (1, 0, 1), "entailed": (1, 0, 1)}
    text = tmp_path / "clear.ru"
    text.write_text("CLEAR SILENT GRAPH graph:plans\n", encoding="utf-8")
    assert _cbrs("update", "--file", str(text))[:2] == (0, NO_SIZE_CHANGED + "\n")  # not data: counted by size
    assert _cbrs("update", "--file", "-", given="DELETE WHERE { GRAPH graph:map { world:Cup home:yaw ?yaw } }")[:2] == (
        0,
        "graph:map: -1 triples (net: the size before and after)\n",
    )


def test_updates_in_a_row_are_counted_and_another_update_by_the_graphs_sizes(kb: KnowledgeBase) -> None:
    assert kb.update_counted(CAMERA).lines() == [
        "graph:services: 1 added, 0 removed",
        "graph:entailed: 1 added, 0 removed",
    ]
    assert kb.update_counted(CAMERA).lines() == ["nothing changed"]
    assert kb.update_counted(CAMERA.replace("INSERT", "DELETE")).lines() == [
        "graph:services: 0 added, 1 removed",
        "graph:entailed: 0 added, 1 removed",
    ]
    moved = kb.update_counted(
        "DELETE { GRAPH graph:map { ?thing home:yaw ?yaw } } INSERT { GRAPH graph:map { ?thing home:yaw 1.0 } }\n"
        "WHERE { GRAPH graph:map { ?thing home:yaw ?yaw FILTER (?yaw = 0) } }"
    )
    # as many removed as added: no net change, and the report does not claim that nothing changed
    assert not moved.exact and moved.lines() == [NO_SIZE_CHANGED]
    assert kb.query("ASK { GRAPH graph:map { ?thing home:yaw 1.0 } }")  # it did change a value


@pytest.mark.parametrize(
    ("text", "said"),
    [
        pytest.param("INSERT DATA { GRAPH graph:services { <http://e.org/a> a }", "nothing was changed", id="syntax"),
        pytest.param('INSERT DATA { GRAPH graph:map { world:Pen rdfs:comment "}" }', "1 '{' not closed", id="unclosed"),
        pytest.param(
            "DELETE WHERE { GRAPH graph:services { ?p cbrs:parameterType home:VideoStream } }",
            "parameterType, the IRI of a class (or a property used as a concept) (and 1 other description with "
            "problems); nothing was changed",
            id="shape",
        ),
        pytest.param(
            CAMERA + " ; DROP GRAPH <urn:example:none>",
            "The graph <urn:example:none> does not exist; nothing was changed",
            id="evaluation",
        ),
        pytest.param("SELECT * WHERE { ?s ?p ?o }", "this is a SPARQL query, not an update", id="query"),
        pytest.param("INSERT DATA { GRAPH graph:services { _:b a cbrs:Camera } }", "_:b", id="blank-node"),
    ],
)
def test_a_refused_update_is_one_line(text: str, said: str) -> None:
    code, _, err = _cbrs("update", text)
    assert code == 1 and said in err and "\n" not in err.strip()


def test_an_update_that_fails_changes_nothing(kb: KnowledgeBase) -> None:
    before = kb.store.dump()
    with pytest.raises(QuerySyntaxError):
        kb.update_counted("INSERT DATA { GRAPH graph:services { <http://e.org/a> a } }")
    with pytest.raises(StoreEvaluationError):  # the first operation would have written, the second fails
        kb.update_counted(CAMERA + " ; CREATE GRAPH graph:services")
    assert kb.store.dump() == before


def test_an_update_on_a_remote_store_is_counted_by_sizes(oxigraph_server: OxigraphServer) -> None:
    oxigraph_server.clear()
    kb = KnowledgeBase(Store.open(oxigraph_server.url))
    kb.load(MINI_FILES)
    report = kb.update_counted(CAMERA)
    assert not report.exact and report.lines()[0] == "graph:services: +1 triples (net: the size before and after)"
    kb.close()


def test_several_operations_are_refused_where_a_request_is_not_one_transaction() -> None:
    assert operations("INSERT DATA { <a:b> <a:c> 'x;y' ; <a:d> <a:e> } ;") == 1
    assert operations("CLEAR ALL ; # a comment ; \n CLEAR ALL") == 2
    store = RemoteStore("http://127.0.0.1:1/sparql", Endpoints.discover("http://127.0.0.1:1/sparql"))
    store._virtuoso = True
    try:
        refuse_split(store, "DROP SILENT GRAPH <a:b>")
        with pytest.raises(UpdateSplitError, match="this update has 2: send them one at a time") as refused:
            refuse_split(store, "DROP SILENT GRAPH <a:b> ; INSERT DATA { GRAPH <a:g> { <a:b> <a:c> <a:d> } }")
        assert refused.value.operations == 2
        said = "updates are disabled: this server was started read-only"
        assert store._refusal(403, store.endpoints.update, said).startswith("the server takes no updates")
    finally:
        store.close()


@pytest.mark.parametrize(
    "text",
    [
        pytest.param('INSERT DATA { GRAPH graph:map { world:Pen home:shapeKind "sphere" } }', id="data"),
        pytest.param(
            "INSERT DATA { GRAPH <urn:example:lab> { <urn:example:a> <urn:example:b> <urn:example:c> } } ;\n"
            "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }",
            id="where-after-data",
        ),
    ],
)
def test_an_update_that_breaks_the_semantic_map_is_refused_as_a_load_is(kb: KnowledgeBase, text: str) -> None:
    before = kb.store.dump()
    with pytest.raises(MapError) as refused:
        kb.update_counted(text)
    assert "world#Pen" in str(refused.value) and "nothing was changed" in "\n".join(refused.value.__notes__)
    assert kb.store.dump() == before  # the other graph's write is gone too


def test_the_cli_names_the_map_problem_of_a_refused_update() -> None:
    code, _, err = _cbrs("update", "DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }")
    assert code == 1 and "Pen" in err and "has no home:sizeX" in err and "nothing was changed" in err


def test_a_remote_store_refuses_the_update_on_a_copy_and_is_left_as_it_was(oxigraph_server: OxigraphServer) -> None:
    oxigraph_server.clear()
    kb = KnowledgeBase.open(oxigraph_server.url)
    try:
        before = kb.store.dump()
        with pytest.raises(MapError) as refused:
            kb.update_counted("DELETE WHERE { GRAPH graph:map { world:Pen home:sizeX ?x } }")
        assert "nothing was changed" in "\n".join(refused.value.__notes__)
        assert kb.store.dump() == before
    finally:
        kb.close()


def test_clear_all_counts_graph_entailed_and_says_the_store_will_be_seeded_again() -> None:
    code, out, err = _cbrs("update", "CLEAR ALL")
    assert code == 0 and "graph:ontology: -" in out
    entailed = next(line for line in out.splitlines() if line.startswith("graph:entailed"))
    assert entailed.startswith("graph:entailed: -") and entailed.endswith("(net: the size before and after)")
    assert "the next command that opens the store seeds it again" in err


def test_the_shape_check_is_left_out_for_an_update_that_cannot_reach_the_descriptions(
    kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """It read graph:services and graph:requirements whole twice for every update that was not data (28 s of
    a map update's 29 s on Virtuoso holding OWLS-TC)."""
    checked: list[str] = []
    real = knowledge_base.checked_update

    def spied(store: Store, whole: bool = False) -> Any:
        checked.append("checked")
        return real(store, whole)

    monkeypatch.setattr(knowledge_base, "checked_update", spied)
    moved = "DELETE { GRAPH graph:map { world:Pen home:yaw ?y } } INSERT { GRAPH graph:map { world:Pen home:yaw 0.5 } }"
    kb.update_counted(moved + " WHERE { GRAPH graph:map { world:Pen home:yaw ?y } }")
    assert checked == []
    kb.update_counted("DELETE { GRAPH ?g { <urn:example:a> ?p ?o } } WHERE { GRAPH ?g { <urn:example:a> ?p ?o } }")
    assert checked == ["checked"]  # a variable graph may be graph:services
