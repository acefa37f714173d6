"""cbrs check: HermiT (owlready2, on Java) over the store's ontologies and descriptions."""

from __future__ import annotations

import shutil
from pathlib import Path

import owlready2
import pytest
from click.testing import CliRunner

from cbrs.check import JavaMissingError, check
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import GraphName

needs_java = pytest.mark.skipif(
    shutil.which(str(owlready2.JAVA_EXE)) is None, reason="no Java runtime (apt-get install default-jre-headless)"
)

HEAD = """@prefix ex: <http://example.org/check#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> . @prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
ex:Cup a owl:Class . ex:Plate a owl:Class ; owl:disjointWith ex:Cup .
"""


def small_kb(tmp_path: Path, turtle: str) -> KnowledgeBase:
    """An unseeded store holding only ``turtle`` in the ontology graph: HermiT answers in about a second."""
    path = tmp_path / "check.ttl"
    path.write_text(HEAD + turtle, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:", seed=False)
    kb.load([path], graph=GraphName.ONTOLOGY)
    return kb


@needs_java
def test_a_fresh_store_is_consistent_with_no_unsatisfiable_class() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "check"])
    assert result.exit_code == 0, result.output
    first = result.output.splitlines()[0]
    assert first.startswith("HermiT (owlready2) over graph:ontology, graph:services, graph:requirements (")
    assert ": consistent, no unsatisfiable class (" in first and first.endswith(" s)")


@needs_java
def test_an_unsatisfiable_class_is_named(tmp_path: Path) -> None:
    kb = small_kb(tmp_path, "ex:CupPlate rdfs:subClassOf ex:Cup , ex:Plate .")
    result = check(kb)
    assert result.consistent and result.unsatisfiable == ["http://example.org/check#CupPlate"]
    assert not result.ok


@needs_java
def test_an_inconsistency_is_reported(tmp_path: Path) -> None:
    kb = small_kb(tmp_path, "ex:mug a owl:NamedIndividual , ex:Cup , ex:Plate .")
    result = check(kb)
    assert not result.consistent and not result.ok
    assert result.to_dict()["consistent"] is False


@needs_java
def test_literals_off_their_declared_range_are_listed(tmp_path: Path) -> None:
    kb = small_kb(tmp_path, "ex:height a owl:DatatypeProperty ; rdfs:range xsd:double .\nex:mug ex:height 0.12 .")
    assert [clash.text() for clash in check(kb).range_clashes] == [
        "http://example.org/check#mug http://example.org/check#height 0.12 is an xsd:decimal, "
        "but http://example.org/check#height has range xsd:double"
    ]


def test_without_java_the_message_says_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(owlready2, "JAVA_EXE", "/nonexistent/java")
    with pytest.raises(JavaMissingError) as caught:
        check(KnowledgeBase.open(":memory:", seed=False))
    assert caught.value.java == "/nonexistent/java"
    result = CliRunner().invoke(cli, ["--store", ":memory:", "check"])
    assert result.exit_code == 1
    assert result.output == (
        "Error: cbrs check runs the HermiT reasoner, which needs Java, but '/nonexistent/java' was not found: "
        "install a Java runtime (Debian/Ubuntu: apt-get install default-jre-headless) or put java on PATH\n"
    )
