"""A program calling ``kb.query`` or ``kb.update`` gets the syntax error ``cbrs query`` and the endpoint give
(:func:`cbrs.kb.sparql_hints.explain_syntax_error`: an undeclared prefix and the nearest, the store's
derived one with its declaration, a query sent as an update), not Oxigraph's list of expected characters;
the parser's own words are kept (``parsed``), and the CLI, which runs the text under a prologue of its own,
explains it once, as before."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, QuerySyntaxError
from cbrs.kb.sparql_hints import explain_syntax_error, unexplained

LAB4 = "https://example.org/lab4#"


@pytest.fixture(scope="module")
def lab_kb() -> Iterator[KnowledgeBase]:
    """A store holding one IRI of a lab's namespace, for which it derives the prefix lab4:."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(f'INSERT DATA {{ GRAPH graph:ontology {{ <{LAB4}Trolley1> rdfs:label "trolley" }} }}')
    yield kb
    kb.close()


@pytest.mark.parametrize(
    ("run", "text", "said"),
    [
        pytest.param(
            "query",
            "SELECT * WHERE { ?s hom:isLocatedOn ?o }",
            "the prefix 'hom:' is not declared: add PREFIX hom: <IRI>; did you mean 'home:'?",
            id="prefix",
        ),
        pytest.param(
            "query",
            "SELECT * WHERE { lab:Trolley1 ?p ?o }",
            f"did you mean 'lab4:' (PREFIX lab4: <{LAB4}>, derived for this store)?",
            id="derived-prefix",
        ),
        pytest.param("query", "SELEKT * WHERE { ?s ?p ?o }", "'SELEKT' begins no SPARQL query: did you mean SELECT?"),
        pytest.param("update", "SELECT * WHERE { ?s ?p ?o }", "this is a SPARQL query, not an update"),
        pytest.param(
            "update_counted",
            "INSERT DATA { GRAPH graph:map { home:Cup1 hme:colour home:Red } }",
            "the prefix 'hme:' is not declared",
        ),
    ],
)
def test_the_library_explains_a_syntax_error_as_the_cli_does(
    lab_kb: KnowledgeBase, run: str, text: str, said: str
) -> None:
    method: Callable[[str], object] = getattr(lab_kb, run)
    with pytest.raises(QuerySyntaxError) as refused:
        method(text)
    error = refused.value
    assert said in str(error) and error.query == text
    assert error.parsed is not None and error.parsed.startswith("error at 1:") and "expected" in error.parsed
    assert error.message.startswith("error at 1:") and "expected one of" not in error.message
    # explained once: asking again changes nothing; the parser's words are there for a caller that knows more
    assert explain_syntax_error(error, text, "query") is error
    assert unexplained(error).message == error.parsed and unexplained(error).parsed is None


def test_the_cli_says_it_once() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "query", "SELEKT * WHERE { ?s ?p ?o }"])
    assert result.exit_code == 1
    assert result.stderr.count("begins no SPARQL query") == 1
    assert "(the parser: expected CONSTRUCT)" in result.stderr
