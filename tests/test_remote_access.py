"""SERVICE and LOAD reach nothing outside unless allowed: no request turns the server into a proxy,
a port scanner or a file reader (kb.remote_access)."""

from __future__ import annotations

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.remote_access import RemoteAccessError, refuse_remote_access
from cbrs.kb.store import EmbeddedStore

REFUSED = [
    pytest.param("SELECT * WHERE { SERVICE <http://127.0.0.1:9/sparql> { ?s ?p ?o } }", id="service-loopback"),
    pytest.param("select * where { service silent <http://10.0.0.1/x> { ?s ?p ?o } }", id="lower-case-silent"),
    pytest.param("SELECT * WHERE { SERVICE ?endpoint { ?s ?p ?o } VALUES ?endpoint { <http://x/> } }", id="variable"),
    pytest.param("SELECT * WHERE { SERVICE ex:endpoint { ?s ?p ?o } }", id="prefixed-name"),
    pytest.param("LOAD <file:///etc/passwd>", id="load-file"),
    pytest.param("LOAD SILENT <http://127.0.0.1:8080/> INTO GRAPH <urn:g>", id="load-url"),
    pytest.param("# SERVICE in a comment\nSELECT * { SERVICE <http://x/> {} }", id="after-a-comment"),
    pytest.param("SELECT * { FILTER(1<2) SERVICE <http://x/> { ?s ?p ?o } }", id="after-a-less-than"),
]
ALLOWED = [
    pytest.param("SELECT * WHERE { ?service ?load ?o }", id="variables-named-so"),
    pytest.param('SELECT * WHERE { ?s ?p "SERVICE <http://x/> LOAD <file:///etc/passwd>" }', id="in-a-string"),
    pytest.param(
        "SELECT * WHERE { ?s <http://example.org/SERVICE> ?o } # LOAD <file:///x>", id="in-an-iri-and-comment"
    ),
    pytest.param("SELECT * WHERE { ?s ex:service ?o }", id="prefixed-name-named-so"),
]


@pytest.mark.parametrize("text", REFUSED)
def test_service_and_load_are_refused_by_default(text: str) -> None:
    with pytest.raises(RemoteAccessError) as refused:
        refuse_remote_access(text)
    assert "federation_allow" in str(refused.value) and refused.value.http_status == 400


@pytest.mark.parametrize("text", ALLOWED)
def test_the_words_in_strings_iris_comments_and_names_are_not_keywords(text: str) -> None:
    refuse_remote_access(text)


def test_an_allowed_prefix_lets_exactly_its_endpoints_through() -> None:
    allowed = ("https://query.wikidata.org/",)
    refuse_remote_access("SELECT * { SERVICE <https://query.wikidata.org/sparql> { ?s ?p ?o } }", allowed)
    with pytest.raises(RemoteAccessError, match=r"http://127\.0\.0\.1"):
        refuse_remote_access("SELECT * { SERVICE <http://127.0.0.1/sparql> { ?s ?p ?o } }", allowed)


def test_the_store_refuses_before_it_fetches_and_an_update_changes_nothing() -> None:
    store = EmbeddedStore.open(":memory:")
    store.update("INSERT DATA { <urn:a> <urn:p> <urn:b> }")
    before = store.dump()
    with pytest.raises(RemoteAccessError, match="LOAD of <file:///etc/passwd>"):
        store.update("LOAD <file:///etc/passwd> INTO GRAPH <urn:g>")
    with pytest.raises(RemoteAccessError, match="SERVICE"):
        list(store.query("SELECT * WHERE { SERVICE <http://127.0.0.1:9/> { ?s ?p ?o } }"))
    assert store.dump() == before


def test_the_knowledge_base_takes_its_allow_list() -> None:
    kb = KnowledgeBase.open(":memory:", remote_access=("http://127.0.0.1:9/",))
    assert kb.store.remote_access == ("http://127.0.0.1:9/",)
    with pytest.raises(Exception) as failed:  # allowed through the check: Oxigraph tries, and the port is closed
        list(kb.query("SELECT * WHERE { SERVICE <http://127.0.0.1:9/sparql> { ?s ?p ?o } }"))
    assert not isinstance(failed.value, RemoteAccessError)
