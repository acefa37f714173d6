"""Numbers under an OWL 2 DL reasoner, and how cbrs check runs one (docs/ontologies.md, "Numbers and their
datatypes" and "How long HermiT may take").

OWL 2 keeps the value spaces of xsd:decimal and xsd:double apart, so a number property whose range is one of
them alone makes the other's literals inconsistent: the bundled map writes Turtle decimals (4.5) where
home.ttl 0.5.0 said xsd:double, and `cbrs check --graph ontology --graph map` said INCONSISTENT on a fresh
store. Every number property now ranges over xsd:decimal or xsd:double or xsd:float. The HermiT tests need
Java (.ci/run installs it) and are skipped without it; the others run anywhere.
"""

from __future__ import annotations

import math
import os
import shutil
import stat
from collections.abc import Iterator
from pathlib import Path

import owlready2
import owlready2.reasoning
import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.check import (
    DEFAULT_GRAPHS,
    HermitMissingError,
    ReasonerTimeoutError,
    check,
    hermit_classpath,
    range_clashes,
)
from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase, Store
from cbrs.kb.loader import parse_file
from cbrs.kb.namespaces import OWL, PREFIXES, RDFS, XSD
from cbrs.kb.resources import bundled_files
from cbrs.kb.upgrade import statement_keys

needs_java = pytest.mark.skipif(
    shutil.which(str(owlready2.JAVA_EXE)) is None,
    reason="no Java runtime: cbrs check runs HermiT on Java (apt-get install default-jre-headless; .ci/run does)",
)

HOME = PREFIXES["home"]
LAB = "https://example.org/lab"
LEGACY = Path(__file__).parent / "data" / "legacy"
UNION = ("xsd:decimal", "xsd:double", "xsd:float")

# Numbers as a lab writes them in its own Turtle: an integer, a decimal, a double (as Python writes a float),
# an xsd:float and an xsd:int (as Protege offers them), on the map's properties and on a QoS metric.
LAB_NUMBERS = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix lab: <https://example.org/lab#> .
lab:Cup9 a home:Cup , owl:NamedIndividual ; home:x 7 ; home:y 3.25 ; home:z 7.5e-1 ;
    home:yaw "0.5"^^xsd:float ; home:sizeX "12"^^xsd:int ; home:massKg 0 .
lab:Quality a cbrs:QoSModel ; cbrs:responseTime 1.0e-1 ; cbrs:availability 1 ; cbrs:accuracy 0.9 .
"""


@pytest.fixture(scope="module")
def fresh() -> Iterator[KnowledgeBase]:
    """A freshly seeded store; the tests that add to it add a graph of their own, which no other reads."""
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


def _load(kb: KnowledgeBase, tmp_path: Path, graph: str, turtle: str) -> None:
    path = tmp_path / "lab.ttl"
    path.write_text(turtle, encoding="utf-8")
    kb.load([path], graph=graph)


@needs_java
def test_the_bundled_store_with_its_map_is_consistent(fresh: KnowledgeBase) -> None:
    result = check(fresh, [*DEFAULT_GRAPHS, GraphName.MAP])
    assert result.consistent and not result.unsatisfiable, result.to_dict()
    assert result.range_clashes == []


@needs_java
def test_a_labs_numbers_as_turtle_writes_them_are_consistent(fresh: KnowledgeBase, tmp_path: Path) -> None:
    # with core.ttl 0.3.0's xsd:decimal range, the double 1.0e-1 of cbrs:responseTime was inconsistent
    _load(fresh, tmp_path, LAB + "/numbers", LAB_NUMBERS)
    result = check(fresh, [GraphName.ONTOLOGY, LAB + "/numbers"])
    assert result.consistent and not result.unsatisfiable, result.to_dict()
    assert result.range_clashes == []


def test_a_word_where_a_number_belongs_is_listed_with_the_union_it_misses(fresh: KnowledgeBase, tmp_path: Path) -> None:
    """HermiT as owlready2 ships it lets a string by on a union range (Pellet does not): the listing names it."""
    words = LAB_NUMBERS + 'lab:Cup8 a home:Cup ; home:x "seven" ; home:y "2"^^xsd:integer .\n'
    _load(fresh, tmp_path, LAB + "/words", words)
    clashes = range_clashes(fresh, [LAB + "/words"])
    assert [clash.text() for clash in clashes] == [
        f"{LAB}#Cup8 home:x seven is an xsd:string, but home:x has range {' or '.join(UNION)}"
    ]
    assert clashes[0].admitted == tuple(XSD + name.removeprefix("xsd:") for name in UNION)


def test_an_integer_on_a_decimal_range_is_no_clash(tmp_path: Path) -> None:
    """xsd:integer and the types below it are xsd:decimals; a double is not one."""
    kb = KnowledgeBase.open(":memory:", seed=False)
    turtle = """@prefix ex: <http://example.org/n#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> . @prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
