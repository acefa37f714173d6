"""The sixteenth round: a semantic-web engineer's ontology from Protégé (docs/examples/lab16_protege: Turtle,
RDF/XML, OWL/XML, an import of the bundled home ontology and of a file beside it mapped by Protégé's
catalog-v001.xml, a class defined by an equivalent class) loaded, checked and served (docs/ontologies.md, "Tried
by a semantic-web engineer"). Each test failed before its fix."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase
from cbrs.kb.catalog import Catalogue
from cbrs.kb.derived_prefixes import derive, namespaces_in
from cbrs.kb.errors import RdfParseError
from cbrs.kb.owl_syntaxes import NotRdfSyntaxError, owl_syntax
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app

LAB = Path(__file__).parent.parent / "docs" / "examples" / "lab16_protege"
KIT, GLASSWARE = "http://lab16.example.org/kit", "http://lab16.example.org/glassware"
HOME = "https://w3id.org/cbrs/home"
RDF_TYPE, OWL_ONTOLOGY = "http://www.w3.org/1999/02/22-rdf-syntax-ns#type", "http://www.w3.org/2002/07/owl#Ontology"
TOKEN = "lab16-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """A store holding the kit, loaded with the folder as its catalogue (the import beside it followed)."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([LAB / "kit.ttl"], catalogue=Catalogue.open(LAB))
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def client(kb: KnowledgeBase) -> Iterator[FlaskClient]:
    service = SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))
    yield create_app(service).test_client()
    service.close()


# -- OWL/XML and the other syntaxes Protégé saves that are not RDF -----------------------------------------


def test_owl_xml_is_refused_naming_the_syntax_and_what_to_save_instead(tmp_path: Path) -> None:
    """Before: "kit.owx: XML namespaces are required in RDF/XML", the same for OWL/XML saved as .owl."""
    kb = KnowledgeBase.open(":memory:")
    before = len(list(kb.store.quads()))
    as_owl = tmp_path / "kit.owl"  # Protégé keeps .owl whatever syntax it saves
    shutil.copy(LAB / "kit.owx", as_owl)
    for path in (LAB / "kit.owx", as_owl):
        with pytest.raises(NotRdfSyntaxError) as refused:
            kb.load([path])
        message = str(refused.value)
        assert message.startswith(f"{path}: this is OWL/XML, which cbrs does not read")
        assert "save the ontology from Protégé as RDF/XML or Turtle" in message
        assert isinstance(refused.value, RdfParseError)  # a parse error wherever one is caught (exit 1, 400)
    assert len(list(kb.store.quads())) == before
    kb.close()


def test_the_syntaxes_are_told_by_content_and_turtle_is_none_of_them() -> None:
    assert owl_syntax((LAB / "kit.owx").read_bytes()) == "OWL/XML"
    assert owl_syntax(b"Prefix(:=<http://x/#>)\nOntology(<http://x/>\n)") == "OWL functional syntax"
    assert owl_syntax(b"Prefix: : <http://x/#>\nOntology: <http://x/>\n") == "Manchester syntax"
    for rdf in ("kit.ttl", "kit.owl", "glassware.ttl"):
        assert owl_syntax((LAB / rdf).read_bytes()) is None
    assert owl_syntax(b"Prefix : <http://x/#>\n:a :b :c .\n") is None  # Turtle, SPARQL-style empty prefix
    assert owl_syntax(b'<?xml version="1.0"?>\n<Ontology xmlns="urn:other#"/>') is None


OWLS_PROLOG = b"""<?xml version='1.0' encoding='ISO-8859-1'?>
<!DOCTYPE uridef [
  <!ENTITY rdf "http://www.w3.org/1999/02/22-rdf-syntax-ns">
  <!ENTITY owl "http://www.w3.org/2002/07/owl">
]>
<!-- entity types as a shorthand for URIs -->
<!-- a second comment -->
"""


