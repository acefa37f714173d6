"""``cbrs query`` takes the names cbrs prints for a store: its derived prefixes (``lab4:Trolley1``).

A new lab's ``cbrs show`` printed ``lab4:Trolley1`` and ``cbrs run`` took it, but ``cbrs query`` refused it
("the prefix 'lab4:' is not declared"). A prefix the store derives is now declared above a query that
uses it and does not declare it; the declaration is written from the store's IRIs, never from the text.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner, Result

from cbrs.cli import cli
from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.sparql_hints import explain_syntax_error, one_line_up, prologue, store_prefixes_used

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
LAB = "https://example.org/lab4#"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A store with the lab's trolley in the ontology and the map, as docs/tasks.md's fourth round loads it."""
    location = str(tmp_path_factory.mktemp("lab4") / "store")
    for graph in ("ontology", "map"):
        loaded = CliRunner().invoke(
            cli, ["--store", location, "load", "--graph", graph, str(EXAMPLES / "lab4_trolley.ttl")]
        )
        assert loaded.exit_code == 0, loaded.output
    return location


def _cbrs(store: str, *args: str) -> Result:
    return CliRunner().invoke(cli, ["--store", store, *args])


@pytest.fixture(scope="module")
def printed(store: str) -> str:
    """The prefix ``cbrs show`` prints for the lab's namespace."""
    shown = _cbrs(store, "show", f"<{LAB}Trolley1>")
    assert shown.exit_code == 0, shown.output
    name = shown.output.split()[0]
    assert name.endswith(":Trolley1") and not name.startswith("<"), shown.output[:200]
    return name.removesuffix(":Trolley1")


def test_a_query_takes_the_prefix_cbrs_prints_for_the_store(store: str, printed: str) -> None:
    answer = _cbrs(store, "query", f"SELECT ?dock WHERE {{ {printed}:Trolley1 home:dockingPose ?dock }}")
    assert answer.exit_code == 0, answer.output
    assert f"{LAB}Trolley1Dock" in answer.output
    bound = _cbrs(store, "query", "--name", "map_facts", "--bind", f"thing={printed}:Trolley1")
    assert bound.exit_code == 0 and "home:dockingPose" in bound.output


def test_a_query_that_declares_the_prefix_itself_keeps_its_own(store: str, printed: str) -> None:
    own = f"PREFIX {printed}: <https://example.org/elsewhere#> SELECT * WHERE {{ {printed}:Trolley1 ?p ?o }}"
    answer = _cbrs(store, "query", own, "--format", "json")
    assert answer.exit_code == 0, answer.output
    assert json.loads(answer.stdout)["results"]["bindings"] == []  # elsewhere#Trolley1 is nothing of the store
    assert f"nothing in the store mentions {printed}:Trolley1" in answer.stderr  # and standard error says so


def test_a_misspelt_prefix_is_offered_the_stores_with_its_namespace(store: str, printed: str) -> None:
    answer = _cbrs(store, "query", "SELECT * WHERE { lab:Trolley1 ?p ?o }")
    assert answer.exit_code == 1
    assert "the prefix 'lab:' is not declared" in answer.output
    assert f"did you mean '{printed}:' (PREFIX {printed}: <{LAB}>, derived for this store)?" in answer.output


def test_a_syntax_error_is_placed_in_the_text_as_written(store: str, printed: str) -> None:
    """The declarations go on one line above the text; the parser's line numbers are corrected for it."""
    broken = f"SELECT * WHERE {{\n  {printed}:Trolley1 ?p ?o .\n  FILTER(?o = ) }}"
    plain = broken.replace(f"{printed}:Trolley1", f"<{LAB}Trolley1>")
    said, expected = _cbrs(store, "query", broken), _cbrs(store, "query", plain)
    assert said.exit_code == expected.exit_code == 1
    assert "error at 3:" in expected.output and said.output == expected.output
    assert f"'{printed}:' is not declared" not in said.output


def test_only_the_prefixes_used_and_undeclared_are_declared_and_only_plain_iris() -> None:
    table = {"lab4": LAB, "odd": "http://x/a> } ; DROP ALL #", "books": "http://127.0.0.1/books.owl#"}
    text = "PREFIX books: <http://b/> SELECT * WHERE { lab4:T ?p books:N . ?s odd:x ?o . ?s home:x ?v }"
    assert store_prefixes_used(text, lambda: table) == {"lab4": LAB}
    assert prologue({"lab4": LAB}) == f"PREFIX lab4: <{LAB}>\n" and prologue({}) == ""

    def unread() -> dict[str, str]:
        raise AssertionError("the table is read only for a text that uses a prefix nobody declares")

    assert store_prefixes_used("SELECT * WHERE { home:Pen ?p ?o }", unread) == {}


def test_the_explanation_counts_the_stores_prefixes_as_declared() -> None:
    text = "SELECT * WHERE {\n lab4:T ?p ?o . FILTER( }"
    error = QuerySyntaxError(text, "error at 3:30: expected one of ...")
    moved = one_line_up(error, text)
    assert moved.message.startswith("error at 2:30")
    explained = explain_syntax_error(moved, text, "query", {"lab4": LAB})
    assert "not declared" not in explained.message and "'('" in explained.message
    assert "the prefix 'lab4:' is not declared" in explain_syntax_error(moved, text, "query").message