ex:p a owl:DatatypeProperty ; rdfs:range xsd:decimal .
ex:a ex:p 1 , "2"^^xsd:nonNegativeInteger , 2.5 , 2.5e0 .
"""
    _load(kb, tmp_path, "http://example.org/n", turtle)
    clashes = range_clashes(kb, ["http://example.org/n"])
    assert [(clash.value, clash.datatype) for clash in clashes] == [("2.5", XSD + "double")]


def test_a_store_seeded_with_the_old_ranges_gets_the_unions(fresh: KnowledgeBase, tmp_path: Path) -> None:
    """core.ttl 0.3.0 and home.ttl 0.5.0 (commit 2d564d3) in the store: opened, its ontology graph says what a
    fresh seed's says, and no number property keeps its old range beside the union."""
    location = str(tmp_path / "store")
    KnowledgeBase.open(location).close()
    old = Store.open(location)
    for name, version in (("core.ttl", "0.3.0"), ("home.ttl", "0.5.0")):
        bundled = next(item.path for item in bundled_files() if item.path.name == name)
        legacy = LEGACY / name.replace(".ttl", f"-{version}.ttl")
        old.replace(parse_file(bundled, GraphName.ONTOLOGY).quads, parse_file(legacy, GraphName.ONTOLOGY).quads)
    x_range = (ox.NamedNode(HOME + "x"), ox.NamedNode(RDFS + "range"), None, GraphName.ONTOLOGY.node)
    assert [quad.object for quad in old.quads(*x_range)] == [ox.NamedNode(XSD + "double")]
    old.close()
    kb = KnowledgeBase.open(location)
    assert kb.upgraded is not None and kb.upgraded.changed
    ranges = [quad.object for quad in kb.store.quads(*x_range)]
    assert len(ranges) == 1 and isinstance(ranges[0], ox.NamedNode)
    union = next(kb.store.quads(ranges[0], ox.NamedNode(OWL + "unionOf"), None))
    assert union is not None
    upgraded = statement_keys(kb.store.quads(graph=GraphName.ONTOLOGY.node))
    seeded = statement_keys(fresh.store.quads(graph=GraphName.ONTOLOGY.node))
    assert set(upgraded) == set(seeded)
    kb.close()


# -- the time limit and the classpath ------------------------------------------------------------------------


@pytest.fixture
def stalling_java(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A "java" that writes its PID and then sleeps, as a HermiT that never finishes would."""
    script = tmp_path / "java"
    script.write_text('#!/bin/sh\necho $$ > "$(dirname "$0")/pid"\nexec sleep 60\n', encoding="utf-8")
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setattr(owlready2, "JAVA_EXE", str(script))
    return tmp_path / "pid"


def _gone(pid_file: Path) -> bool:
    """Whether the process that wrote ``pid_file`` is gone (killed and reaped); one killed before it could
    write its PID is gone too."""
    if not pid_file.exists():
        return True
    try:
        os.kill(int(pid_file.read_text()), 0)
    except ProcessLookupError:
        return True
    return False


def test_a_reasoner_past_its_time_limit_is_killed_and_named(stalling_java: Path) -> None:
    kb = KnowledgeBase.open(":memory:", seed=False)
    with pytest.raises(ReasonerTimeoutError) as caught:
        check(kb, timeout=0.5)
    error = caught.value
    assert (error.seconds, error.graphs, error.triples) == (0.5, tuple(g.iri for g in DEFAULT_GRAPHS), 0)
    assert str(error) == (
        "HermiT did not finish over graph:ontology, graph:services, graph:requirements (0 triples) within 0.5 s, "
        "and was stopped: give it longer with the check_timeout setting (CBRS_CHECK_TIMEOUT=SECONDS), or check "
        "fewer graphs (--graph)"
    )
    assert _gone(stalling_java)


def test_a_time_limit_of_inf_waits_without_one_and_nan_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``cbrs check --timeout inf`` (click's FloatRange takes it) failed with "cannot convert float infinity
    to integer" from the subprocess module, and nan likewise: inf is no limit, nan is refused naming it."""
    script = tmp_path / "java"
    script.write_text("#!/bin/sh\nexit 0\n", encoding="utf-8")  # a HermiT that finds nothing, at once
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setattr(owlready2, "JAVA_EXE", str(script))
    kb = KnowledgeBase.open(":memory:", seed=False)
    assert check(kb, timeout=math.inf).consistent
    with pytest.raises(ValueError, match=r"a positive number of seconds .*, not nan"):
        check(kb, timeout=math.nan)
    kb.close()


def test_cbrs_check_takes_its_time_limit_from_the_setting(stalling_java: Path) -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "check"], env={"CBRS_CHECK_TIMEOUT": "0.5"})
    assert result.exit_code == 1
    assert result.output.startswith("Error: HermiT did not finish over graph:ontology, graph:services, ")
    assert "within 0.5 s, and was stopped: give it longer with the check_timeout setting" in result.output
    assert _gone(stalling_java)


def test_hermits_classpath_is_owlready2s_jar() -> None:
    """The one use of owlready2's private _HERMIT_CLASSPATH: this fails first if a release moves it."""
    entries = hermit_classpath().split(os.pathsep)
    jars = [Path(entry) for entry in entries if entry.endswith(".jar")]
    assert [jar.name for jar in jars] == ["HermiT.jar"] and jars[0].is_file()


def test_without_owlready2s_classpath_the_error_says_which_owlready2(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(owlready2.reasoning, "_HERMIT_CLASSPATH")
    with pytest.raises(HermitMissingError, match=r"found no HermiT in owlready2 \S+: owlready2.reasoning has no"):
        hermit_classpath()