@pytest.mark.parametrize(
    ("root", "syntax"),
    [
        (b'<rdf:RDF xmlns:rdf="&rdf;#" xmlns:owl="http://www.w3.org/2002/07/owl#">', None),
        (b'<Ontology xmlns="http://www.w3.org/2002/07/owl#" ontologyIRI="http://x/">', "OWL/XML"),
        (b"<owl:Ontology xmlns:owl='http://www.w3.org/2002/07/owl#'>", "OWL/XML"),
        (b'<Ontology xmlns="urn:other#">', None),
        (b'<rdf:RDF xmlns:rdf="&rdf;#"><owl:Ontology xmlns:owl="http://www.w3.org/2002/07/owl#"/>', None),
    ],
)
def test_the_root_element_is_read_past_an_owl_s_prolog(root: bytes, syntax: str | None) -> None:
    """An OWL-S file's prolog (a DOCTYPE of entities, comments) before its root: the root alone decides.
    The first reader, one regular expression over prolog and root, backtracked for minutes on each of
    OWLS-TC's files whose root was not an Ontology, and CI's load of OWLS-TC with it did not end."""
    assert owl_syntax(b"\xef\xbb\xbf" + OWLS_PROLOG + root + b"\n</x>") == syntax
    assert owl_syntax(OWLS_PROLOG + b"<!-- unclosed comment") is None


def test_the_cli_refuses_owl_xml_in_one_line() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", str(LAB / "kit.owx")])
    assert result.exit_code == 1
    assert "this is OWL/XML, which cbrs does not read" in result.output
    assert "XML namespaces are required" not in result.output


def test_the_graph_store_names_owl_xml_by_type_and_by_content(client: FlaskClient) -> None:
    body = (LAB / "kit.owx").read_bytes()
    target = "/store?graph=http://lab16.example.org/graph/kit"
    by_type = client.put(target, data=body, content_type="application/owl+xml", headers=AUTH)
    assert by_type.status_code == 415
    assert "OWL/XML is no RDF syntax: save the ontology from Protégé as RDF/XML or Turtle" in by_type.json["message"]
    by_content = client.put(target, data=body, content_type="application/rdf+xml", headers=AUTH)
    assert by_content.status_code == 400
    assert by_content.json["error"] == "RdfParseError"
    assert "this is OWL/XML" in by_content.json["message"]


# -- imports ---------------------------------------------------------------------------------------------


def test_a_folder_catalogue_reads_the_catalogue_protege_keeps_there() -> None:
    """Before: --catalog DIR resolved an import by the IRI's last segment alone: DIR/glassware, no such file."""
    assert Catalogue.open(LAB).resolve(GLASSWARE) == LAB / "glassware.ttl"


def test_an_import_of_an_ontology_the_store_holds_is_not_unresolved() -> None:
    """Before: "unresolved imports: 1 (https://w3id.org/cbrs/home)", the bundled ontology every store holds."""
    kb = KnowledgeBase.open(":memory:")
    report = kb.load([LAB / "kit.owl"], catalogue=Catalogue.open(LAB))
    assert report.unresolved_imports == []
    assert report.already_loaded == [HOME]
    assert [Path(item.source).name for item in report.imports] == ["glassware.ttl"]
    kb.close()


def test_cbrs_load_names_an_ontologys_imports_it_did_not_follow(tmp_path: Path) -> None:
    """Before: an ontology (not OWL-S) importing a file beside it loaded without a word of the import."""
    store = str(tmp_path / "s")
    alone = CliRunner().invoke(cli, ["--store", store, "load", str(LAB / "kit.ttl")])
    assert alone.exit_code == 0, alone.output
    lines = alone.output.splitlines()
    assert f"imports not followed (no --catalog): 2 ({GLASSWARE}, {HOME})" in lines
    assert f"  of which already in the store: 1 ({HOME})" in lines
    followed = CliRunner().invoke(cli, ["--store", store, "load", "--catalog", str(LAB), str(LAB / "kit.owl")])
    assert followed.exit_code == 0, followed.output
    assert "unresolved imports: 0" in followed.output.splitlines()
    assert "unresolved parameter types" not in followed.output  # looked up for OWL-S files only: always 0 here


