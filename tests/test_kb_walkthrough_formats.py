"""A lab loading its own data in every format the docs claim: blank nodes are named (so a reload adds
nothing), named graphs of TriG and N-Quads are kept, and a folder's stray JSON is passed over."""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase
from cbrs.kb.loader import expand_paths
from cbrs.kb.namespaces import GENID, GraphName

TURTLE = """@prefix ex: <https://example.org/lab#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
ex:Shelf rdfs:label "Regal für Bücher"@de ; ex:holds [ ex:item ex:Book ; ex:count 3 ] .
"""
TRIPLE_FORMATS = {
    ".ttl": ox.RdfFormat.TURTLE,
    ".nt": ox.RdfFormat.N_TRIPLES,
    ".rdf": ox.RdfFormat.RDF_XML,
    ".jsonld": ox.RdfFormat.JSON_LD,
    ".n3": ox.RdfFormat.N3,
}
LAB = ox.NamedNode("https://example.org/lab#g1")


def _write(tmp_path: Path, suffix: str) -> Path:
    triples = list(ox.parse(TURTLE.encode(), format=ox.RdfFormat.TURTLE))
    path = tmp_path / f"shelf{suffix}"
    if suffix in TRIPLE_FORMATS:
        data = ox.serialize(triples, format=TRIPLE_FORMATS[suffix])
    else:
        quads = [ox.Quad(t.subject, t.predicate, t.object, LAB) for t in triples]
        quads.append(ox.Quad(triples[0].subject, triples[0].predicate, triples[0].object, ox.DefaultGraph()))
        data = ox.serialize(quads, format=ox.RdfFormat.TRIG if suffix == ".trig" else ox.RdfFormat.N_QUADS)
    assert data is not None
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("suffix", [*TRIPLE_FORMATS, ".trig", ".nq"])
def test_every_claimed_format_loads_with_named_blank_nodes(tmp_path: Path, suffix: str) -> None:
    kb = KnowledgeBase.open(":memory:")
    path = _write(tmp_path, suffix)
    kb.load([path])
    once = kb.store.dump()
    kb.load([path])
    assert kb.store.dump() == once  # the blank node got the same name again
    holds = ox.NamedNode("https://example.org/lab#holds")
    nodes = [q.object for q in kb.store.quads(None, holds, None)]
    assert nodes and all(isinstance(n, ox.NamedNode) and n.value.startswith(GENID) for n in nodes)
    label = [q for q in kb.store.quads(None, ox.NamedNode("http://www.w3.org/2000/01/rdf-schema#label"), None)]
    assert {q.object.value for q in label if q.subject.value == "https://example.org/lab#Shelf"} == {"Regal für Bücher"}
    graphs = {q.graph_name for q in kb.store.quads(None, holds, None)}
    assert graphs == ({LAB} if suffix in (".trig", ".nq") else {GraphName.SERVICES.node})


def test_a_folder_s_stray_json_is_passed_over(tmp_path: Path) -> None:
    _write(tmp_path, ".ttl")
    (tmp_path / "config.json").write_text('{"name": "lab", "robots": 3}', encoding="utf-8")
    (tmp_path / "shelf.json").write_bytes(_write(tmp_path, ".jsonld").read_bytes())
    assert [p.name for p in expand_paths([tmp_path])] == ["shelf.json", "shelf.jsonld", "shelf.ttl"]
    assert expand_paths([tmp_path / "config.json"]) == [tmp_path / "config.json"]  # named: read as given


BROKEN = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix ex: <https://example.org/lab#> .

ex:Fine a cbrs:StaticDataComponent ; cbrs:deviceName "Server" ; cbrs:serviceName "Map" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Map ] ] .
# ex:Cam is the one at fault
ex:Cam a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "Cam" ; cbrs:serviceName "Detect" ;
    cbrs:hasQoSModel [ cbrs:responseTime "fast" ] ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] .
"""


@pytest.mark.parametrize(
    ("suffix", "rdf_format"),
    [
        (".ttl", None),
        (".nt", ox.RdfFormat.N_TRIPLES),
        (".rdf", ox.RdfFormat.RDF_XML),
        (".jsonld", ox.RdfFormat.JSON_LD),
    ],
)
def test_a_refused_description_is_named_with_its_file_and_line(
    tmp_path: Path, suffix: str, rdf_format: ox.RdfFormat | None
) -> None:
    path = tmp_path / f"lab{suffix}"
    if rdf_format is None:
        path.write_text(BROKEN, encoding="utf-8")
    else:
        data = ox.serialize(list(ox.parse(BROKEN.encode(), format=ox.RdfFormat.TURTLE)), format=rdf_format)
        assert data is not None
        path.write_bytes(data)
    lines = path.read_text(encoding="utf-8").splitlines()
    kb = KnowledgeBase.open(":memory:")
    with pytest.raises(InvalidDescriptionError) as caught:
        kb.load([path])
    where, _, rest = str(caught.value).partition(": <https://example.org/lab#Cam> is not a valid")
    assert rest and where.startswith(f"{path}:")
    line = lines[int(where.rsplit(":", 1)[1]) - 1].strip()
    subject = {
        ".ttl": "ex:Cam a cbrs:DynamicPerceptionComponent ;",
        ".nt": "<https://example.org/lab#Cam> ",
        ".rdf": "<DynamicPerceptionComponent ",
        ".jsonld": "[{",
    }[suffix]
    assert line.startswith(subject) and ("Cam" in line)
