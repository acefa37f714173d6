"""cbrs check --write-inferred: HermiT's conclusions that the store does not already say go into graph:inferred,
all or nothing, idempotent, replaced wholesale, refused over inconsistent graphs. Before it, nothing HermiT
concluded reached the store: ``ASK { ex:box1 a ex:LiddedContainer }`` was false however often cbrs check ran.

Each HermiT run takes about a second on these unseeded stores; the written store is shared by the module."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import owlready2
import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.check import JVM_OPTIONS, CheckResult, WriteRefusedError, check, write_inferred
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.inferred import INFERRED, InferredGraph, replace_inferred
from cbrs.kb.namespaces import OWL, RDF, RDFS, GraphName

pytestmark = pytest.mark.skipif(
    shutil.which(str(owlready2.JAVA_EXE)) is None, reason="no Java runtime (apt-get install default-jre-headless)"
)

EX = "http://example.org/lids#"
# ex:LiddedContainer is defined (an equivalent class with a restriction). HermiT alone finds that ex:Jar is
# below it (a jar is a container with some lid) and that ex:box1 is one (a container with a lid); ex:Jar is
# also an individual (punning), whose subclass must not be written as a type. ex:pot1 is one as box1 is.
ONTOLOGY = """@prefix ex: <http://example.org/lids#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
ex:Container a owl:Class . ex:Lid a owl:Class . ex:hasLid a owl:ObjectProperty .
ex:LiddedContainer a owl:Class ; owl:equivalentClass [ a owl:Class ; owl:intersectionOf ( ex:Container
    [ a owl:Restriction ; owl:onProperty ex:hasLid ; owl:someValuesFrom ex:Lid ] ) ] .
ex:Jar a owl:Class , owl:NamedIndividual ; rdfs:subClassOf ex:Container ,
    [ a owl:Restriction ; owl:onProperty ex:hasLid ; owl:someValuesFrom ex:Lid ] .
ex:box1 a owl:NamedIndividual , ex:Container ; ex:hasLid ex:lid1 .
ex:lid1 a owl:NamedIndividual , ex:Lid .
ex:pot1 a owl:NamedIndividual , ex:Container ; ex:hasLid ex:lid1 .
ex:jar1 a owl:NamedIndividual , ex:Jar .
"""
INCONSISTENT = "ex:Lid owl:disjointWith ex:Container . ex:lid1 a ex:Container .\n"
UNSATISFIABLE = "ex:Lid owl:disjointWith ex:Container . ex:LidBox rdfs:subClassOf ex:Lid , ex:Container .\n"


Written = tuple[KnowledgeBase, CheckResult, InferredGraph]


def triple(subject: str, predicate: str, obj: str) -> tuple[str, str, str]:
    return (EX + subject, predicate, EX + obj)


WRITTEN = {
    triple("Jar", RDFS + "subClassOf", "LiddedContainer"),
    triple("LiddedContainer", RDFS + "subClassOf", "Container"),
    triple("box1", RDF + "type", "LiddedContainer"),
    triple("pot1", RDF + "type", "LiddedContainer"),
}
BOX1_LOSES_ITS_LID = (
    "DELETE DATA { GRAPH <https://w3id.org/cbrs/graph/ontology> "
    "{ <http://example.org/lids#box1> <http://example.org/lids#hasLid> <http://example.org/lids#lid1> } }"
)
LIDDED = ox.NamedNode(EX + "LiddedContainer")
POT1 = ox.Triple(ox.NamedNode(EX + "pot1"), ox.NamedNode(RDF + "type"), LIDDED)
ELSEWHERE = ox.NamedNode("https://example.org/lab/said")


def small_kb(folder: Path, extra: str = "") -> KnowledgeBase:
    """An unseeded in-memory store holding the ontology (and ``extra``) in graph:ontology."""
    path = folder / "lids.ttl"
    path.write_text(ONTOLOGY + extra, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:", seed=False)
    kb.load([path], graph=GraphName.ONTOLOGY)
    return kb


def inferred(kb: KnowledgeBase) -> set[tuple[str, str, str]]:
    return {(str(q.subject)[1:-1], q.predicate.value, str(q.object)[1:-1]) for q in kb.store.quads(graph=INFERRED)}


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Written]:
    """The ontology's store after one write-back, pot1's type stated in a graph of the lab's before it."""
    kb = small_kb(tmp_path_factory.mktemp("lids"))
    kb.store.add([ox.Quad(POT1.subject, POT1.predicate, POT1.object, ELSEWHERE)])
    result, report = write_inferred(kb)
    assert result.ok
    yield kb, result, report
    kb.close()


