"""cbrs check --graph takes a lab's own named graph (cbrs load --graph IRI) by its IRI, alone or with
cbrs's graphs; it took cbrs's eight graph names only (click refused an IRI). An IRI the store holds no
graph of is refused naming the graphs it does hold, not checked as an empty, consistent graph."""

from __future__ import annotations

import shutil
from pathlib import Path

import owlready2
import pytest
from click.testing import CliRunner

from cbrs.check import NoSuchGraphError, check
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import UnknownGraphError
from cbrs.kb.namespaces import GraphName

needs_java = pytest.mark.skipif(
    shutil.which(str(owlready2.JAVA_EXE)) is None, reason="no Java runtime (apt-get install default-jre-headless)"
)

LAB = "https://example.org/lab/kit"
KIT = """@prefix ex: <http://example.org/check#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
ex:Cup a owl:Class . ex:Plate a owl:Class ; owl:disjointWith ex:Cup .
ex:CupPlate rdfs:subClassOf ex:Cup , ex:Plate .
"""


@pytest.fixture
def lab_store(tmp_path: Path) -> Path:
    """An on-disk store with the kit in the lab's graph (the CLI seeds cbrs's graphs on first use)."""
    (tmp_path / "kit.ttl").write_text(KIT, encoding="utf-8")
    kb = KnowledgeBase.open(str(tmp_path / "store"), seed=False)
    kb.load([tmp_path / "kit.ttl"], graph=LAB)
    kb.close()
    return tmp_path / "store"


@needs_java
def test_a_labs_own_graph_is_checked_by_its_iri(lab_store: Path) -> None:
    result = CliRunner().invoke(cli, ["--store", str(lab_store), "check", "--graph", LAB, "--graph", "ontology"])
    assert result.exit_code == 1, result.output  # the lab's unsatisfiable class: status 1, as for cbrs's own
    first = result.output.splitlines()[0]
    assert first.startswith(f"HermiT (owlready2) over {LAB}, graph:ontology (")
    assert "consistent, 1 unsatisfiable class" in first
    assert "unsatisfiable: check:CupPlate" in result.output  # by the prefix derived for the kit's namespace


def test_an_iri_of_no_graph_is_refused_naming_the_stores_graphs(lab_store: Path, tmp_path: Path) -> None:
    kb = KnowledgeBase.open(str(lab_store), seed=False)
    try:
        with pytest.raises(NoSuchGraphError) as caught:
            check(kb, [GraphName.ONTOLOGY, LAB + "s"])
        assert caught.value.graph == LAB + "s" and caught.value.others == [LAB]
        with pytest.raises(UnknownGraphError):
            check(kb, ["kit"])  # neither a name of cbrs's nor an IRI
    finally:
        kb.close()
    result = CliRunner().invoke(cli, ["--store", str(lab_store), "check", "--graph", LAB + "s"])
    assert result.exit_code == 1
    assert result.output == (
        f"Error: the store holds no graph {LAB}s; check a graph of cbrs's by its name (ontology, services, "
        "requirements, map, world, plans, liveness, entailed) or one of the store's own by its IRI (its graphs "
        f"other than cbrs's own: {LAB}); '{LAB}s': did you mean {LAB}?\n"  # cbrs.graph_names' hint
    )
