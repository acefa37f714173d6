"""The bundled ontologies through the OWL API (the library inside Protégé) and HermiT.

tests/java/RoundTrip.java loads every bundled ontology with the OWL API (its imports resolved through
ontologies/catalog-v001.xml, as Protégé resolves them), reports the triples its parser could not read and
the OWL 2 DL profile violations, and saves it as Turtle. These tests check that there are none, that every
precondition and effect is in the saved file as it was in ours, that the save adds nothing but the
declarations of IRIs used as individuals, and that cbrs reads the saved files as it reads its own. HermiT
(owlready2) then checks that no action class is taken for a service description.

They need Java with its compiler and Debian's libowlapi-java (5.1.20) in /usr/share/java; without them
they are skipped, saying what to install. .ci/run installs both.
"""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.check import JVM_OPTIONS
from cbrs.kb import KnowledgeBase
from cbrs.kb.conditions import CONDITION_PARTS
from cbrs.kb.namespaces import OWL, RDF
from cbrs.kb.resources import bundled_files, ontology_dir
from cbrs.kb.vocab import CBRS

JAVA_SOURCE = Path(__file__).parent / "java" / "RoundTrip.java"
JAR_DIR = Path("/usr/share/java")
# libowlapi-java and the jars of the packages it depends on (apt-cache depends libowlapi-java)
OWLAPI_JARS = ("owlapi-distribution.jar",)
DEPENDENCY_JARS = (
    "atinject-jsr330-api.jar",
    "caffeine.jar",
    "commons-codec.jar",
    "commons-io.jar",
    "commons-logging.jar",
    "commons-rdf-api.jar",
    "guava.jar",
    "hppcrt.jar",
    "httpclient.jar",
    "httpcore.jar",
    "jackson-annotations.jar",
    "jackson-core.jar",
    "jackson-databind.jar",
    "jsr305.jar",
    "slf4j-api.jar",
    "slf4j-nop.jar",
    "xz.jar",
)
INSTALL = "apt-get install libowlapi-java default-jdk-headless"
JAVA_SECONDS = 300  # the whole bundle takes about 10 s on a shared 2-core machine
# A short run: the client compiler alone and the serial collector start sooner and leave the other core to
# the other tests (javac and the round trip took 12.5 s with the defaults, 8.4 s with these); cbrs check's.
JVM_FLAGS = JVM_OPTIONS


@dataclass(frozen=True)
class RoundTrip:
    """What RoundTrip.java printed and where it saved the files."""

    returncode: int
    lines: list[str]
    saved: Path

    def findings(self, kind: str) -> list[str]:
        return [line for line in self.lines if line.startswith(kind + " ")]


def _classpath() -> str:
    """The OWL API and its dependencies, or a skip naming what is missing."""
    for tool in ("java", "javac"):
        if shutil.which(tool) is None:
            pytest.skip(f"no {tool} on PATH: the OWL API round trip compiles and runs Java ({INSTALL})")
    jars = [JAR_DIR / name for name in (*OWLAPI_JARS, *DEPENDENCY_JARS)]
    missing = [jar.name for jar in jars if not jar.is_file()]
    rdf4j = sorted(path for path in JAR_DIR.glob("rdf4j-*.jar") if not path.stem[-1].isdigit())  # unversioned names
    if not rdf4j:
        missing.append("rdf4j-*.jar")
    if missing:
        pytest.skip(f"the OWL API is not installed in {JAR_DIR} (missing {', '.join(missing)}; {INSTALL})")
    return ":".join(str(jar) for jar in (*jars, *rdf4j))


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory: pytest.TempPathFactory) -> RoundTrip:
    classpath = _classpath()
    work = tmp_path_factory.mktemp("owlapi")
    classes, saved = work / "classes", work / "saved"
    classes.mkdir()
    saved.mkdir()
    compiled = subprocess.run(
        ["javac", *(f"-J{flag}" for flag in JVM_FLAGS), "-d", str(classes), "-cp", classpath, str(JAVA_SOURCE)],
        capture_output=True,
        text=True,
        timeout=JAVA_SECONDS,
    )
    assert compiled.returncode == 0, compiled.stderr
    files = [str(item.path) for item in bundled_files()]
    ran = subprocess.run(
        [
            "java",
            *JVM_FLAGS,
            "-cp",
            f"{classes}:{classpath}",
            "RoundTrip",
            str(ontology_dir() / "catalog-v001.xml"),
            str(saved),
            *files,
        ],
        capture_output=True,
        text=True,
        timeout=JAVA_SECONDS,
    )
    assert ran.returncode in (0, 3), ran.stderr  # 3: it found something, which the tests below name
    return RoundTrip(ran.returncode, ran.stdout.splitlines(), saved)


