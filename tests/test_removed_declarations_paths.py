"""The paths that replace statements wholesale keep every class under a declared term of cbrs's own
vocabularies, as an update or a Graph Store write does (kb/superclasses.py): ``cbrs load --graph map
--replace`` (kb/loader.py), ``cbrs restore`` (kb/backup.py: a whole restore checks the file by itself,
one of some graphs the change it makes) and a Graph Store ``PUT`` of a named graph, which reads
declarations in every graph as the server's queries read the union. Each refusal names the term and a class
under it, and leaves the store's N-Quads as they were."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import UndeclaredSuperclassError
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.superclasses import RemovedDeclarationError
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

HOME_FILE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "studio_flat" / "home.ttl"
HOME = PREFIXES["home"]
FRUIT = ox.NamedNode(HOME + "Fruit")
EIGHT, NINE = "https://example.org/lab#eight", "https://example.org/lab#nine"
TURTLE_PREFIXES = (
    "@prefix home: <https://w3id.org/cbrs/home#> . @prefix lab: <https://example.org/lab#> .\n"
    "@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
)
DECLARED = TURTLE_PREFIXES + "home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject .\n"
BANANA = TURTLE_PREFIXES + "lab:Banana rdfs:subClassOf home:Fruit .\n"
APPLE = TURTLE_PREFIXES + "lab:Apple rdfs:subClassOf home:Fruit .\n"
# A lab declares home:Fruit in graph lab:eight; another's banana is under it, in lab:nine.
LAB_FRUIT = (
    "PREFIX lab: <https://example.org/lab#>\n"
    "INSERT DATA { GRAPH lab:eight { home:Fruit a owl:Class ; rdfs:subClassOf home:PhysicalObject }\n"
    "  GRAPH lab:nine { lab:Banana rdfs:subClassOf home:Fruit } }"
)
TOKEN = "removed-declarations-paths-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


def _file(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


# -- cbrs load --graph map --replace ----------------------------------------------------------------


def test_a_map_replaced_without_the_declaration_a_class_needs_is_refused(tmp_path: Path) -> None:
    """The lab's home declared home:Fruit in graph:map; a new home without it would leave the banana under
    a term declared nowhere (before, it was loaded). A class of the new files under a term only the old map
    declared is refused too (before, the files' check read the old map as staying)."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([HOME_FILE, _file(tmp_path, "fruit.ttl", DECLARED)], graph="map", replace=True)
    apple = kb.store.dump()
    with pytest.raises(UndeclaredSuperclassError, match=r"Apple rdfs:subClassOf home:Fruit: home:Fruit is") as new:
        kb.load([HOME_FILE, _file(tmp_path, "apple.ttl", APPLE)], graph="map", replace=True)
    assert not isinstance(new.value, RemovedDeclarationError)
    assert str(new.value).endswith("nothing was loaded and graph:map is as it was")
    assert kb.store.dump() == apple

    kb.load([_file(tmp_path, "banana.ttl", BANANA)], graph=NINE)
    before = kb.store.dump()
    with pytest.raises(RemovedDeclarationError) as removed:
        kb.load([HOME_FILE], graph="map", replace=True)
    said = str(removed.value)
    assert said.startswith(f"the load of {HOME_FILE} replacing graph:map: it removes the last statement about")
    assert "home:Fruit, and https://example.org/lab#Banana rdfs:subClassOf home:Fruit stays" in said
    assert removed.value.superclass == FRUIT.value and removed.value.subclass.endswith("#Banana")
    assert kb.store.dump() == before
    # with the declaration in the new files (or anywhere else), the home is replaced
    kb.load([HOME_FILE, tmp_path / "fruit.ttl"], graph="map", replace=True)
    assert any(kb.store.quads(FRUIT, graph=GraphName.MAP.node))
    kb.close()


def test_the_cli_says_which_term_and_class(tmp_path: Path) -> None:
    location = str(tmp_path / "store")
    fruit, banana = _file(tmp_path, "fruit.ttl", DECLARED), _file(tmp_path, "banana.ttl", BANANA)
    runner = CliRunner()
    for args in (["--replace", str(HOME_FILE), str(fruit)], ["--graph", NINE, str(banana)]):
        graph = [] if "--graph" in args else ["--graph", "map"]
        done = runner.invoke(cli, ["--store", location, "load", *graph, *args])
        assert done.exit_code == 0, done.output
    refused = runner.invoke(cli, ["--store", location, "load", "--graph", "map", "--replace", str(HOME_FILE)])
    assert refused.exit_code != 0
    assert "it removes the last statement about home:Fruit" in refused.output


# -- cbrs restore -----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def exports(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two exports of a store with the lab's fruit: ``whole`` as the checks keep it, ``broken`` with the
    declaration taken out behind their back (an older cbrs, a file edited by hand)."""
    folder = tmp_path_factory.mktemp("exports")
    kb = KnowledgeBase.open(":memory:")
    kb.update(LAB_FRUIT)
    kb.export(folder / "whole.nq")
    kb.store.replace(list(kb.store.quads(FRUIT, graph=ox.NamedNode(EIGHT))), [])
    kb.export(folder / "broken.nq")
    kb.close()
    return {"whole": folder / "whole.nq", "broken": folder / "broken.nq"}


@pytest.fixture
def fruit() -> Iterator[KnowledgeBase]:
    """A store that declares home:Fruit, with the banana under it."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(LAB_FRUIT)
    yield kb
    kb.close()


def test_a_whole_restore_of_a_file_holding_a_class_under_a_term_it_does_not_declare_is_refused(
    exports: dict[str, Path], fruit: KnowledgeBase
) -> None:
    before = fruit.store.dump()
    with pytest.raises(RemovedDeclarationError) as refused:
        fruit.restore(exports["broken"])
    said = str(refused.value)
    assert said.startswith(f"the restore of {exports['broken']}: it removes the last statement about home:Fruit")
    assert "lab#Banana rdfs:subClassOf home:Fruit stays" in said
    assert said.endswith("nothing was restored (cbrs restore --force takes the file as it is)")
    assert fruit.store.dump() == before


def test_a_whole_restore_is_checked_by_the_file_alone(exports: dict[str, Path]) -> None:
    """Into a store that never declared home:Fruit the same file is a class under an undeclared term; the
    export of a store the checks kept restores into one that lacks its terms; --force takes any file."""
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(UndeclaredSuperclassError, match=r"Banana rdfs:subClassOf home:Fruit: home:Fruit is") as new:
        kb.restore(exports["broken"])
    assert not isinstance(new.value, RemovedDeclarationError) and kb.store.dump() == before
    kb.restore(exports["whole"])
    assert any(kb.store.quads(FRUIT))
    kb.restore(exports["broken"], force=True)
    assert not any(kb.store.quads(FRUIT)) and any(kb.store.quads(predicate=None, object=FRUIT))
    kb.close()


def test_a_restore_of_some_graphs_is_checked_against_the_rest_of_the_store(
    exports: dict[str, Path], fruit: KnowledgeBase
) -> None:
    """lab:eight from the broken file takes the declaration out while lab:nine's banana stays: refused;
    lab:nine alone changes nothing declared, and lab:eight from the whole file puts it back as it was."""
    before = fruit.store.dump()
    with pytest.raises(RemovedDeclarationError, match=r"^the restore of .*broken\.nq: it removes the last statement"):
        fruit.restore(exports["broken"], graphs=[EIGHT])
    assert fruit.store.dump() == before
    fruit.restore(exports["broken"], graphs=[NINE])
    fruit.restore(exports["whole"], graphs=[EIGHT])
    assert fruit.store.dump() == before


def test_the_restore_command_refuses_it(exports: dict[str, Path], tmp_path: Path) -> None:
    location = str(tmp_path / "store")
    runner = CliRunner()
    assert runner.invoke(cli, ["--store", location, "update", LAB_FRUIT]).exit_code == 0
    refused = runner.invoke(cli, ["--store", location, "restore", "--yes", str(exports["broken"])])
    assert refused.exit_code != 0
    assert "it removes the last statement about home:Fruit" in refused.output
    assert "nothing was restored" in refused.output
    new = tmp_path / "new-store"  # refused before a store is made there, as a file that is no export is
    into_new = runner.invoke(cli, ["--store", str(new), "restore", "--yes", str(exports["broken"])])
    assert into_new.exit_code != 0 and "home:Fruit is declared nowhere" in into_new.output
    assert not new.exists()


# -- the Graph Store, a PUT of a named graph ---------------------------------------------------------


def test_a_put_counts_the_same_statement_in_another_graph_as_the_union_reads_it() -> None:
    """home:Fruit's declaration is in lab:eight and, the very same triple, in graph:ontology. A PUT of
    lab:eight without it leaves the declaration the server's queries read (their default graph is the union
    of the graphs), so it passes; a PUT of graph:ontology without it then leaves none, and is refused."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(LAB_FRUIT)
    kb.update("INSERT DATA { GRAPH graph:ontology { home:Fruit a owl:Class } }")
    client = create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN))).test_client()
    turtle = "text/turtle"
    emptied = client.put(
        f"/store?graph={quote(EIGHT, safe='')}", data=TURTLE_PREFIXES, content_type=turtle, headers=AUTH
    )
    assert emptied.status_code == 204, emptied.data
    ontology = [q for q in kb.store.quads(graph=GraphName.ONTOLOGY.node) if q.subject != FRUIT]
    body = ox.serialize([ox.Triple(q.subject, q.predicate, q.object) for q in ontology], format=ox.RdfFormat.N_TRIPLES)
    before = kb.store.dump()
    put = client.put(
        f"/store?graph={GraphName.ONTOLOGY.iri}", data=body, content_type="application/n-triples", headers=AUTH
    )
    assert put.status_code == 400 and put.get_json()["error"] == "RemovedDeclarationError", put.data
    assert (
        "home:Fruit, and https://example.org/lab#Banana rdfs:subClassOf home:Fruit stays" in put.get_json()["message"]
    )
    assert kb.store.dump() == before
    kb.close()
