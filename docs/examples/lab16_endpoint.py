"""The sixteenth round (docs/ontologies.md, "Tried by a semantic-web engineer"): the lab's kit read and written
through a running ``cbrs serve`` with rdflib and the standard library alone, as the SPARQL 1.1 Protocol and
the Graph Store HTTP Protocol describe them. It prints one line per trial.

    cbrs load --catalog docs/examples/lab16_protege docs/examples/lab16_protege/kit.ttl
    CBRS_UPDATE_TOKEN=... cbrs serve --port 8080 &
    CBRS_UPDATE_TOKEN=... python docs/examples/lab16_endpoint.py http://127.0.0.1:8080
"""

from __future__ import annotations

import os
import sys
import urllib.error
import urllib.parse
import urllib.request
from email.message import Message
from pathlib import Path

from rdflib import Graph, Literal, Namespace, URIRef
from rdflib.plugins.stores.sparqlstore import SPARQLStore, SPARQLUpdateStore

KIT = Namespace("http://lab16.example.org/kit#")
GW = Namespace("http://lab16.example.org/glassware#")
ONTOLOGY = URIRef("https://w3id.org/cbrs/graph/ontology")
NOTES = URIRef("http://lab16.example.org/graph/notes")
SELECT = "PREFIX kit: <http://lab16.example.org/kit#> SELECT ?p ?o WHERE { kit:Beaker1 ?p ?o } ORDER BY ?p"


def call(
    method: str, url: str, body: bytes | None = None, headers: dict[str, str] | None = None
) -> tuple[int, Message, bytes]:
    request = urllib.request.Request(url, data=body, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(request, timeout=30) as answer:
            return answer.status, answer.headers, answer.read()
    except urllib.error.HTTPError as error:
        return error.code, error.headers, error.read()


def main(base: str, token: str) -> None:
    sparql, store = f"{base}/sparql", f"{base}/store"
    auth = {"Authorization": f"Bearer {token}"}

    # rdflib, reading: the union default graph, then one graph by default-graph-uri
    union = Graph(SPARQLStore(sparql))
    print("SPARQLStore, the union: ", len(union), "triples")
    ontology = Graph(SPARQLStore(sparql), identifier=ONTOLOGY)
    print(
        "SPARQLStore, graph:ontology:",
        len(ontology),
        "triples;",
        "Beaker1:",
        sorted(ontology.predicate_objects(KIT.Beaker1)),
    )
    # rdflib, writing with the token
    notes = Graph(SPARQLUpdateStore(sparql, f"{base}/update", headers=auth), identifier=NOTES)
    notes.set((KIT.Beaker1, GW.capacityMl, Literal(300)))
    print("SPARQLUpdateStore set:", list(notes.objects(KIT.Beaker1, GW.capacityMl)))
    notes.remove((None, None, None))

    # the protocol's three forms, and each result type
    query = urllib.parse.urlencode({"query": SELECT})
    for accept in (
        "application/sparql-results+json",
        "application/sparql-results+xml",
        "text/csv",
        "text/tab-separated-values",
    ):
        status, headers, _ = call("GET", f"{sparql}?{query}", headers={"Accept": accept})
        print("GET", accept, status, headers.get("Content-Type"))
    status, _, body = call(
        "POST", sparql, query.encode(), {"Content-Type": "application/x-www-form-urlencoded", "Accept": "text/csv"}
    )
    print("POST form", status, len(body.splitlines()) - 1, "rows")
    dataset = urllib.parse.urlencode({"default-graph-uri": "https://w3id.org/cbrs/graph/services"})
    direct = {"Content-Type": "application/sparql-query", "Accept": "text/csv"}
    status, _, body = call("POST", f"{sparql}?{dataset}", SELECT.encode(), direct)
    print("POST direct, default-graph-uri graph:services", status, len(body.splitlines()) - 1, "rows")
    for accept in ("text/turtle", "application/n-triples", "application/ld+json", "application/rdf+xml"):
        describe = urllib.parse.urlencode({"query": "DESCRIBE <http://lab16.example.org/kit#MeasuringBeaker>"})
        status, headers, _ = call("GET", f"{sparql}?{describe}", headers={"Accept": accept})
        print("DESCRIBE", accept, status, headers.get("Content-Type"))

    # the Graph Store Protocol
    graph = f"{store}?graph={urllib.parse.quote('http://lab16.example.org/graph/kit', safe='')}"
    kit = Path(__file__).with_name("lab16_protege").joinpath("kit.ttl").read_bytes()
    print("PUT", call("PUT", graph, kit, {**auth, "Content-Type": "text/turtle"})[0])
    owx = Path(__file__).with_name("lab16_protege").joinpath("kit.owx").read_bytes()
    status, _, body = call("PUT", graph, owx, {**auth, "Content-Type": "application/owl+xml"})
    print("PUT OWL/XML", status, body.decode()[:160])
    status, _, body = call("GET", graph, headers={"Accept": "application/n-triples"})
    _, head, _ = call("HEAD", graph, headers={"Accept": "application/n-triples"})
    print("GET", status, len(body), "bytes; HEAD Content-Length", head.get("Content-Length"), "Vary", head.get("Vary"))
    print(
        "POST",
        call(
            "POST",
            graph,
            b"<urn:lab16:a> <urn:lab16:b> <urn:lab16:c> .",
            {**auth, "Content-Type": "application/n-triples"},
        )[0],
    )
    print("DELETE", call("DELETE", graph, headers=auth)[0])
    status, headers, body = call("DELETE", graph, headers=auth)
    print("DELETE again", status, "Cbrs-Server" in headers, headers.get("Vary"), body.decode())


if __name__ == "__main__":
    main(sys.argv[1].rstrip("/"), os.environ.get("CBRS_UPDATE_TOKEN", "").strip())
