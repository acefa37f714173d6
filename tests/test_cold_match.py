"""``cbrs match`` in a fresh process over an on-disk store ranks as the same match in memory, and the
reader's one-pass reads (every description, every part tree) give what one query per description or
concept gives (issue 18; the figures are bench/cold_match.py's)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, descriptions
from cbrs.kb.catalog import Catalogue
from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import Term
from cbrs.reasoner.matchmaker import Matchmaker

pytestmark = pytest.mark.both_stores

OWLS = Path(__file__).parent / "data" / "owls"
SHARED = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
PER_DESCRIPTION = (*descriptions.PER_DESCRIPTION, "description_model")  # and the OWL-S model's link


def _key(row: dict[str, Term]) -> tuple[tuple[str, str], ...]:
    return tuple(sorted((name, str(term)) for name, term in row.items()))


def _descriptions(kb: KnowledgeBase) -> list[str]:
    rows = [*kb.select("advertisements"), *kb.select("requirements")]
    return sorted({(row.get("service") or row["requirement"]).value for row in rows})


def test_every_value_at_once_gives_each_value_its_own_rows(fresh_bundled_kb: KnowledgeBase) -> None:
    """select_every is the query with its parameter unbound: its rows for a value are the rows of
    that value bound, for every per-description query and for concept_parts."""
    kb = fresh_bundled_kb
    iris = _descriptions(kb)
    assert len(iris) > 50
    for name in PER_DESCRIPTION:
        every = kb.queries.select_every(kb.store, name)
        for iri in iris:
            own = sorted(_key(row) for row in every if row["description"] == ox.NamedNode(iri))
            assert own == sorted(_key(row) for row in kb.select(name, {"description": iri})), (name, iri)
    parts = kb.queries.select_every(kb.store, "concept_parts")
    wholes = {row["concept"].value for row in parts}
    assert len(wholes) > 3
    for concept in [*sorted(wholes), "http://example.org/none#Nothing"]:
        own = sorted(_key(row) for row in parts if row["concept"] == ox.NamedNode(concept))
        assert own == sorted(_key(row) for row in kb.select("concept_parts", {"concept": concept})), concept


def test_reading_every_description_at_once_equals_reading_each(fresh_bundled_kb: KnowledgeBase) -> None:
    kb = fresh_bundled_kb
    ads = kb.advertisements()
    requirements = kb.requirements()
    assert len(ads) > 50 and len(requirements) > 5
    assert ads == [kb.description(ad.iri) for ad in ads]
    assert requirements == [kb.description(r.iri) for r in requirements]
    assert any(p.tree.children for ad in ads for p in (*ad.inputs, *ad.outputs))  # part trees were read too


def test_a_part_tree_follows_a_write_made_straight_to_the_store() -> None:
    """The part rows are read once per store generation: a write that bypasses the knowledge base
    (a SPARQL update, the graph store protocol) is still seen by the next tree."""
    kb = KnowledgeBase.open(":memory:")
    ex = "http://example.org/parts#"
    assert kb.part_tree(ex + "Tray").children == ()
    restriction = ox.NamedNode(ex + "TrayHasHandle")
    graph = GraphName.ONTOLOGY.node
    owl, rdfs = "http://www.w3.org/2002/07/owl#", "http://www.w3.org/2000/01/rdf-schema#"
    has_part = "http://www.ontologydesignpatterns.org/ont/dul/DUL.owl#hasPart"
    kb.store.add(
        [
            ox.Quad(ox.NamedNode(ex + "Tray"), ox.NamedNode(rdfs + "subClassOf"), restriction, graph),
            ox.Quad(restriction, ox.NamedNode(owl + "onProperty"), ox.NamedNode(has_part), graph),
            ox.Quad(restriction, ox.NamedNode(owl + "someValuesFrom"), ox.NamedNode(ex + "Handle"), graph),
        ]
    )
    assert [child.concept for child in kb.part_tree(ex + "Tray").children] == [ex + "Handle"]


# -- a fresh cbrs process on disk against the same store in memory --------------------------------


def _cbrs(*args: str) -> str:
    done = subprocess.run(
        [sys.executable, "-m", "cbrs", *args], capture_output=True, text=True, timeout=600, env=os.environ.copy()
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def _load(store: str, *args: str) -> None:
    """``cbrs --store STORE load ARGS`` in this process: the loads are not what is compared, the fresh
    process's match is."""
    result = CliRunner().invoke(cli, ["--store", store, "load", *args])
    assert result.exit_code == 0, result.output


def _same_ranking_on_disk_and_in_memory(tmp_path: Path, services: list[Path], request: Path, catalogue: Path) -> None:
    store = str(tmp_path / "store")
    _load(store, "--catalog", str(catalogue), *map(str, services))
    _load(store, "--graph", "requirements", "--catalog", str(catalogue), str(request))
    kb = KnowledgeBase.open(":memory:")
    kb.load(services, catalogue=Catalogue.open(catalogue))
    report = kb.load([request], graph="requirements", catalogue=Catalogue.open(catalogue))
    requirement = next(service.iri for item in report.files if item.owls for service in item.owls.services)
    for method in ("sem-str", "logic"):
        on_disk = json.loads(_cbrs("--store", store, "match", requirement, "--json", "--top", "50", "--method", method))
        fresh = KnowledgeBase(kb.store)  # nothing cached from the loads
        in_memory = json.loads(json.dumps(Matchmaker(fresh, method).rank(requirement, explain=50).to_dict(50)))
        assert on_disk == in_memory
        assert on_disk["candidates"], "the request matched nothing: the comparison would be empty"


def test_cbrs_match_in_a_fresh_process_on_disk_ranks_as_in_memory(tmp_path: Path) -> None:
    services = sorted((OWLS / "services").glob("*.owls"))
    _same_ranking_on_disk_and_in_memory(tmp_path, services, services[0], OWLS / "catalog.tsv")


@pytest.mark.skipif(not (SHARED / "relevance.xml").exists(), reason=f"OWLS-TC 4 is not at {SHARED}")
def test_the_same_on_a_part_of_owls_tc(tmp_path: Path) -> None:
    names = ["car_price_service.owls", "car_priceauto_service.owls", "book_price_service.owls", "fall_down_pill.owls"]
    services = [SHARED / "services" / name for name in names]
    _same_ranking_on_disk_and_in_memory(tmp_path, services, SHARED / "queries" / names[0], SHARED / "ontology")
