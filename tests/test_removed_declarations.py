"""An update that removes the last statement about a term of cbrs's own vocabularies while a class stays
under it is refused, as an insert of that class's axiom is (kb/superclasses.py): a DELETE DATA before it
runs, any other form once it ran and undone whole; unless the same update takes the classes away or
re-points them, or the store is left without the vocabulary. Only an update whose text can reach such a
statement, and whose store holds one in that reach, keeps a copy of the store to be checked."""

from __future__ import annotations

from collections.abc import Iterator

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import PREFIXES, RDF, RDFS
from cbrs.kb.superclasses import Reach, RemovedDeclarationError, removal_reach, watch_update
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

TOKEN = "removed-declarations-token"
LAB = "PREFIX lab: <https://example.org/lab#>\n"
HOME = PREFIXES["home"]
CUP = ox.NamedNode(HOME + "Cup")
# A lab declares home:Fruit (as a lab adds a term to home:, by declaring it) and an apple under it; another
# lab's banana is under it too.
FRUIT = (
    LAB + "INSERT DATA { GRAPH lab:eight { home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject .\n"
    "  lab:Apple rdfs:subClassOf home:Fruit } GRAPH lab:nine { lab:Banana rdfs:subClassOf home:Fruit } }"
)
SAID = r"^the update: it removes the last statement about home:Fruit, and .*#{0} rdfs:subClassOf home:Fruit stays: "


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    found = KnowledgeBase.open(":memory:")
    found.update(FRUIT)
    yield found
    found.close()


def _everything(kb: KnowledgeBase) -> set[ox.Quad]:
    return set(kb.store.quads())


@pytest.mark.parametrize(
    ("text", "user"),
    [
        pytest.param(
            "DELETE DATA { GRAPH lab:eight { home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject } }",
            "Apple",
            id="delete-data",
        ),
        pytest.param("DELETE WHERE { GRAPH lab:eight { home:Fruit ?p ?o } }", "Apple", id="delete-where"),
        pytest.param(
            "DELETE { GRAPH ?g { ?c ?p ?o } } WHERE { GRAPH ?g { ?c a owl:Class ; ?p ?o } FILTER (?c = home:Fruit) }",
            "Apple",
            id="delete-where-variable-subject",
        ),
        pytest.param("DROP GRAPH lab:eight", "Banana", id="drop-graph"),  # the apple goes with its graph
        pytest.param("CLEAR SILENT GRAPH lab:eight", "Banana", id="clear-graph"),
        pytest.param(
            "DELETE WHERE { GRAPH lab:nine { lab:Banana ?p ?o } } ; DELETE WHERE { GRAPH lab:eight { ?s ?p ?o } }",
            None,
            id="two-operations",  # the banana goes, then the apple and home:Fruit with the graph: all of it
        ),
    ],
)
def test_removing_the_last_statement_about_a_term_a_class_is_under_is_refused_and_writes_nothing(
    kb: KnowledgeBase, text: str, user: str | None
) -> None:
    before = _everything(kb)
    if user is None:  # nothing stays under home:Fruit: it passes; put back for the next case
        kb.update(LAB + text)
        assert not kb.query("ASK { ?c rdfs:subClassOf home:Fruit }")
        kb.store.add(before - _everything(kb))
        kb.store.replace(_everything(kb) - before, [])
        assert _everything(kb) == before
        return
    with pytest.raises(RemovedDeclarationError, match=SAID.format(user)) as refused:
        kb.update(LAB + text)
    assert refused.value.superclass == HOME + "Fruit" and refused.value.subclass == f"https://example.org/lab#{user}"
    assert isinstance(refused.value, UndeclaredSuperclassError)  # caught where that one is
    assert str(refused.value).endswith("nothing was written")
    assert _everything(kb) == before


