"""A class put under a term of cbrs's own vocabularies that nothing declares is refused in an update of any
form, as a load and an INSERT DATA refuse it (kb/superclasses.py): an INSERT ... WHERE and a DELETE/INSERT
... WHERE are checked once they ran and undone whole, through the library, /update and ``cbrs update
--file``; an update that cannot add a subclass axiom is not checked (the text says so: may_add_subclasses)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import PREFIXES, RDFS
from cbrs.kb.superclasses import may_add_subclasses
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

TOKEN = "update-superclasses-token"
LAB = "https://example.org/lab#"
# An apple put under home:Fruit, which the home ontology does not declare, by a WHERE that binds it.
APPLE_UNDER_FRUIT = (
    "INSERT { GRAPH graph:ontology { ?apple rdfs:subClassOf home:Fruit } }\n"
    "WHERE { BIND (<https://example.org/lab#Apple> AS ?apple) }"
)
# The cup turned and, in the same update, an apple put under a misspelt bowl: all of it refused.
TURN_CUP_AND_MISSPELL = (
    "DELETE { GRAPH graph:map { world:Cup home:yaw ?yaw } }\n"
    "INSERT { GRAPH graph:map { world:Cup home:yaw 1.5 } GRAPH graph:ontology { ?apple rdfs:subClassOf home:Bowll } }\n"
    "WHERE { GRAPH graph:map { world:Cup home:yaw ?yaw } BIND (<https://example.org/lab#Apple> AS ?apple) }"
)
SAID = r"^the update: .*Apple rdfs:subClassOf home:{0}: home:{0} is declared nowhere .*nothing was written$"


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    found = KnowledgeBase.open(":memory:")
    yield found
    found.close()


def _everything(kb: KnowledgeBase) -> set[ox.Quad]:
    return set(kb.store.quads())


def test_an_insert_where_is_refused_as_insert_data_is_and_writes_nothing(kb: KnowledgeBase) -> None:
    before = _everything(kb)
    with pytest.raises(UndeclaredSuperclassError, match=SAID.format("Fruit")) as refused:
        kb.update(APPLE_UNDER_FRUIT)
    assert refused.value.subclass == LAB + "Apple" and refused.value.superclass == PREFIXES["home"] + "Fruit"
    assert _everything(kb) == before
    data = "INSERT DATA { GRAPH graph:ontology { <https://example.org/lab#Apple> rdfs:subClassOf home:Fruit } }"
    with pytest.raises(UndeclaredSuperclassError) as as_data:
        kb.update(data)
    assert str(as_data.value) == str(refused.value)  # the same words, whatever the update's form


def test_a_delete_insert_where_is_undone_whole_with_a_did_you_mean(kb: KnowledgeBase) -> None:
    before = _everything(kb)
    assert kb.query("ASK { GRAPH graph:map { world:Cup home:yaw ?yaw } }")
    with pytest.raises(UndeclaredSuperclassError, match=SAID.format("Bowll")) as refused:
        kb.update_counted(TURN_CUP_AND_MISSPELL)
    assert "did you mean home:Bowl?" in str(refused.value)
    assert _everything(kb) == before  # the cup's yaw too: deleted and re-inserted, then put back


def test_a_superclass_declared_in_the_same_update_or_already_is_let_in(kb: KnowledgeBase) -> None:
    kb.update(
        "INSERT { GRAPH graph:ontology { home:Pome a owl:Class ; rdfs:subClassOf home:PhysicalObject .\n"
        "  ?pear rdfs:subClassOf home:Pome . ?quince rdfs:subClassOf home:Cup } }\n"
        "WHERE { BIND (<https://example.org/lab#Pear> AS ?pear) BIND (<https://example.org/lab#Quince> AS ?quince) }"
    )
    assert kb.query("ASK { <https://example.org/lab#Pear> rdfs:subClassOf+ home:PhysicalObject }")
    assert kb.query("ASK { <https://example.org/lab#Quince> rdfs:subClassOf home:Cup }")


def test_a_subclass_axiom_copied_by_a_variable_predicate_is_checked(kb: KnowledgeBase) -> None:
    """The text never names rdfs:subClassOf: the axiom comes from the store (written there past the checks,
    as a store seeded without the vocabulary could hold it), copied to a new class."""
    ontology = ox.NamedNode("https://w3id.org/cbrs/graph/ontology")
    slipped = ox.Quad(
        ox.NamedNode(LAB + "Plum"),
        ox.NamedNode(RDFS + "subClassOf"),
        ox.NamedNode(PREFIXES["home"] + "Fruit"),
        ontology,
    )
    kb.store.add([slipped])
    try:
        before = _everything(kb)
        copy = (
            "INSERT { GRAPH graph:ontology { <https://example.org/lab#Sloe> ?p ?o } }\n"
            "WHERE { GRAPH graph:ontology { <https://example.org/lab#Plum> ?p ?o } }"
        )
        with pytest.raises(UndeclaredSuperclassError, match=r"Sloe rdfs:subClassOf home:Fruit"):
            kb.update(copy)
        assert _everything(kb) == before
    finally:
        kb.store.replace([slipped], [])


@pytest.mark.parametrize(
    ("text", "may"),
    [
        pytest.param("INSERT { ?c rdfs:subClassOf ?d } WHERE { ?c a ?d }", True, id="named"),
        pytest.param("INSERT { ?c <http://www.w3.org/2000/01/rdf-schema#subClassOf> ?d } WHERE {}", True, id="iri"),
        pytest.param(
            "PREFIX r: <http://www.w3.org/2000/01/rdf-schema#sub> INSERT { ?c r:ClassOf ?d } WHERE {}", True, id="split"
        ),
        pytest.param("INSERT { ?c rdfs:sub\\u0043lassOf ?d } WHERE {}", True, id="escape"),
        pytest.param("INSERT { ?s ?p ?o } WHERE { ?s ?p ?o }", True, id="variable"),
        pytest.param("INSERT { ?s home:p ?o ; ?p ?o } WHERE {}", True, id="variable-after-semicolon"),
        pytest.param("INSERT { [ home:p ?o ] ?p ?o } WHERE {}", True, id="variable-after-blank-node"),
        pytest.param("INSERT { ?s home:p ( ?a [ ?p ?o ] ) } WHERE {}", True, id="variable-in-a-collection"),
        pytest.param("COPY graph:ontology TO <urn:copy>", True, id="copy"),
        pytest.param("INSERT { ?s home:p ?o WHERE { ?s ?p ?o }", True, id="unclosed"),
        pytest.param(
            "DELETE { ?s home:yaw ?y } INSERT { ?s home:yaw 1.5 } WHERE { ?s home:yaw ?y }", False, id="fixed"
        ),
        pytest.param("INSERT { ?s a ?c ; home:p ?o , 'x'@en , '1'^^xsd:int } WHERE { ?s ?p ?o }", False, id="objects"),
        pytest.param("INSERT { GRAPH ?g { ?s home:p ?o . } } WHERE { GRAPH ?g { ?s ?p ?o } }", False, id="graph"),
        pytest.param("INSERT { ?s home:p '} ?p ?o' } # ?s ?p ?o\nWHERE {}", False, id="hidden"),
        pytest.param("CLEAR GRAPH graph:plans", False, id="clear"),
    ],
)
def test_only_an_update_that_may_add_a_subclass_axiom_is_checked(text: str, may: bool) -> None:
    assert may_add_subclasses(text) is may


def test_the_update_endpoint_refuses_it_with_a_400_and_keeps_the_store(kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN))).test_client()
    before = _everything(kb)
    response = client.post(
        "/update",
        data=TURN_CUP_AND_MISSPELL.encode(),
        content_type="application/sparql-update",
        headers={"Authorization": f"Bearer {TOKEN}"},
    )
    assert response.status_code == 400
    body = response.get_json()
    assert body["error"] == "UndeclaredSuperclassError" and "did you mean home:Bowl?" in body["message"]
    assert _everything(kb) == before


def test_cbrs_update_file_refuses_it(tmp_path: Path) -> None:
    text = tmp_path / "apple.ru"
    text.write_text(APPLE_UNDER_FRUIT, encoding="utf-8")
    refused = CliRunner().invoke(cli, ["--store", ":memory:", "update", "--file", str(text)])
    assert refused.exit_code != 0
    assert "home:Fruit is declared nowhere" in refused.stderr and "nothing was written" in refused.stderr
    fixed = tmp_path / "apple_fixed.ru"
    fixed.write_text(APPLE_UNDER_FRUIT.replace("home:Fruit", "home:PhysicalObject"), encoding="utf-8")
    written = CliRunner().invoke(cli, ["--store", ":memory:", "update", "--file", str(fixed)])
    assert written.exit_code == 0 and "graph:ontology: +1" in written.stdout