def test_every_bundled_ontology_is_owl2_dl_and_read_whole(round_trip: RoundTrip) -> None:
    assert round_trip.findings("violation") == []
    assert round_trip.findings("unparsed") == []  # the reified conditions were 210 unparsed triples
    assert [line.split()[1] for line in round_trip.findings("file")] == [item.path.name for item in bundled_files()]
    assert round_trip.returncode == 0


def _conditions(path: Path) -> set[tuple[str, ...]]:
    """(holder, link, type, subject, predicate, object, text) of every condition in a Turtle file."""
    store = ox.Store()
    store.load(path=str(path), format=ox.RdfFormat.TURTLE)
    parts = " ".join(f"OPTIONAL {{ ?c <{part}> ?p{i} }}" for i, part in enumerate(CONDITION_PARTS))
    query = f"""SELECT ?holder ?link ?type ?p0 ?p1 ?p2 ?text WHERE {{
        ?holder <{CBRS.hasOWLSModel}> ?model . ?model ?link ?c . ?c a ?type .
        VALUES ?link {{ <{CBRS.hasPrecondition}> <{CBRS.hasEffect}> <{CBRS.hasDeleteEffect}> }}
        {parts} OPTIONAL {{ ?c <{CBRS.conditionText}> ?text }} }}"""
    rows = store.query(query)
    assert isinstance(rows, ox.QuerySolutions)
    found = set()
    for row in rows:
        values = (row[name] for name in ("holder", "link", "type", "p0", "p1", "p2", "text"))
        found.add(tuple("" if value is None else value.value for value in values))
    return found


@pytest.mark.parametrize("name", ["actions.ttl", "services.ttl", "requirements.ttl"])
def test_every_condition_survives_the_round_trip(round_trip: RoundTrip, name: str) -> None:
    before = _conditions(ontology_dir() / name)
    assert before and all(row[3] and row[4] and row[5] for row in before)
    assert _conditions(round_trip.saved / name) == before


def _graph(path: Path) -> ox.Dataset:
    return ox.Dataset(ox.Quad(t.subject, t.predicate, t.object) for t in ox.parse(path=str(path)))


def _canonical(dataset: ox.Dataset) -> set[str]:
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    return {str(quad) for quad in dataset}


def test_a_save_adds_only_declarations_of_individuals(round_trip: RoundTrip) -> None:
    individual = ox.NamedNode(OWL + "NamedIndividual")
    for item in bundled_files():
        ours, saved = _graph(item.path), _graph(round_trip.saved / item.path.name)
        added = [q for q in saved if q.predicate.value == RDF + "type" and q.object == individual and q not in ours]
        for quad in added:  # an IRI the file uses as an individual (a punned class) without declaring it
            assert isinstance(quad.subject, ox.NamedNode)
            saved.remove(quad)
        assert _canonical(saved) == _canonical(ours), item.path.name


def _descriptions(kb: KnowledgeBase) -> dict[str, tuple[object, ...]]:
    """Each description as cbrs reads it, without the skolem IRIs of its nodes (a save renames them)."""
    found: dict[str, tuple[object, ...]] = {}
    for d in (*kb.advertisements(include_unavailable=True), *kb.requirements()):
        parameters = tuple((p.direction, p.name, p.type, p.tree) for p in (*d.inputs, *d.outputs))
        ports = tuple(sorted(str(dataclasses.replace(port, iri="")) for port in getattr(d, "ports", ())))
        found[d.iri] = (sorted(d.types), d.label, d.service_name, parameters, ports, d.area, d.qos)
        found[d.iri] += (d.preconditions, d.effects, d.deletes)
    return found


