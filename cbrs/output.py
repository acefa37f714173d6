"""Render query results and descriptions for a terminal: aligned tables, SPARQL JSON/CSV/TSV."""

from __future__ import annotations

import shutil
import sys
import time
from collections.abc import Callable, Iterable
from typing import IO, Any

import pyoxigraph as ox

from cbrs.kb.namespaces import OWL, PREFIXES, RDF, XSD, shorten
from cbrs.kb.skolem import is_skolem
from cbrs.kb.store import QueryResult, Term

RESULT_FORMATS = ("table", "json", "csv", "tsv")

_SOLUTION_FORMATS = {
    "json": ox.QueryResultsFormat.JSON,
    "csv": ox.QueryResultsFormat.CSV,
    "tsv": ox.QueryResultsFormat.TSV,
}
# For CONSTRUCT and DESCRIBE: table shows Turtle, json gives JSON-LD, csv/tsv give N-Triples.
_GRAPH_FORMATS = {
    "table": ox.RdfFormat.TURTLE,
    "json": ox.RdfFormat.JSON_LD,
    "csv": ox.RdfFormat.N_TRIPLES,
    "tsv": ox.RdfFormat.N_TRIPLES,
}


def used_prefixes(statements: Iterable[ox.Triple | ox.Quad]) -> dict[str, str]:
    """The declared prefixes of the namespaces ``statements`` name (an IRI's namespace ends at its last
    ``#`` or ``/``; a literal's datatype counts), for Turtle and TriG that declare what they abbreviate:
    two triples came after 25 ``@prefix`` lines."""
    namespaces = {namespace: prefix for prefix, namespace in PREFIXES.items()}
    used: dict[str, str] = {}
    seen: set[str] = set()
    for statement in statements:
        for term in (statement.subject, statement.predicate, statement.object, getattr(statement, "graph_name", None)):
            iri = (
                term.value
                if isinstance(term, ox.NamedNode)
                else term.datatype.value
                if isinstance(term, ox.Literal)
                else None
            )
            if iri is None or iri in seen:
                continue
            seen.add(iri)
            for end in (iri.rfind("#"), iri.rfind("/")):
                prefix = namespaces.get(iri[: end + 1]) if end >= 0 else None
                if prefix is not None:
                    used[prefix] = iri[: end + 1]
    return dict(sorted(used.items()))


def render_result(result: QueryResult | list[ox.Triple], fmt: str) -> str:
    """The text for a query result in one of ``RESULT_FORMATS``; a list is a graph's triples (as a query
    worker answers a CONSTRUCT or DESCRIBE, cbrs.isolated_queries)."""
    if isinstance(result, ox.QueryTriples | list):
        triples = list(result)
        data = ox.serialize(triples, format=_GRAPH_FORMATS[fmt], prefixes=used_prefixes(triples))
        return data.decode("utf-8") if data else ""
    if fmt in _SOLUTION_FORMATS:
        data = result.serialize(format=_SOLUTION_FORMATS[fmt])
        return data.decode("utf-8") if data else ""
    if isinstance(result, ox.QueryBoolean):
        return "true" if bool(result) else "false"
    names = [v.value for v in result.variables]
    rows = [[term_text(row[name]) for name in names] for row in result]
    return table(names, rows) + f"\n({len(rows)} row{'s' if len(rows) != 1 else ''})"


def term_text(term: Term | None) -> str:
    """A short human form: prefixed IRIs, plain literal values, empty for unbound."""
    if term is None:
        return ""
    if isinstance(term, ox.NamedNode):
        return shorten(term.value)
    if isinstance(term, ox.BlankNode):
        return f"_:{term.value}"
    return " ".join(shorten(part) if "://" in part else part for part in term.value.split(" "))


def sorted_lists(rows: Iterable[dict[str, Term]], columns: Iterable[str]) -> list[dict[str, Term]]:
    """The rows with each of ``columns`` (a ``GROUP_CONCAT`` of IRIs joined by spaces) listing its values
    in IRI order. SPARQL leaves a concatenation's order to the store: the same advertisement's inputs
    came as ``home:GraspPose home:ObjectPosition3D`` from one store and the other way round from a store
    that also held OWLS-TC (16 of the 53 bundled advertisements' lists differed)."""
    names = tuple(columns)
    found = []
    for row in rows:
        row = dict(row)
        for name in names:
            term = row.get(name)
            if isinstance(term, ox.Literal):
                row[name] = ox.Literal(" ".join(sorted(term.value.split())))
        found.append(row)
    return found


