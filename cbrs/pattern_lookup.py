"""Point lookups answered without the SPARQL engine: one triple pattern read straight from the indexes.

A lookup (``SELECT ?p ?o WHERE { <thing> ?p ?o }``) through pyoxigraph's SPARQL engine is parsed,
planned and evaluated, and the GIL released and taken back twice or so, for a scan of one index range.
``Store.quads_for_pattern`` walks the same range without releasing the GIL, and the W3C JSON results
are a few string joins, written here byte for byte as Oxigraph writes them. On an in-memory store that
is 40 us of CPU a lookup instead of 65 (10 triples); on disk it saves nothing, because
``quads_for_pattern`` reads the subject and the graph name of every quad back from RocksDB, which the
engine does not, so the endpoint takes this path for in-memory stores only (docs/serving.md).

Only a shape whose answer is provably Oxigraph's is taken (:func:`parse`): a single scan
(:func:`cbrs.scan_queries.single_scan`), ``SELECT`` or ``ASK``, over the union default graph (no
``FROM``), whose terms are absolute IRIs, ``a``, variables with ASCII names, or ASCII prefixed names
declared by the query's ``PREFIX`` lines or cbrs's prefix table, and an optional ``LIMIT``. Oxigraph's
union default graph holds a triple once per graph it is in (the default graph too), which is what
``quads_for_pattern`` with no graph yields, and a pattern whose variables are distinct constrains
nothing beyond its bound terms, so every quad read is one solution. Everything else (a literal, whose
equality in SPARQL is not the store's; ``BASE``; a relative IRI; a repeated ``PREFIX`` or projected
variable; a name outside ASCII) is ``None`` and goes to the engine. tests/test_pattern_lookup.py
compares both answers on random stores.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from itertools import islice
from json.encoder import encode_basestring as _quote  # json.dumps(ensure_ascii=False) of a str, in C
from typing import Any

import pyoxigraph as ox

from cbrs.kb.results import releases_results

_RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
_XSD_STRING = "http://www.w3.org/2001/XMLSchema#string"
# SPARQL's VARNAME, PN_PREFIX and PN_LOCAL restricted to ASCII (no escapes): exactly the grammar's there.
_NAME = re.compile(r"[A-Za-z0-9_]+")
_PNAME = re.compile(r"(?P<prefix>[A-Za-z](?:[\w.-]*[\w-])?)?:(?P<local>[\w:](?:[\w.:-]*[\w:-])?)?", re.ASCII)
_DECLARATION = re.compile(r"(?i:PREFIX)\s*(?P<prefix>[^\s:]*):\s*<(?P<iri>[^>]*)>|(?P<base>(?i:BASE))")
_VARIABLE = re.compile(r"[?$](\w+)")
_DEADLINE_EVERY = 64  # solutions written between two looks at the clock
_ASK = {True: b'{"head":{},"boolean":true}', False: b'{"head":{},"boolean":false}'}


@dataclass(frozen=True)
class Lookup:
    """A query :func:`parse` took: the pattern's bound terms (``None`` where a variable stands), the
    variable's name at each position, the projected names (``None`` for ``ASK``) and the ``LIMIT``."""

    pattern: tuple[ox.NamedNode | None, ox.NamedNode | None, ox.NamedNode | None]
    names: tuple[str | None, str | None, str | None]
    projection: tuple[str, ...] | None
    limit: int | None


class Stopped(Exception):
    """The result outgrew its byte budget (``reason`` "too-large") or its deadline ("timeout")."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(reason)


def parse(match: re.Match[str], prefixes: Mapping[str, str]) -> Lookup | None:
    """The lookup a single scan's ``match`` asks for, or ``None`` when it is not a shape this module
    answers exactly as Oxigraph would; ``prefixes`` are those the engine would be given besides the
    query's own (its ``PREFIX`` lines win)."""
    if match.group("s") is None or match.group("dataset"):
        return None
    declared: dict[str, str] = {}
    for declaration in _DECLARATION.finditer(match.string, 0, match.start("form")):
        prefix = declaration.group("prefix")
        if declaration.group("base") or prefix in declared or _iri(declaration.group("iri")) is None:
            return None  # BASE resolves relative IRIs; a prefix declared twice is left to the parser
        declared[prefix] = declaration.group("iri")
    pattern: list[ox.NamedNode | None] = []
    names: list[str | None] = []
    for text in (match.group("s"), match.group("p"), match.group("o")):
        if text[0] in "?$":
            if not _NAME.fullmatch(text, 1):
                return None
            pattern.append(None)
            names.append(text[1:])
            continue
        term = _RDF_TYPE if text == "a" else _term(text, declared, prefixes)
        if term is None:
            return None
        pattern.append(term)
        names.append(None)
    projection: tuple[str, ...] | None = None
    projected = match.group("projection")
    if projected == "*":
        projection = tuple(sorted(name for name in names if name is not None))  # Oxigraph sorts them
    elif projected is not None:
        projection = tuple(_VARIABLE.findall(projected))
        if len(set(projection)) < len(projection) or not all(_NAME.fullmatch(name) for name in projection):
            return None
    limit = match.group("limit")
    if limit is not None and len(limit) > 18:
        return None  # past Oxigraph's integer range: its parser decides
    return Lookup((pattern[0], pattern[1], pattern[2]), (names[0], names[1], names[2]), projection,
                  None if limit is None else int(limit))  # fmt: skip