def test_an_update_that_re_points_the_classes_in_the_same_write_passes(kb: KnowledgeBase) -> None:
    before = _everything(kb)
    kb.update(
        LAB + "DELETE { GRAPH ?g { ?c rdfs:subClassOf home:Fruit } GRAPH lab:eight { home:Fruit ?p ?o } }\n"
        "INSERT { GRAPH ?g { ?c rdfs:subClassOf home:Fruits } GRAPH lab:eight { home:Fruits a owl:Class ;\n"
        "  rdfs:subClassOf home:PhysicalObject } }\n"
        "WHERE { { GRAPH ?g { ?c rdfs:subClassOf home:Fruit } } UNION { GRAPH lab:eight { home:Fruit ?p ?o } } }"
    )
    assert kb.query(LAB + "ASK { lab:Banana rdfs:subClassOf home:Fruits . FILTER NOT EXISTS { home:Fruit ?p ?o } }")
    kb.store.replace(_everything(kb) - before, before - _everything(kb))


def test_a_term_declared_elsewhere_too_may_lose_one_statement(kb: KnowledgeBase) -> None:
    label = LAB + "INSERT DATA { GRAPH lab:nine { home:Fruit rdfs:label 'fruit' } }"
    kb.update(label)
    kb.update(LAB + "DELETE WHERE { GRAPH lab:eight { home:Fruit ?p ?o } }")  # lab nine still says something
    with pytest.raises(RemovedDeclarationError):
        kb.update(label.replace("INSERT", "DELETE"))  # now its last statement
    kb.update(
        LAB + "DELETE DATA { GRAPH lab:nine { home:Fruit rdfs:label 'fruit' } } ;\n"
        "INSERT DATA { GRAPH lab:eight { home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject } }"
    )  # replaced in one update: passes


def test_an_update_that_leaves_the_store_without_the_vocabulary_is_not_refused() -> None:
    """As an insert into a store without the home ontology is not: none of its terms counts as undeclared."""
    kb = KnowledgeBase.open(":memory:")
    try:
        kb.update(
            LAB + "INSERT DATA { GRAPH graph:ontology { home:Fruit a owl:Class }\n"
            "  GRAPH lab:eight { lab:Apple rdfs:subClassOf home:Fruit } }"
        )
        with pytest.raises(RemovedDeclarationError):
            kb.update("DELETE DATA { GRAPH graph:ontology { home:Fruit a owl:Class } }")
        kb.update("DROP GRAPH graph:ontology")  # home:Fruit and the vocabulary's header go; the apple stays
        assert kb.query(LAB + "ASK { lab:Apple rdfs:subClassOf home:Fruit }")
    finally:
        kb.close()


@pytest.mark.parametrize(
    ("text", "reach"),
    [
        pytest.param("INSERT DATA { <urn:a> <urn:b> 'DELETE' }", None, id="no-delete"),
        pytest.param("DELETE WHERE { GRAPH graph:map { world:Cup home:yaw ?y } }", None, id="subject-not-ours"),
        pytest.param(
            "DELETE { ?s home:yaw ?y } INSERT { ?s home:yaw 1.5 } WHERE { ?s home:yaw ?y }",
            Reach(statements=frozenset({(None, ox.NamedNode(HOME + "yaw"), None)})),
            id="fixed-predicate",
        ),
        pytest.param(
            "PREFIX h: <https://w3id.org/cbrs/home#> DELETE DATA { h:Cup rdfs:label 'x' ; a owl:Class }",
            Reach(
                statements=frozenset(
                    {(CUP, ox.NamedNode(RDFS + "label"), None), (CUP, ox.NamedNode(RDF + "type"), None)}
                )
            ),
            id="prefix-of-ours",
        ),
        pytest.param(
            "WITH <urn:g> DELETE { ?s rdfs:label ?l } WHERE { ?s rdfs:label ?l } ;\n"
            "DELETE WHERE { GRAPH <urn:h> { ?s rdfs:label ?l } GRAPH ?g { ?s a ?c } }",
            Reach(
                statements=frozenset(
                    {
                        (None, ox.NamedNode(RDFS + "label"), ox.NamedNode("urn:g")),
                        (None, ox.NamedNode(RDFS + "label"), ox.NamedNode("urn:h")),
                        (None, ox.NamedNode(RDF + "type"), None),
                    }
                )
            ),
            id="graphs-of-statements",
        ),
        pytest.param("DELETE WHERE { home:Cup ?p ?o }", Reach(anything=True), id="variable-predicate"),
        pytest.param("DELETE WHERE { [] home:p ?o }", Reach(anything=True), id="blank-node"),
        pytest.param("DELETE WHERE { ?s home:y\\u0061w ?o }", Reach(anything=True), id="escape"),
        pytest.param("CLEAR ALL", Reach(anything=True), id="clear-all"),
        pytest.param(
            "DROP SILENT GRAPH graph:map", Reach(graphs=frozenset({ox.NamedNode(PREFIXES["graph"] + "map")})), id="drop"
        ),
        pytest.param(
            "MOVE <urn:a> TO GRAPH <urn:b>",
            Reach(graphs=frozenset({ox.NamedNode("urn:a"), ox.NamedNode("urn:b")})),
            id="move",
        ),
        pytest.param("COPY DEFAULT TO <urn:b>", Reach(graphs=frozenset({ox.NamedNode("urn:b")})), id="copy"),
        pytest.param("ADD <urn:a> TO <urn:b>", None, id="add"),
    ],
)
def test_the_text_says_what_an_update_may_remove(text: str, reach: Reach | None) -> None:
    assert removal_reach(text) == reach