def test_the_turtle_and_the_rdf_xml_give_the_same_graph() -> None:
    graphs = []
    for name in ("kit.ttl", "kit.owl"):
        kb = KnowledgeBase.open(":memory:")
        kb.load([LAB / name], catalogue=Catalogue.open(LAB))
        graphs.append({(q.subject, q.predicate, q.object) for q in kb.store.quads(graph=GraphName.ONTOLOGY.node)})
        kb.close()
    assert graphs[0] == graphs[1]
    declared = (ox.NamedNode(GLASSWARE), ox.NamedNode(RDF_TYPE), ox.NamedNode(OWL_ONTOLOGY))
    assert declared in graphs[0]  # the import beside it came in


# -- names -----------------------------------------------------------------------------------------------


def test_an_ontologys_version_iri_does_not_take_its_terms_prefix(kb: KnowledgeBase) -> None:
    """Before: kit1:MeasuringBeaker, the version IRI http://lab16.example.org/kit/1.0 deriving "kit" too."""
    table = derive(namespaces_in(kb.store))
    assert table.get("kit") == KIT + "#"
    assert table.get("glassware") == GLASSWARE + "#"


# -- the Graph Store's answers ---------------------------------------------------------------------------


def test_head_of_a_graph_says_the_length_a_get_sends(client: FlaskClient) -> None:
    """Before: HEAD /store?graph=... answered Content-Length: 0 where the GET sent the graph."""
    target = f"/store?graph={GraphName.ONTOLOGY.iri}"
    got, head = client.get(target), client.head(target)
    assert head.status_code == got.status_code == 200
    assert int(head.headers["Content-Length"]) == len(got.get_data()) > 0
    assert head.get_data() == b""


def test_every_graph_store_answer_carries_the_endpoints_headers(client: FlaskClient) -> None:
    """Before: an error of /store had neither Cbrs-Server nor Vary; a 200 said Vary: Accept alone."""
    answers = [
        client.get(f"/store?graph={GraphName.MAP.iri}"),
        client.get("/store?graph=http://lab16.example.org/no-such-graph"),
        client.put("/store?graph=urn:x:g", data="<urn:a> <urn:b> <urn:c> .", content_type="text/turtle"),
        client.get(f"/store?graph={GraphName.MAP.iri}", headers={"Accept": "text/csv"}),
    ]
    endpoint = client.get("/sparql", query_string={"query": "ASK {}"})
    assert [a.status_code for a in answers] == [200, 404, 403, 406]
    for answer in answers:
        assert answer.headers["Cbrs-Server"] == endpoint.headers["Cbrs-Server"]
        assert set(answer.headers["Vary"].replace(" ", "").split(",")) == {"Accept", "Origin"}


# -- the round's program, as docs/examples/lab16_endpoint.py's docstring runs it -----------------------------


def test_the_rounds_rdflib_and_protocol_program_runs_against_a_served_store() -> None:
    """The program the round's write-up quotes, run against ``cbrs serve`` on loopback (the kit loaded into a
    store of its own: the program writes): every trial answers as written there, and the program ends well."""
    program = LAB.parent / "lab16_endpoint.py"
    kb = KnowledgeBase.open(":memory:")
    kb.load([LAB / "kit.ttl"], catalogue=Catalogue.open(LAB))
    server = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN, isolate=False)))
    server.start()
    try:
        ran = subprocess.run(
            [sys.executable, str(program), f"http://127.0.0.1:{server.http_port}"],
            env={**os.environ, "CBRS_UPDATE_TOKEN": TOKEN},
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
    finally:
        server.stop(timeout=10)
        kb.close()
    assert ran.returncode == 0, ran.stderr
    lines = ran.stdout.splitlines()
    assert any(line.startswith("SPARQLUpdateStore set: ") and "'300'" in line for line in lines), ran.stdout
    for expected in ("PUT 201", "POST 204", "DELETE 204"):
        assert expected in lines, ran.stdout
    assert any(line.startswith("PUT OWL/XML 415 ") for line in lines), ran.stdout
    again = next(line for line in lines if line.startswith("DELETE again "))
    assert again.startswith("DELETE again 404 True Accept, Origin "), again
