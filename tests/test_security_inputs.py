"""Security issue 20, items 5 and 7: files and updates that would exhaust memory or corrupt the store.

- RDF/XML entities are measured before Oxigraph expands them, on every path that parses RDF/XML
  (``cbrs load`` / ``KnowledgeBase.load``, ``parse_bytes`` as registration uses it, OWL-S files).
- A PDDL condition of many atoms costs its text once, not once per atom.
- A blank node inserted by an update is refused on write, and one already stored is passed over on read.
- An OWL-S file is not merged into another description of the same IRI, nor loaded when it describes
  nothing; a LOAD that cannot read its source is the request's fault (400), not the server's.
"""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import BlankNodeError, BlankNodeInsertError, RdfParseError, StoreEvaluationError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import expand
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.sparql_service import EndpointConfig, SparqlService

DATA = Path(__file__).parent / "data"
OWLS = DATA / "owls"
NAVIGATE = OWLS / "services" / "navigate.owls"
TOKEN = "inputs-test-token"
SERVICES = "https://w3id.org/cbrs/graph/services"


def bomb(levels: int, fan: int = 10, in_namespace: bool = False) -> bytes:
    """A 'billion laughs': ``fan ** levels`` copies of "lol", from well under a kilobyte."""
    declarations = ['<!ENTITY e0 "lol">'] + [f'<!ENTITY e{n} "{f"&e{n - 1};" * fan}">' for n in range(1, levels + 1)]
    use = f"&e{levels};"
    namespace = f' xmlns:x="http://example.org/{use}#"' if in_namespace else ""
    label = "" if in_namespace else use
    return (
        f'<?xml version="1.0"?>\n<!DOCTYPE rdf:RDF [ {" ".join(declarations)} ]>\n'
        f'<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#" '
        f'xmlns:rdfs="http://www.w3.org/2000/01/rdf-schema#"{namespace}>'
        f'<rdf:Description rdf:about="http://example.org/a"><rdfs:label>{label}x</rdfs:label></rdf:Description>'
        "</rdf:RDF>\n"
    ).encode()


@pytest.fixture
def kb() -> KnowledgeBase:
    return KnowledgeBase.open(":memory:")


# -- entity expansion ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("data", "said"),
    [
        pytest.param(bomb(7), "expand", id="nested-entities-in-text"),  # 30 MB once expanded
        pytest.param(bomb(7, in_namespace=True), "expand", id="nested-entities-in-xmlns"),
        pytest.param(bomb(2, fan=2000), "expand", id="wide-entity"),
        pytest.param(
            b'<?xml version="1.0"?><!DOCTYPE r [ <!ENTITY x SYSTEM "file:///etc/passwd"> ]>'
            b'<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">&x;</rdf:RDF>',
            "external",
            id="external-entity",
        ),
        pytest.param(
            b'<?xml version="1.0"?><!DOCTYPE r [ <!ENTITY % p "x"> ]>'
            b'<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"/>',
            "parameter",
            id="parameter-entity",
        ),
        pytest.param(
            b'<?xml version="1.0"?><!DOCTYPE r [ <!ENTITY a "&b;"> <!ENTITY b "&a;"> ]>'
            b'<rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#"><rdf:Description rdf:about="u:a">'
            b"<rdf:value>&a;</rdf:value></rdf:Description></rdf:RDF>",
            "itself",
            id="entity-cycle",
        ),
    ],
)
def test_entities_are_measured_before_any_parser_expands_them(
    kb: KnowledgeBase, tmp_path: Path, data: bytes, said: str
) -> None:
    before = kb.store.dump()
    for suffix in (".rdf", ".owls"):  # cbrs load, and the OWL-S import path
        path = tmp_path / f"hostile{suffix}"
        path.write_bytes(data)
        with pytest.raises(RdfParseError, match=said) as refused:
            kb.load([path])
        assert str(path) in str(refused.value)
    with pytest.raises(RdfParseError, match=said):  # the in-memory path registration and imports use
        parse_bytes(data, "<registration>", ox.RdfFormat.RDF_XML)
    assert kb.store.dump() == before


def test_a_file_with_modest_entities_still_loads(kb: KnowledgeBase, tmp_path: Path) -> None:
    path = tmp_path / "modest.rdf"
    path.write_bytes(bomb(2))  # 100 laughs: what ontologies do with &owl; and &xsd;
    report = kb.load([path])
    assert report.quads == 1
    assert kb.store.count() > 0


# -- PDDL conditions ---------------------------------------------------------------------------------


def test_a_condition_of_many_atoms_costs_its_text_once(kb: KnowledgeBase, tmp_path: Path) -> None:
    atoms = " ".join(["(robots:Charged ?Robot)"] * 1500)
    text = NAVIGATE.read_text(encoding="utf-8").replace("(robots:Charged ?Robot)", f"(and {atoms})")
    path = tmp_path / "navigate.owls"
    path.write_text(text, encoding="utf-8")
    report = kb.load([path], catalogue=OWLS / "ontology")
    conversion = report.files[0].owls
    assert conversion is not None
    kept = [note for note in conversion.notes if "1500 atoms" in note]
    assert kept and "kept as text" in kept[0]
    long_texts = [q for q in report.files[0].quads if isinstance(q.object, ox.Literal) and len(q.object.value) > 30_000]
    # the file's own expression body and the text kept once: not once per atom (1500 copies of 36 KB before)
    assert len(long_texts) == 2