def test_hermits_new_subclasses_and_types_are_written_to_graph_inferred(written: Written) -> None:
    kb, result, report = written
    assert inferred(kb) == WRITTEN - {triple("pot1", RDF + "type", "LiddedContainer")}  # stated elsewhere
    assert (report.holds, report.added, report.removed) == (3, 3, 0)
    assert report.already_said > 0  # jar1 a Jar, Jar below Container, pot1's type
    seen = kb.query("ASK { ?thing a ?class }", {"thing": ox.NamedNode(EX + "pot1"), "class": LIDDED})
    assert isinstance(seen, ox.QueryBoolean) and bool(seen)  # pot1 stated elsewhere: the query reads the union
    box1 = kb.query("ASK { ?thing a ?class }", {"thing": ox.NamedNode(EX + "box1"), "class": LIDDED})
    assert isinstance(box1, ox.QueryBoolean) and bool(box1)  # SPARQL sees the conclusion
    assert not bool(kb.query("ASK { ?thing a ?class }", {"thing": ox.NamedNode(EX + "box2"), "class": LIDDED}))
    assert not inferred(kb) & {triple("Jar", RDF + "type", "LiddedContainer"), triple("Jar", RDF + "type", "Container")}
    named = {str(term)[1:-1] for t in result.conclusions for term in (t.subject, t.object)}
    assert not any(iri.startswith(OWL) or "/.well-known/genid/" in iri for iri in named)  # no owl:Thing, no restriction


def test_a_second_write_back_adds_nothing(written: Written) -> None:
    kb, _, _ = written
    _, again = write_inferred(kb)
    assert not again.changed and (again.added, again.removed, again.holds) == (0, 0, 3)
    assert inferred(kb) == WRITTEN - {triple("pot1", RDF + "type", "LiddedContainer")}


def test_the_next_write_back_replaces_the_graph_wholesale(tmp_path: Path) -> None:
    kb = small_kb(tmp_path)
    write_inferred(kb)
    kb.update(BOX1_LOSES_ITS_LID)
    _, report = write_inferred(kb)  # box1 has no lid now: it is no lidded container
    assert inferred(kb) == WRITTEN - {triple("box1", RDF + "type", "LiddedContainer")}
    assert (report.added, report.removed, report.holds) == (0, 1, 3)


@pytest.mark.parametrize(
    ("extra", "why"), [(INCONSISTENT, "they are inconsistent"), (UNSATISFIABLE, "1 class is unsatisfiable (")]
)
def test_inconsistent_or_unsatisfiable_graphs_are_refused_and_nothing_is_written(
    tmp_path: Path, extra: str, why: str
) -> None:
    kb = small_kb(tmp_path, extra)
    kept = ox.Quad(ox.NamedNode(EX + "earlier"), ox.NamedNode(RDF + "type"), ox.NamedNode(EX + "Lid"), INFERRED)
    kb.store.add([kept])  # what an earlier write-back left stays
    with pytest.raises(WriteRefusedError) as caught:
        write_inferred(kb)
    assert why in str(caught.value) and "nothing was written" in str(caught.value)
    assert caught.value.result.ok is False
    assert list(kb.store.quads(graph=INFERRED)) == [kept]