@pytest.mark.parametrize(
    ("text", "watched"),
    [
        pytest.param("DELETE { ?s home:yaw ?y } WHERE { ?s home:yaw ?y }", False, id="a-predicate-no-class-has"),
        pytest.param("DELETE WHERE { ?s rdfs:label ?l }", True, id="a-predicate-classes-have"),
        pytest.param(
            "DELETE WHERE { GRAPH <https://example.org/lab#nine> { ?s rdfs:label ?l } }",
            False,
            id="a-predicate-classes-have-in-a-graph-saying-nothing-of-them",
        ),
        pytest.param(
            "DELETE WHERE { GRAPH graph:ontology { ?s rdfs:label ?l } }", True, id="a-predicate-classes-have-there"
        ),
        pytest.param(
            "DELETE WHERE { GRAPH graph:ontology { home:Bowl rdfs:comment ?c } }", False, id="a-term-no-class-is-under"
        ),
        pytest.param(
            "DELETE WHERE { GRAPH graph:ontology { home:Container rdfs:comment ?c } }",
            True,
            id="a-term-classes-are-under",
        ),
        pytest.param("DROP GRAPH graph:map", False, id="a-graph-saying-nothing-of-them"),
        pytest.param("DROP GRAPH graph:ontology", True, id="the-ontology"),
        pytest.param("DELETE WHERE { GRAPH graph:map { world:Cup ?p ?o } }", False, id="not-ours"),
    ],
)
def test_only_an_update_reaching_a_statement_about_a_used_term_is_watched(
    kb: KnowledgeBase, text: str, watched: bool
) -> None:
    """A watched update keeps a copy of the store to be undone; the rest pay one query at most."""
    watch = watch_update(kb.store, text)
    assert (watch is not None) is watched
    if watch is not None:
        assert ox.NamedNode(HOME + "PhysicalObject") in watch.declared


def test_the_update_endpoint_refuses_it_with_a_400_and_keeps_the_store(kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN))).test_client()
    before = _everything(kb)
    response = client.post(
        "/update",
        data=(LAB + "DROP GRAPH lab:eight").encode(),
        content_type="application/sparql-update",
        headers={"Authorization": f"Bearer {TOKEN}"},
    )
    assert response.status_code == 400
    body = response.get_json()
    assert body["error"] == "RemovedDeclarationError" and "Banana rdfs:subClassOf home:Fruit stays" in body["message"]
    assert _everything(kb) == before


def test_an_insert_data_whose_declaration_the_same_update_deletes_is_refused(kb: KnowledgeBase) -> None:
    """Each quad is checked as the last operation naming it leaves it: before, the declaration inserted
    counted though a later DELETE DATA of the same update took it away again."""
    before = _everything(kb)
    with pytest.raises(
        UndeclaredSuperclassError, match=r"Pear rdfs:subClassOf home:Pome: home:Pome is declared nowhere"
    ):
        kb.update(
            LAB + "INSERT DATA { GRAPH lab:eight { home:Pome a owl:Class . lab:Pear rdfs:subClassOf home:Pome } } ;\n"
            "DELETE DATA { GRAPH lab:eight { home:Pome a owl:Class } }"
        )
    assert _everything(kb) == before