@releases_results
def json_results(store: ox.Store, lookup: Lookup, limit: int, deadline: float) -> bytes:
    """The SPARQL JSON results of ``lookup`` on ``store``, as Oxigraph writes them; raises
    :class:`Stopped` as soon as they pass ``limit`` bytes or the clock passes ``deadline``."""
    quads: Iterator[ox.Quad] = store.quads_for_pattern(*lookup.pattern)  # every graph: the union default graph
    if lookup.limit is not None:
        quads = islice(quads, lookup.limit)
    if lookup.projection is None:
        found = next(quads, None) is not None
        if time.monotonic() > deadline:
            raise Stopped("timeout")
        return _ASK[found]
    keys = [(f'"{name}":', lookup.names.index(name)) for name in lookup.projection if name in lookup.names]
    head = '{"head":{"vars":[' + ",".join(f'"{name}"' for name in lookup.projection) + ']},"results":{"bindings":['
    rows: list[str] = [head]
    size = len(head) + len("]}}")  # characters: never more than the bytes they encode to
    separator = ""
    for count, quad in enumerate(quads, 1):
        row = separator + "{" + ",".join(key + _json(quad[at]) for key, at in keys) + "}"
        separator = ","
        size += len(row)
        if size > limit:
            raise Stopped("too-large")
        rows.append(row)
        if count % _DEADLINE_EVERY == 0 and time.monotonic() > deadline:
            raise Stopped("timeout")
    rows.append("]}}")
    body = "".join(rows).encode("utf-8")
    if len(body) > limit:
        raise Stopped("too-large")
    if time.monotonic() > deadline:
        raise Stopped("timeout")
    return body


def _term(text: str, declared: Mapping[str, str], prefixes: Mapping[str, str]) -> ox.NamedNode | None:
    """The IRI an IRI reference or prefixed name of the query stands for; ``None`` for anything else."""
    if text[0] == "<":
        return _iri(text[1:-1])
    name = _PNAME.fullmatch(text)
    if name is None:
        return None  # a literal, or a name outside ASCII
    prefix = name.group("prefix") or ""
    namespace = declared[prefix] if prefix in declared else prefixes.get(prefix)
    return None if namespace is None else _iri(namespace + (name.group("local") or ""))


def _iri(value: str) -> ox.NamedNode | None:
    """``value`` as an IRI if it is an absolute one (the parser refuses a relative IRI without ``BASE``)."""
    try:
        return ox.NamedNode(value)
    except ValueError:
        return None


def _json(term: Any) -> str:
    """A term as SPARQL JSON results write it (W3C, with Oxigraph's ``its:dir`` and ``triple``)."""
    kind = type(term)
    if kind is ox.NamedNode:
        return '{"type":"uri","value":' + _quote(term.value) + "}"
    if kind is ox.Literal:
        language = term.language
        if language is not None:
            direction = term.direction
            extra = ',"xml:lang":' + _quote(language)
            if direction is not None:
                extra += ',"its:dir":' + _quote(str(direction))
        else:
            datatype = term.datatype.value
            extra = "" if datatype == _XSD_STRING else ',"datatype":' + _quote(datatype)
        return '{"type":"literal","value":' + _quote(term.value) + extra + "}"
    if kind is ox.BlankNode:
        return '{"type":"bnode","value":' + _quote(term.value) + "}"
    return (
        '{"type":"triple","value":{"subject":' + _json(term.subject) + ',"predicate":' + _json(term.predicate)
        + ',"object":' + _json(term.object) + "}}"
    )  # fmt: skip