def test_the_cli_writes_then_says_unchanged_and_refuses_with_an_error(tmp_path: Path) -> None:
    lab = "https://example.org/lab/lids"
    (tmp_path / "lids.ttl").write_text(ONTOLOGY, encoding="utf-8")
    (tmp_path / "bad.ttl").write_text(
        "@prefix ex: <http://example.org/lids#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .\n" + INCONSISTENT,
        encoding="utf-8",
    )
    kb = KnowledgeBase.open(str(tmp_path / "store"), seed=False)
    kb.load([tmp_path / "lids.ttl"], graph=lab)
    kb.close()
    store = ["--store", str(tmp_path / "store")]
    first = CliRunner().invoke(cli, [*store, "check", "--graph", lab, "--write-inferred"])
    assert first.exit_code == 0, first.output
    assert first.output.splitlines()[1].startswith("graph:inferred: 4 conclusions (4 added, 0 removed; ")
    second = CliRunner().invoke(cli, [*store, "check", "--graph", lab, "--write-inferred", "--json"])
    assert second.exit_code == 0, second.output
    assert '"holds": 4' in second.output and '"added": 0' in second.output
    assert CliRunner().invoke(cli, [*store, "load", "--graph", lab, str(tmp_path / "bad.ttl")]).exit_code == 0
    refused = CliRunner().invoke(cli, [*store, "check", "--graph", lab, "--write-inferred"])
    assert refused.exit_code == 1
    assert refused.output.startswith(f"Error: HermiT's conclusions over {lab} were not written to graph:inferred")
    kb = KnowledgeBase.open(str(tmp_path / "store"))
    assert inferred(kb) == WRITTEN
    kb.close()


@pytest.mark.parametrize("own", [None, "-Xss2m"])
def test_hermit_runs_on_the_quick_jvm_options_then_the_users_own(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, own: str | None
) -> None:
    """The client compiler and the serial collector halve a short check; a user's own JDK_JAVA_OPTIONS
    follows them, so it wins. They go in HermiT's environment only (this process's is as it was)."""
    if own is None:
        monkeypatch.delenv("JDK_JAVA_OPTIONS", raising=False)
    else:
        monkeypatch.setenv("JDK_JAVA_OPTIONS", own)
    seen: list[str | None] = []
    popen = subprocess.Popen

    def recorded(*args: Any, **kwargs: Any) -> Any:
        seen.append(kwargs["env"].get("JDK_JAVA_OPTIONS"))
        return popen(*args, **kwargs)

    monkeypatch.setattr(subprocess, "Popen", recorded)
    assert check(small_kb(tmp_path)).consistent
    assert seen == [" ".join([*JVM_OPTIONS, *([own] if own else [])])]
    assert os.environ.get("JDK_JAVA_OPTIONS") == own


def test_what_graph_entailed_holds_is_not_written_again(tmp_path: Path) -> None:
    """No HermiT run: the conclusions handed over directly, one of them in graph:entailed already."""
    kb = KnowledgeBase.open(":memory:", seed=False)
    box1 = ox.Triple(ox.NamedNode(EX + "box1"), ox.NamedNode(RDF + "type"), ox.NamedNode(EX + "LiddedContainer"))
    kb.store.add([ox.Quad(POT1.subject, POT1.predicate, POT1.object, GraphName.ENTAILED.node)])
    report = replace_inferred(kb, [box1, POT1, box1])
    assert inferred(kb) == {triple("box1", RDF + "type", "LiddedContainer")}
    assert (report.holds, report.added, report.already_said) == (1, 1, 1)
    with pytest.raises(ValueError, match="types, subclasses, subproperties and equivalences only"):
        replace_inferred(kb, [ox.Triple(box1.subject, ox.NamedNode(EX + "hasLid"), box1.object)])


def test_an_equivalence_only_hermit_finds_is_written_once(tmp_path: Path) -> None:
    """Two classes defined by the same restriction: HermiT names them equivalent, both ways round."""
    same = "[ a owl:Restriction ; owl:onProperty ex:hasLid ; owl:someValuesFrom ex:Lid ]"
    kb = small_kb(tmp_path, f"ex:Closed owl:equivalentClass {same} .\nex:WithLid owl:equivalentClass {same} .\n")
    write_inferred(kb)
    equivalences = {t for t in inferred(kb) if t[1] == OWL + "equivalentClass"}
    assert equivalences == {triple("Closed", OWL + "equivalentClass", "WithLid")}