def json_row(row: dict[str, Term], lists: Iterable[str]) -> dict[str, Any]:
    """A query row as JSON: each value as text, but each of ``lists`` (a ``GROUP_CONCAT`` of IRIs joined
    by spaces) as a list in IRI order, empty when the row has none, as the browser's JSON twins give them
    (``cbrs services --json`` gave one string, which every reader had to split)."""
    names = tuple(lists)
    found: dict[str, Any] = {k: v.value for k, v in row.items() if k not in names}
    for name in names:
        term = row.get(name)
        found[name] = sorted(term.value.split()) if term is not None else []
    return found


def table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [len(h) for h in headers]
    for row in rows:
        widths = [max(w, len(cell)) for w, cell in zip(widths, row, strict=True)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    lines.extend("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows)
    return "\n".join(lines)


# -- tables cut to a width ----------------------------------------------------------------------

LEAST_LIST = 24
"""Columns a list cut to a width keeps at least: a prefixed name and the count of the others
(``home:ObjectPosition3D +2 more``). With less room beside the other columns, the lists go on a line of
their own under the row."""

LEAST_CUT = 12
"""Columns a list keeps at least on a line of its own: the end of a name and a count (``…Car +1 more``);
a line is wider than the width only where the cells before the lists leave less."""

LIST_INDENT = "    "
LIST_JOINER = " -> "


def output_width(given: int | None, stream: IO[str] | None = None) -> int | None:
    """The width to cut lines to: ``given`` (0 for none); else, when ``stream`` (standard output) is a
    terminal, its width (``COLUMNS`` if set, as :func:`shutil.get_terminal_size` reads it); else ``None``,
    whole lines: a pipe or a file gets what programs and ``grep`` read, one whole line a row."""
    if given is not None:
        return given or None
    stream = stream if stream is not None else sys.stdout
    return shutil.get_terminal_size().columns if stream.isatty() else None


def elided(names: list[str], width: int) -> tuple[str, int]:
    """``names`` joined by spaces, cut to ``width`` columns at a name, with the count of those left out
    (``home:A home:B +3 more``); the first name is cut short (``…``) if even it does not fit. Returns the
    text and how many names are not shown whole."""
    whole = " ".join(names)
    if len(whole) <= width:
        return whole, 0
    shown: list[str] = []
    for name in names:
        rest = len(names) - len(shown) - 1
        if len(" ".join([*shown, name])) + len(f" +{rest} more") > width:
            break
        shown.append(name)
    if not shown:
        tail = f" +{len(names) - 1} more" if len(names) > 1 else ""
        return shortened(names[0], width - len(tail)) + tail, len(names)
    return f"{' '.join(shown)} +{len(names) - len(shown)} more", len(names) - len(shown)


def shortened(name: str, width: int) -> str:
    """``name`` in ``width`` columns (at least its local name's last few): what it names is at its end
    (``http://127.0.0.1/ontology/my_ontology.owl#FourWheeledCar``), so the cut is before its local name,
    with ``…`` (``http://127.…#FourWheeledCar``), or in the local name's start if that is too long."""
    if len(name) <= width:
        return name
    local = max(name.rfind("#"), name.rfind("/"), name.rfind(":"))
    keep = max(width - 1, 4)
    tail = name[local:] if local >= 0 and len(name) - local <= keep else name[-keep:]
    return name[: keep - len(tail)] + "…" + tail


def _shares(needs: list[int], room: int) -> list[int]:
    """``room`` columns shared among lists that need ``needs``: the shorter ones get all they need,
    the longer ones split what is left evenly."""
    given = [0] * len(needs)
    left, waiting = room, len(needs)
    for index in sorted(range(len(needs)), key=lambda i: needs[i]):
        given[index] = min(needs[index], max(left // waiting, 0))
        left -= given[index]
        waiting -= 1
    return given


Cell = str | list[str]


def fitted_table(headers: list[str], rows: list[list[Cell]], width: int | None) -> tuple[str, int]:
    """:func:`table` of ``rows`` whose list cells (lists of names) are cut to ``width`` columns (or
    joined whole for ``None``); other cells are kept whole. When they leave each list fewer than
    :data:`LEAST_LIST` columns, the lists go on a line of their own under each row (``inputs ->
    outputs``, indented). Empty lists show ``-``. Returns the text and how many lists were cut."""
    lists = [i for i, cell in enumerate(rows[0]) if isinstance(cell, list)] if rows else []
    if width is None or not lists:
        return table(headers, [[_joined(c) for c in row] for row in rows]), 0
    plain = [i for i in range(len(headers)) if i not in lists]
    plain_widths = [max([len(headers[i])] + [len(str(row[i])) for row in rows]) for i in plain]
    needs = [max([len(headers[i])] + [len(_joined(row[i])) for row in rows]) for i in lists]
    room = width - sum(plain_widths) - 2 * (len(headers) - 1)
    beside = _shares(needs, room)
    if all(share >= min(need, LEAST_LIST) for share, need in zip(beside, needs, strict=True)):
        cells = [
            [_cut(c, beside[lists.index(i)]) if i in lists else (str(c), 0) for i, c in enumerate(row)] for row in rows
        ]
        cut = sum(1 for row in cells for _, lost in row if lost)
        return table(headers, [[text for text, _ in row] for row in cells]), cut
    return _two_lines(headers, rows, plain, lists, width)


def _joined(cell: Cell) -> str:
    return (" ".join(cell) or "-") if isinstance(cell, list) else cell


def _cut(cell: Cell, width: int) -> tuple[str, int]:
    if not isinstance(cell, list) or not cell:
        return _joined(cell), 0
    return elided(cell, width)


def _two_lines(
    headers: list[str], rows: list[list[Cell]], plain: list[int], lists: list[int], width: int
) -> tuple[str, int]:
    """Each row as two lines: its first cell alone (a name, kept whole), then, indented, its other cells
    and its lists cut to ``width``. The other cells are aligned in columns when that leaves the lists
    at most half the width, and otherwise follow one another (OWLS-TC's device names run to 79 columns)."""
    first, rest = plain[0], plain[1:]
    widths = [max([len(headers[i])] + [len(str(row[i])) for row in rows]) for i in rest]
    aligned = len(LIST_INDENT) + sum(w + 2 for w in widths) <= width // 2  # the lists keep half the line

    def second(cells: list[str], named: list[Cell], cut: bool) -> tuple[str, int]:
        front = LIST_INDENT + "".join((c.ljust(w) if aligned else c) + "  " for c, w in zip(cells, widths, strict=True))
        floor = sum(min(len(_joined(cell)), LEAST_CUT) for cell in named)
        room = max(width - len(front) - len(LIST_JOINER) * (len(lists) - 1), floor)
        shares = _shares([len(_joined(cell)) for cell in named], room)  # a short list leaves the others room
        parts = [
            _cut(cell, max(share, 1)) if cut else (_joined(cell), 0) for cell, share in zip(named, shares, strict=True)
        ]
        return (front + LIST_JOINER.join(text for text, _ in parts)).rstrip(), sum(1 for _, lost in parts if lost)

    head = [headers[first], second([headers[i] for i in rest], [headers[i] for i in lists], False)[0]]
    lines = [*head, "-" * max(len(line) for line in head)]
    cut = 0
    for row in rows:
        text, lost = second([str(row[i]) for i in rest], [row[i] for i in lists], True)
        lines += [str(row[first]), text]
        cut += lost
    return "\n".join(lines), cut


# -- class expressions -------------------------------------------------------------------------

Expression = dict[str, Any]
"""A class expression as JSON: ``{"type": ...}`` with, by type, ``iri`` (``class``, ``property``,
``individual``, ``node``: one not read), ``value`` (``literal``), ``property`` and ``filler`` (``some``, ``only``,
``value``), ``property`` (``self``, ``inverse``), ``property``, ``cardinality`` and maybe ``filler``
(``min``, ``max``, ``exactly``), ``operands`` (``and``, ``or``), ``operand`` (``not``), ``members``
(``oneOf``), ``datatype`` and ``facets`` (``datatype``)."""

EXPRESSION_DEPTH = 4
"""Class expressions nested deeper than this are named by their node (``genid:...``): a restriction
on an intersection of restrictions is as deep as an ontology of this kind goes, and a deeper (or
cyclic) one would not be read on one line anyway."""

_VALUE_RESTRICTIONS = {OWL + "someValuesFrom": "some", OWL + "allValuesFrom": "only", OWL + "hasValue": "value"}
_CARDINALITIES = {
    OWL + "minCardinality": "min",
    OWL + "maxCardinality": "max",
    OWL + "cardinality": "exactly",
    OWL + "minQualifiedCardinality": "min",
    OWL + "maxQualifiedCardinality": "max",
    OWL + "qualifiedCardinality": "exactly",
}
_BOOLEANS = {OWL + "intersectionOf": "and", OWL + "unionOf": "or"}
_FACETS = {"minInclusive": ">=", "maxInclusive": "<=", "minExclusive": ">", "maxExclusive": "<"}

Object = ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple
"""Any term a quad may have as its object."""

QuadsOf = Callable[[ox.NamedNode], Iterable[ox.Quad]]
"""The quads whose subject is a node, in any graph (``lambda n: store.quads(n)``)."""


def class_expression(quads_of: QuadsOf, node: Object, depth: int = EXPRESSION_DEPTH) -> Expression | None:
    """The OWL class expression a skolemised node (a blank node in the source) stands for: a restriction,
    an intersection, union or complement, an enumeration or a datatype restriction. None when the node is
    none of those (a service description's parameter, say)."""
    if not is_skolem(node):
        return None
    found = _expression(quads_of, node, depth, frozenset())
    return None if found["type"] == "node" else found


def _expression(quads_of: QuadsOf, term: Object, depth: int, path: frozenset[str]) -> Expression:
    """``term`` read as a class expression; a node it cannot read (or too deep) as ``{"type": "node"}``."""
    if isinstance(term, ox.Literal):
        return _literal(term)
    if not isinstance(term, ox.NamedNode):
        return {"type": "node", "iri": str(term)}
    if not is_skolem(term):
        return {"type": "class", "iri": term.value}
    if depth <= 0 or term.value in path:
        return {"type": "node", "iri": term.value}
    here = path | {term.value}
    values: dict[str, list[Object]] = {}
    for quad in quads_of(term):
        found = values.setdefault(quad.predicate.value, [])
        if quad.object not in found:
            found.append(quad.object)
    first = {predicate: objects[0] for predicate, objects in values.items() if len(objects) == 1}

    def inner(value: Object) -> Expression:
        return _expression(quads_of, value, depth - 1, here)

    if OWL + "onProperty" in first:
        restriction = _restriction(first, inner)
        if restriction is not None:
            return restriction
    for predicate, kind in _BOOLEANS.items():
        if predicate in first:
            members = _members(quads_of, first[predicate])
            if members is not None:
                return {"type": kind, "operands": [inner(m) for m in members]}
    inverse = first.get(OWL + "inverseOf")
    if isinstance(inverse, ox.NamedNode):
        return {"type": "inverse", "property": {"type": "property", "iri": inverse.value}}
    if OWL + "complementOf" in first:
        return {"type": "not", "operand": inner(first[OWL + "complementOf"])}
    if OWL + "oneOf" in first:
        members = _members(quads_of, first[OWL + "oneOf"])
        if members is not None:
            individuals = [inner(m) for m in members]
            for member in individuals:
                if member["type"] == "class":
                    member["type"] = "individual"
            return {"type": "oneOf", "members": individuals}
    datatype = first.get(OWL + "onDatatype")
    if isinstance(datatype, ox.NamedNode) and OWL + "withRestrictions" in first:
        facets = _members(quads_of, first[OWL + "withRestrictions"])
        if facets is not None:
            read = [_facet(quads_of, facet) for facet in facets]
            if all(item is not None for item in read):
                return {"type": "datatype", "datatype": datatype.value, "facets": read}
    return {"type": "node", "iri": term.value}


def _restriction(first: dict[str, Object], inner: Callable[[Object], Expression]) -> Expression | None:
    prop = inner(first[OWL + "onProperty"])
    if prop["type"] == "node":
        return None
    if prop["type"] == "class":
        prop = {"type": "property", "iri": prop["iri"]}
    for predicate, kind in _VALUE_RESTRICTIONS.items():
        if predicate in first:
            value = first[predicate]
            filler = _literal(value) if isinstance(value, ox.Literal) else inner(value)
            if kind == "value" and filler["type"] == "class":
                filler = {"type": "individual", "iri": filler["iri"]}
            return {"type": kind, "property": prop, "filler": filler}
    if OWL + "hasSelf" in first:
        return {"type": "self", "property": prop}
    for predicate, kind in _CARDINALITIES.items():
        number = first.get(predicate)
        if isinstance(number, ox.Literal):
            try:
                count = int(number.value)
            except ValueError:
                return None
            found: Expression = {"type": kind, "property": prop, "cardinality": count}
            qualifier = first.get(OWL + "onClass", first.get(OWL + "onDataRange"))
            if qualifier is not None:
                found["filler"] = inner(qualifier)
            return found
    return None


def _literal(term: ox.Literal) -> Expression:
    found: Expression = {"type": "literal", "value": term.value}
    if term.language:
        found["language"] = term.language
    else:
        found["datatype"] = term.datatype.value
    return found


def _members(quads_of: QuadsOf, head: Object) -> list[Object] | None:
    """The members of the RDF list at ``head``; None when it is no well-formed list."""
    members: list[Object] = []
    seen: set[Object] = set()
    node = head
    while node != ox.NamedNode(RDF + "nil"):
        if not isinstance(node, ox.NamedNode) or node in seen:
            return None
        seen.add(node)
        links = {q.predicate.value: q.object for q in quads_of(node)}
        if RDF + "first" not in links or RDF + "rest" not in links:
            return None
        members.append(links[RDF + "first"])
        node = links[RDF + "rest"]
    return members


def _facet(quads_of: QuadsOf, node: Object) -> dict[str, Any] | None:
    if not isinstance(node, ox.NamedNode):
        return None
    for quad in quads_of(node):
        if quad.predicate.value.startswith(XSD) and isinstance(quad.object, ox.Literal):
            return {"facet": quad.predicate.value, "value": _literal(quad.object)}
    return None


Namer = Callable[[str, str], str]
"""How :func:`manchester` writes a name: given the kind (``class``, ``property``, ``individual``,
``node``, ``datatype``) and the IRI."""


def _prefixed(kind: str, iri: str) -> str:
    return shorten(iri)


def manchester(
    expression: Expression, nested: bool = False, name: Namer = _prefixed, plain: Callable[[str], str] = str
) -> str:
    """``expression`` in Manchester syntax with prefixed names: ``home:hasPart some home:Gripper``,
    ``home:hasColour value home:Red``, ``home:hasWheel exactly 4 home:Wheel``; an operand that is
    itself compound is put in parentheses. ``name`` writes the names and ``plain`` the literals and
    facets (the browser links the one and escapes the other)."""

    def inner(part: Expression, parenthesised: bool = True) -> str:
        return manchester(part, parenthesised, name, plain)

    kind = expression["type"]
    if kind in ("class", "property", "individual", "node"):
        return name(kind, expression["iri"])
    if kind == "literal":
        return plain(_literal_text(expression))
    if kind == "and" or kind == "or":
        text = f" {kind} ".join(inner(operand) for operand in expression["operands"])
    elif kind == "inverse":
        text = "inverse " + inner(expression["property"])
    elif kind == "not":
        text = "not " + inner(expression["operand"])
    elif kind == "oneOf":
        return "{" + ", ".join(inner(member, False) for member in expression["members"]) + "}"
    elif kind == "datatype":
        facets = ", ".join(
            plain(f"{_FACETS.get(f['facet'].removeprefix(XSD), shorten(f['facet']))} {_literal_text(f['value'])}")
            for f in expression["facets"]
        )
        return f"{name('datatype', expression['datatype'])}[{facets}]"
    else:
        prop = inner(expression["property"])
        if kind == "self":
            text = f"{prop} Self"
        elif "cardinality" in expression:
            filler = f" {inner(expression['filler'])}" if "filler" in expression else ""
            text = f"{prop} {kind} {expression['cardinality']}{filler}"
        else:
            text = f"{prop} {kind} {inner(expression['filler'])}"
    return f"({text})" if nested else text


def _literal_text(literal: Expression) -> str:
    value = str(literal["value"])
    if literal.get("datatype") in (XSD + "integer", XSD + "decimal", XSD + "double", XSD + "boolean"):
        return value
    quoted = '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if "language" in literal:
        return f"{quoted}@{literal['language']}"
    if literal.get("datatype") not in (None, XSD + "string"):
        return f"{quoted}^^{shorten(literal['datatype'])}"
    return quoted


def node_view(quads_of: QuadsOf, quads_into: QuadsOf, node: Object, direction: str = "out") -> dict[str, Any] | None:
    """How ``cbrs show`` names a skolemised node it lists: ``{"text"}`` with ``expression`` (a class
    expression, :func:`class_expression`) and, for a node that points at the shown resource
    (``direction`` "in"), ``owner`` (``{"iri", "path"}``: the named resource it hangs off and the
    properties down to it). ``home:Cup rdfs:subClassOf home:hasPart some home:Handle`` for the restriction
    that names a part, ``svc:Cam / cbrs:hasOWLSModel / cbrs:hasInput`` for a parameter. None for other terms."""
    if not is_skolem(node) or not isinstance(node, ox.NamedNode):
        return None
    if direction != "in":
        expression = class_expression(quads_of, node)
        return None if expression is None else {"text": manchester(expression), "expression": expression}
    owner = _owner(quads_into, node)
    if owner is None:
        expression = class_expression(quads_of, node)
        return None if expression is None else {"text": manchester(expression), "expression": expression}
    iri, path, top = owner
    found: dict[str, Any] = {"owner": {"iri": iri, "path": path}}
    expression = class_expression(quads_of, top)
    if expression is not None:
        found["expression"] = expression
        found["text"] = f"{shorten(iri)} {shorten(path[0])} {manchester(expression)}"
    else:
        steps = [shorten(step) for step in path if step not in (RDF + "first", RDF + "rest")]
        found["text"] = " / ".join([shorten(iri), *steps])
    return found


OWNER_DEPTH = 8
"""How far up :func:`node_view` looks for the named resource a node hangs off."""


def _owner(quads_into: QuadsOf, node: ox.NamedNode) -> tuple[str, list[str], ox.NamedNode] | None:
    """The named resource above ``node``, the properties from it down to ``node``, and the topmost
    skolemised node on the way (the class expression a nested one is part of)."""
    path: list[str] = []
    current = node
    seen = {node}
    for _ in range(OWNER_DEPTH):
        links = sorted(quads_into(current), key=str)
        if not links:
            return None
        link = links[0]  # a blank node of the source has one parent
        path.insert(0, link.predicate.value)
        parent = link.subject
        if not isinstance(parent, ox.NamedNode) or parent in seen:
            return None
        if not is_skolem(parent):
            return parent.value, path, current
        seen.add(parent)
        current = parent
    return None


class ProgressLine:
    """One line on standard error, rewritten as a long command goes (``reading 412/1083``) and cleared at
    the end; nothing unless the stream is a terminal, so piped output and logs stay as they were. A load
    of OWLS-TC printed nothing for half a minute, a 100 MB file nothing for minutes."""

    def __init__(self, stream: IO[str] | None = None, interval: float = 0.1) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.active = self.stream.isatty()
        self.interval = interval
        self._shown = 0
        self._stage = ""
        self._last = 0.0

    def __call__(self, stage: str, done: int, total: int) -> None:
        if not self.active:
            return
        now = time.monotonic()
        if stage == self._stage and now - self._last < self.interval:
            return  # many files a second: a terminal need not redraw for each
        self._stage, self._last = stage, now
        text = f"{stage} {done}/{total} ..." if total else f"{stage} ..."
        text = text[: max(shutil.get_terminal_size().columns - 1, 20)]
        self.stream.write("\r" + text.ljust(self._shown))
        self.stream.flush()
        self._shown = len(text)

    def clear(self) -> None:
        """Remove the line, so that what the command prints next starts on a clean line."""
        if self.active and self._shown:
            self.stream.write("\r" + " " * self._shown + "\r")
            self.stream.flush()
            self._shown = 0