def test_cbrs_reads_what_the_owl_api_saved(round_trip: RoundTrip) -> None:
    kb = KnowledgeBase.open(":memory:", seed=False)
    for item in bundled_files():
        kb.load([round_trip.saved / item.path.name], graph=item.graph.value)
    fresh = KnowledgeBase.open(":memory:")
    assert _descriptions(kb) == _descriptions(fresh)
    action = "https://w3id.org/cbrs/action#PickingUpAnObject"
    assert kb.action_requirement(action).preconditions == fresh.action_requirement(action).preconditions


# -- HermiT ---------------------------------------------------------------------------------------


def _new_cbrs_types(folder: Path, core: str, monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, str]]:
    """The cbrs classes HermiT (owlready2) makes a class of the bundle's ontology, services and requirements
    graphs (with ``core`` for core.ttl) an instance of: a class is one only by punning, as the action classes
    that carry an IOPE are."""
    owlready2 = pytest.importorskip("owlready2")
    if shutil.which(str(owlready2.JAVA_EXE)) is None:
        pytest.skip("no Java runtime for HermiT (apt-get install default-jre-headless)")
    triples = [
        t
        for item in bundled_files()
        if item.graph.value in ("ontology", "services", "requirements")
        for t in (
            ox.parse(core.encode(), format=ox.RdfFormat.TURTLE)
            if item.path.name == "core.ttl"
            else ox.parse(path=str(item.path))
        )
        if t.predicate.value != OWL + "imports"
    ]
    path = folder / "bundle.nt"
    path.write_bytes(ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES) or b"")
    world = owlready2.World()
    ontology = world.get_ontology(path.as_uri()).load(format="ntriples")
    typed = "SELECT ?s ?o WHERE { ?s a ?o . FILTER (isIRI(?s) && isIRI(?o)) }"
    before = {(str(s), str(o)) for s, o in world.as_rdflib_graph().query(typed)}
    # owlready2 takes no JVM options: the java launcher reads them from the environment (HermiT took 9 s
    # with the defaults, 3 s with these, on a loaded 2-core machine)
    monkeypatch.setenv("JDK_JAVA_OPTIONS", " ".join(JVM_FLAGS))
    with ontology:
        owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
    after = {(str(s), str(o)) for s, o in world.as_rdflib_graph().query(typed)}
    assert list(world.inconsistent_classes()) == []
    world.close()
    classes = {s for s, o in before if o == OWL + "Class"}
    return sorted((s, o) for s, o in after - before if s in classes and o in classes and o.startswith(CBRS.NS))


def test_hermit_takes_no_action_class_for_a_service_description(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    core = (ontology_dir() / "core.ttl").read_text(encoding="utf-8")
    assert _new_cbrs_types(tmp_path, core, monkeypatch) == []


def test_with_the_domain_of_core_0_1_0_it_did(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The check above can fail: hasOWLSModel's domain as core 0.1.0 had it makes every action class
    that carries a model (by punning) a service description."""
    core = (ontology_dir() / "core.ttl").read_text(encoding="utf-8")
    union = "rdfs:domain [ a owl:Class ; owl:unionOf ( cbrs:ActionType cbrs:ServiceDescription ) ] ;"
    assert union in core
    inferred = _new_cbrs_types(tmp_path, core.replace(union, "rdfs:domain cbrs:ServiceDescription ;"), monkeypatch)
    assert ("https://w3id.org/cbrs/action#PickingUpAnObject", CBRS.ServiceDescription) in inferred
    assert {o for _, o in inferred} == {CBRS.ServiceDescription}
    assert all(s.startswith("https://w3id.org/cbrs/action#") for s, _ in inferred)
