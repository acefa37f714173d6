"""A name typed with a misspelt prefix (``hom:Cup`` for ``home:Cup``) is refused, naming the input, the
prefix and the declared prefixes nearest it (``UnknownPrefixError``), wherever cbrs reads a name: it was
taken as an absolute IRI of scheme ``hom``, named nothing, and a named query gave no rows, ``cbrs show``
"nothing in the store mentions" it. Absolute IRIs keep passing: an authority (``scheme://``), a scheme
RDF data writes bare (``urn:``, ``tag:``, ``mailto:``...), or anything in ``<>`` (docs/web.md, "Names
in the CLI")."""

from __future__ import annotations

from collections.abc import Mapping

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import BindingError, KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.kb.namespaces import HOME, expand, store_names
from cbrs.kb.semantic_map import designate
from cbrs.reasoner.matchmaker import Matchmaker


class _Names:
    """A store's derived prefixes, as :func:`store_names` takes them (kb/derived_prefixes.py)."""

    def __init__(self, prefixes: Mapping[str, str]) -> None:
        self.prefixes = prefixes

    def shorten(self, iri: str) -> str | None:
        return None

    def namespace_of(self, prefix: str) -> str | None:
        return self.prefixes.get(prefix)


@pytest.mark.parametrize(
    ("typed", "prefix", "near"),
    [
        pytest.param("hom:Cup", "hom", ("home",), id="a-letter-left-out"),
        pytest.param("HOME:Cup", "HOME", ("home",), id="case"),
        pytest.param("rq:RobotSelfPosition", "rq", ("req",), id="req"),
        pytest.param("lab_4:Trolley1", "lab_4", (), id="no-scheme-and-nothing-near"),
    ],
)
def test_a_misspelt_prefix_is_refused_naming_the_input_the_prefix_and_the_nearest(
    typed: str, prefix: str, near: tuple[str, ...]
) -> None:
    with pytest.raises(UnknownPrefixError) as refused:
        expand(typed)
    error = refused.value
    assert (error.name, error.prefix) == (typed, prefix)
    assert error.near[: len(near)] == near and (near or not error.near)
    said = str(error)
    assert said.startswith(f"{typed!r} is neither an absolute IRI nor a prefixed name with a known prefix: {prefix}:")
    if near:
        assert f"did you mean {near[0]}:{typed.partition(':')[2]}" in said
    assert isinstance(error, ValueError) and isinstance(error, KnowledgeBaseError) and error.http_status == 400


@pytest.mark.parametrize(
    "iri",
    [
        "urn:uuid:6e8bc430-9c3a-11d9-9669-0800200c9a66",
        "URN:isbn:0451450523",
        "tag:lab.example,2026:cup",
        "mailto:lab@example.org",
        "http://example.org/lab#Cup",
        "https://w3id.org/cbrs/home#Cup",
        "file:///srv/lab/map.ttl",
        "ftp://example.org/map.ttl",
        "did:example:123",
    ],
)
def test_absolute_iris_pass_unchanged(iri: str) -> None:
    assert expand(iri) == iri


def test_any_iri_in_angle_brackets_passes_and_a_declared_or_derived_prefix_wins() -> None:
    assert expand("<hom:Cup>") == "hom:Cup"  # written so on purpose: an IRI of scheme hom
    assert expand("home:Cup") == HOME + "Cup"
    with store_names(_Names({"books": "https://example.org/books#", "urn": "https://example.org/urn#"})):
        assert expand("books:Novel") == "https://example.org/books#Novel"  # was an IRI of scheme books
        assert expand("urn:x") == "https://example.org/urn#x"  # a derived prefix wins over a scheme read bare
        with pytest.raises(UnknownPrefixError, match="did you mean books:Novel"):
            expand("book:Novel")
    with pytest.raises(UnknownPrefixError):
        expand("books:Novel")  # outside a store's names: no prefix of cbrs's


def test_the_library_refuses_it_where_it_takes_a_name(bundled_kb: KnowledgeBase) -> None:
    """A named query's IRI parameter (``[]`` before), a task input's class, the matchmaker's requirement."""
    with pytest.raises(BindingError, match="did you mean home:Cup") as refused:
        bundled_kb.select("things_in_room", {"class": "hom:Cup", "room": "world:Kitchen"})
    assert isinstance(refused.value.__cause__, UnknownPrefixError)
    with pytest.raises(BindingError, match="did you mean home:Cup"):
        designate(bundled_kb, "hom:Cup")
    with pytest.raises(UnknownPrefixError, match="did you mean req:RobotSelfPosition"):
        Matchmaker(bundled_kb).rank("rq:RobotSelfPosition")


def _cli(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args])
    return result.exit_code, result.stderr


@pytest.mark.parametrize(
    ("args", "wanted"),
    [
        pytest.param(["show", "hom:Cup"], "did you mean home:Cup?", id="show"),
        pytest.param(["match", "rq:RobotSelfPosition"], "did you mean req:RobotSelfPosition?", id="match"),
        pytest.param(["deregister", "sv:LocateMobileRobot_CeilingCamera01"], "did you mean svc:", id="deregister"),
        pytest.param(["run", "--fail", "sv:X", "FetchMyPen"], "did you mean svc:X?", id="run-fail"),
    ],
)
def test_the_cli_refuses_a_misspelt_prefix_as_a_usage_error(args: list[str], wanted: str) -> None:
    code, err = _cli(*args)
    assert code == 2, err
    assert "is neither an absolute IRI nor a prefixed name with a known prefix" in err and wanted in err


def test_a_task_with_a_misspelt_prefix_says_what_is_wrong_with_the_prefix() -> None:
    """``cbrs plan`` and ``cbrs run``: the task's did-you-mean of local names, and the prefix's."""
    for command in ("plan", "run"):
        code, err = _cli(command, "rq:FetchMyPen")
        assert code == 1, err
        assert "no requirement or action named 'rq:FetchMyPen'" in err
        assert "rq: is declared nowhere and is no IRI scheme cbrs reads bare; did you mean req:FetchMyPen?" in err


def test_a_page_links_a_stored_iri_of_any_scheme_and_still_refuses_a_slip() -> None:
    """The pages link an IRI they show by its text: the link to a stored ``isbn:0451450523`` answered 400
    once a name of an undeclared prefix was refused; what the store holds is read as itself, a slip that
    names nothing is still refused."""
    from cbrs.sparql_service import SparqlService
    from cbrs.web import create_app

    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "PREFIX rdfs: <http://www.w3.org/2000/01/rdf-schema#> "
        'INSERT DATA { GRAPH <urn:books> { <isbn:0451450523> rdfs:label "The Last Unicorn" } }'
    )
    http = create_app(SparqlService(kb)).test_client()
    found = http.get("/search", query_string={"q": "isbn:0451450523"}, headers={"Accept": "text/html"})
    assert found.status_code in (200, 302, 303)
    page = http.get("/resource", query_string={"iri": "isbn:0451450523"}, headers={"Accept": "text/html"})
    assert page.status_code == 200 and "The Last Unicorn" in page.text
    slip = http.get("/resource", query_string={"iri": "isbm:0451450523"}, headers={"Accept": "text/html"})
    assert slip.status_code == 400 and "isbm: is declared nowhere" in slip.text
