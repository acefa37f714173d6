"""Read RDF files into quads and load them all-or-nothing.

Every file of a load is parsed before anything is written; one that fails to parse aborts the
whole load with its name and line, and the store is left as it was.

Blank nodes are skolemised (RDF 1.1, section 3.5) to IRIs under ``GENID`` that are derived from
the canonical form of the file (RDFC-1.0): loading the same file twice adds nothing the second
time, and every stored node can be named in an update.
"""

from __future__ import annotations

import codecs
import hashlib
import re
import xml.parsers.expat
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from kb.errors import RdfParseError, UnknownFormatError, UnknownGraphError
from kb.namespaces import CBRS, GENID, OWL, RDF, RDFS, GraphName
from kb.store import Store

FORMATS_BY_EXTENSION: dict[str, ox.RdfFormat] = {
    ".ttl": ox.RdfFormat.TURTLE,
    ".turtle": ox.RdfFormat.TURTLE,
    ".nt": ox.RdfFormat.N_TRIPLES,
    ".nq": ox.RdfFormat.N_QUADS,
    ".trig": ox.RdfFormat.TRIG,
    ".n3": ox.RdfFormat.N3,
    ".jsonld": ox.RdfFormat.JSON_LD,
    ".json": ox.RdfFormat.JSON_LD,
    ".rdf": ox.RdfFormat.RDF_XML,
    ".xml": ox.RdfFormat.RDF_XML,
    ".owl": ox.RdfFormat.RDF_XML,  # OWL files are RDF/XML unless their content says Turtle
    ".owls": ox.RdfFormat.RDF_XML,
}

_DECLARATION_TYPES = {OWL + "Class", RDFS + "Class", OWL + "ObjectProperty", OWL + "DatatypeProperty"}
_XML_ENCODING = re.compile(rb"""^(<\?xml[^>]*?encoding\s*=\s*["'])([A-Za-z0-9._-]+)(["'])""")


@dataclass(frozen=True)
class ParsedFile:
    """One parsed file: its quads, ready to store, and the graph its triples went to."""

    source: str
    graph: str
    quads: list[ox.Quad]


