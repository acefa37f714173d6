"""``cbrs update`` takes the names cbrs prints for a store (``lab4:Trolley1``) as ``cbrs query`` does.

After the fourth round, ``cbrs query`` declared a store's derived prefixes above a query that uses them,
but ``cbrs update`` still refused them ("the prefix 'lab4:' is not declared"). The same rule applies now:
the declarations are written from the store's IRIs, never from the text; an update that declares the
prefix keeps its own; a syntax error is placed in the text as written.
"""

from __future__ import annotations

import json

from click.testing import Result

from tests.test_query_store_prefixes import LAB, _cbrs, printed, store

__all__ = ["printed", "store"]  # the fixtures, used by name


def _labels(location: str, iri: str) -> str:
    answer = _cbrs(location, "query", f"SELECT ?label WHERE {{ GRAPH graph:map {{ <{iri}> rdfs:label ?label }} }}")
    assert answer.exit_code == 0, answer.output
    return answer.output


def _update(location: str, text: str) -> Result:
    return _cbrs(location, "update", text)


def test_an_update_takes_the_prefix_cbrs_prints_for_the_store(store: str, printed: str) -> None:
    answer = _update(store, f'INSERT DATA {{ GRAPH graph:map {{ {printed}:Trolley1 rdfs:label "serving trolley" }} }}')
    assert answer.exit_code == 0, answer.output
    assert answer.output.startswith("graph:map: 1 added, 0 removed")
    assert "serving trolley" in _labels(store, f"{LAB}Trolley1")


def test_an_update_that_declares_the_prefix_itself_keeps_its_own(store: str, printed: str) -> None:
    elsewhere = "https://example.org/elsewhere#"
    own = f'PREFIX {printed}: <{elsewhere}> INSERT DATA {{ GRAPH graph:map {{ {printed}:Cart rdfs:label "a cart" }} }}'
    answer = _update(store, own)
    assert answer.exit_code == 0, answer.output
    found = _cbrs(store, "query", 'SELECT ?s WHERE { GRAPH graph:map { ?s rdfs:label "a cart" } }', "--format", "json")
    assert [row["s"]["value"] for row in json.loads(found.output)["results"]["bindings"]] == [f"{elsewhere}Cart"]


def test_a_syntax_error_is_placed_in_the_update_as_written(store: str, printed: str) -> None:
    broken = f"DELETE WHERE {{\n  GRAPH graph:map {{ {printed}:Trolley1 rdfs:label ?l .\n  FILTER(?l = ) }} }}"
    plain = broken.replace(f"{printed}:Trolley1", f"<{LAB}Trolley1>")
    said, expected = _update(store, broken), _update(store, plain)
    assert said.exit_code == expected.exit_code == 1
    assert "error at 3:" in expected.output and said.output == expected.output
    assert "nothing was changed" in said.output and f"'{printed}:' is not declared" not in said.output


def test_a_misspelt_prefix_is_offered_the_stores_with_its_namespace(store: str, printed: str) -> None:
    answer = _update(store, 'INSERT DATA { GRAPH graph:map { lab:Trolley1 rdfs:label "x" } }')
    assert answer.exit_code == 1
    assert "the prefix 'lab:' is not declared" in answer.output
    assert f"did you mean '{printed}:' (PREFIX {printed}: <{LAB}>, derived for this store)?" in answer.output


def test_an_update_that_changed_nothing_names_the_stores_name_it_matched_nowhere(store: str, printed: str) -> None:
    answer = _update(store, f'DELETE DATA {{ GRAPH graph:map {{ {printed}:Trolly1 rdfs:label "x" }} }}')
    assert answer.exit_code == 0, answer.output
    assert f"note: nothing in the store mentions {printed}:Trolly1" in answer.output
    assert f"{printed}:Trolley1" in answer.output  # the nearest name, as the store prints it