# -- blank nodes ---------------------------------------------------------------------------------------

BLANK_SERVICE = f"""PREFIX cbrs: <https://w3id.org/cbrs/core#>
INSERT DATA {{ GRAPH <{SERVICES}> {{
  <urn:evil:camera> a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Evil" ; cbrs:serviceName "Evil" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ; cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "p" ;
      cbrs:parameterType <https://w3id.org/cbrs/home#RobotPosition> ] ] .
  _:anonymous a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Nobody" ; cbrs:serviceName "Nobody" .
}} }}"""


def test_an_update_inserting_blank_nodes_is_refused_and_writes_nothing(kb: KnowledgeBase) -> None:
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    before = kb.store.dump()
    with pytest.raises(BlankNodeInsertError) as refused:
        sparql.update(BLANK_SERVICE, TOKEN)
    assert refused.value.http_status == 400 and "give it an IRI" in str(refused.value)
    assert kb.store.dump() == before
    sparql.update(f'INSERT DATA {{ GRAPH <{SERVICES}> {{ <urn:a> <urn:b> "_:not [ a node" }} }}', TOKEN)
    sparql.update(
        f"DELETE {{ GRAPH <{SERVICES}> {{ ?s ?p ?o }} }} WHERE {{ GRAPH <{SERVICES}> {{ ?s ?p [] }} }}", TOKEN
    )


def test_blank_nodes_already_stored_are_passed_over_on_read(kb: KnowledgeBase) -> None:
    kb.update(BLANK_SERVICE)  # through the library, as an older server or another tool could have
    names = {ad.iri for ad in kb.advertisements()}
    assert "urn:evil:camera" not in names and len(names) > 5
    ranking = Matchmaker(kb).rank(expand("req:RobotSelfPosition"), explain=3)
    assert ranking.candidates
    with pytest.raises(BlankNodeError, match="urn:evil:camera") as refused:
        kb.description("urn:evil:camera")
    assert refused.value.http_status == 400


# -- OWL-S files and LOAD ---------------------------------------------------------------------------


def test_an_owls_file_is_not_merged_into_another_description_of_its_iri(kb: KnowledgeBase, tmp_path: Path) -> None:
    kb.load([NAVIGATE], catalogue=OWLS / "ontology")
    before = kb.store.dump()
    kb.load([NAVIGATE], catalogue=OWLS / "ontology")  # the same file again adds nothing
    assert kb.store.dump() == before
    changed = tmp_path / "navigate.owls"
    changed.write_text(NAVIGATE.read_text(encoding="utf-8").replace("(robots:Charged ?Robot)", "(robots:Idle ?Robot)"))
    with pytest.raises(RdfParseError, match="already in the store, described differently"):
        kb.load([changed], catalogue=OWLS / "ontology")
    assert kb.store.dump() == before


OWLS_PREFIXES = """@prefix service: <http://www.daml.org/services/owl-s/1.1/Service.owl#> .
@prefix profile: <http://www.daml.org/services/owl-s/1.1/Profile.owl#> .
@prefix process: <http://www.daml.org/services/owl-s/1.1/Process.owl#> .
"""


def test_an_owls_file_that_describes_nothing_is_refused(kb: KnowledgeBase, tmp_path: Path) -> None:
    bare = tmp_path / "bare.ttl"
    bare.write_text(OWLS_PREFIXES + "<http://example.org/s#S> a service:Service .\n", encoding="utf-8")
    with pytest.raises(RdfParseError, match="neither a profile nor a process"):
        kb.load([bare])
    partial = tmp_path / "partial.ttl"
    partial.write_text(
        OWLS_PREFIXES + '<http://example.org/p#P> a profile:Profile ; profile:serviceName "P" .\n', encoding="utf-8"
    )
    report = kb.load([partial])
    notes = report.files[0].owls.notes if report.files[0].owls else []
    assert any("has no service and no process" in note for note in notes)


def test_a_load_that_cannot_read_its_source_is_a_400(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(tmp_path / "store", remote_access=("file:///",))
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    try:
        (tmp_path / "data.ttl").write_text("<urn:x> <urn:y> <urn:z> .\n", encoding="utf-8")
        for target in (tmp_path / "missing.ttl", tmp_path, tmp_path / "data.ttl"):  # Oxigraph reads no file format
            with pytest.raises(StoreEvaluationError, match="LOAD failed") as refused:
                sparql.update(f"LOAD <{target.as_uri()}>", TOKEN)
            assert refused.value.http_status == 400
    finally:
        sparql.close()
        kb.close()