def parse_file(path: str | Path, graph: str | GraphName | None = None) -> ParsedFile:
    """Parse one file; ``graph`` (a graph name or IRI) overrides the graph chosen from its content."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise RdfParseError(str(path), f"cannot read: {error.strerror or error}") from error
    return parse_bytes(raw, str(path), rdf_format=_format_for(path, raw), graph=graph)


def parse_bytes(
    raw: bytes,
    source: str,
    rdf_format: ox.RdfFormat,
    graph: str | GraphName | None = None,
    base_iri: str | None = None,
) -> ParsedFile:
    """Parse serialised RDF from memory; ``source`` names it in errors."""
    data = _as_utf8(raw, source)
    base = base_iri or (Path(source).resolve().as_uri() if "://" not in source else source)
    try:
        parsed = list(ox.parse(input=data, format=rdf_format, base_iri=base))
    except SyntaxError as error:
        raise _located(error, source, data, rdf_format) from error
    except ValueError as error:
        raise RdfParseError(source, str(error)) from error
    target = resolve_graph(graph) if graph is not None else _graph_for(parsed)
    quads = [
        ox.Quad(
            q.subject,
            q.predicate,
            q.object,
            target if isinstance(q.graph_name, ox.DefaultGraph) else q.graph_name,
        )
        for q in parsed
    ]
    return ParsedFile(source, target.value, skolemise(quads))


def load_files(
    store: Store, paths: Sequence[str | Path], graph: str | GraphName | None = None
) -> list[ParsedFile]:
    """Parse every file, then add them all in one transaction; nothing is written if any fails."""
    parsed = [parse_file(path, graph) for path in paths]
    store.add(quad for item in parsed for quad in item.quads)
    return parsed


def resolve_graph(graph: str | GraphName) -> ox.NamedNode:
    """A graph given as a cbrs graph name (``services``) or a full IRI."""
    if isinstance(graph, GraphName):
        return graph.node
    try:
        return GraphName(graph).node
    except ValueError:
        pass
    if "://" in graph or graph.startswith("urn:"):
        try:
            return ox.NamedNode(graph)
        except ValueError:
            pass
    raise UnknownGraphError(graph, [g.value for g in GraphName])


def skolemise(quads: Iterable[ox.Quad]) -> list[ox.Quad]:
    """Replace blank nodes with IRIs derived from the canonical form of ``quads``."""
    quads = list(quads)
    if not any(isinstance(t, ox.BlankNode) for q in quads for t in (q.subject, q.object)):
        return quads
    dataset = ox.Dataset(quads)
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    canonical = sorted(dataset, key=str)
    digest = hashlib.sha256("".join(f"{q} .\n" for q in canonical).encode("utf-8")).hexdigest()[:16]

    def named(term: Any) -> Any:
        if isinstance(term, ox.BlankNode):
            return ox.NamedNode(f"{GENID}{digest}-{term.value}")
        return term

    return [ox.Quad(named(q.subject), q.predicate, named(q.object), q.graph_name) for q in canonical]


def _format_for(path: Path, raw: bytes) -> ox.RdfFormat:
    head = _as_utf8(raw[:4096], str(path), strict=False).lstrip()
    looks_turtle = head.startswith((b"@prefix", b"@base", b"PREFIX", b"BASE", b"prefix"))
    looks_xml = head.startswith((b"<?xml", b"<rdf:RDF"))
    known = FORMATS_BY_EXTENSION.get(path.suffix.lower())
    if known == ox.RdfFormat.RDF_XML and looks_turtle:
        return ox.RdfFormat.TURTLE  # OWL files in the wild are Turtle too; the content decides
    if known is not None:
        return known
    if looks_xml:
        return ox.RdfFormat.RDF_XML
    if looks_turtle:
        return ox.RdfFormat.TURTLE
    raise UnknownFormatError(str(path), sorted(FORMATS_BY_EXTENSION))


def _as_utf8(raw: bytes, source: str, strict: bool = True) -> bytes:
    """Re-encode UTF-16/32 or legacy-encoded XML as UTF-8, which the parsers expect."""
    for bom, codec in (
        (codecs.BOM_UTF32_LE, "utf-32"),
        (codecs.BOM_UTF32_BE, "utf-32"),
        (codecs.BOM_UTF8, "utf-8-sig"),
        (codecs.BOM_UTF16_LE, "utf-16"),
        (codecs.BOM_UTF16_BE, "utf-16"),
    ):
        if raw.startswith(bom):
            return _redeclare(_decode(raw, codec, source, strict).encode("utf-8"))
    declared = _XML_ENCODING.match(raw)
    if declared and declared.group(2).lower().replace(b"_", b"-") not in {b"utf-8", b"utf8"}:
        codec = declared.group(2).decode("ascii")
        return _redeclare(_decode(raw, codec, source, strict).encode("utf-8"))
    return raw


def _decode(raw: bytes, codec: str, source: str, strict: bool) -> str:
    try:
        return raw.decode(codec, errors="strict" if strict else "replace")
    except LookupError as error:
        raise RdfParseError(source, f"unknown character encoding {codec!r}") from error
    except UnicodeDecodeError as error:
        raise RdfParseError(source, f"not valid {codec}: byte {error.start} ({error.reason})") from error


def _redeclare(data: bytes) -> bytes:
    return _XML_ENCODING.sub(rb"\g<1>UTF-8\g<3>", data, count=1)


def _located(error: SyntaxError, source: str, data: bytes, rdf_format: ox.RdfFormat) -> RdfParseError:
    message = str(error.args[0]) if error.args else str(error)
    position = error.args[1] if len(error.args) > 1 and isinstance(error.args[1], tuple) else ()
    line = position[1] if len(position) > 1 else None
    column = position[2] if len(position) > 2 else None
    if line is None and rdf_format == ox.RdfFormat.RDF_XML:
        line, column = _xml_error_position(data)
    message = re.sub(
        r"^Parser error (between|at) line \d+ column \d+( and line \d+ column \d+)?: ", "", message
    )
    return RdfParseError(source, message, line, column)


def _xml_error_position(data: bytes) -> tuple[int | None, int | None]:
    """Oxigraph's RDF/XML errors carry no position; expat finds it when the XML is malformed."""
    parser = xml.parsers.expat.ParserCreate()
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as error:
        return error.lineno, error.offset + 1
    return None, None


def _graph_for(quads: list[ox.Quad]) -> ox.NamedNode:
    """The graph for a file's triples when none is given: declarations go to the ontology graph,
    requirements to the requirements graph, everything else to the services graph."""
    types = {
        q.object.value
        for q in quads
        if q.predicate.value == RDF + "type" and isinstance(q.object, ox.NamedNode)
    }
    if types & _DECLARATION_TYPES:
        return GraphName.ONTOLOGY.node
    if CBRS + "Requirement" in types and CBRS + "Advertisement" not in types:
        return GraphName.REQUIREMENTS.node
    return GraphName.SERVICES.node
