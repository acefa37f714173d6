"""Render query results and descriptions for a terminal: aligned tables, SPARQL JSON/CSV/TSV."""

from __future__ import annotations

import pyoxigraph as ox

from cbrs.kb.namespaces import PREFIXES, shorten
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


def render_result(result: QueryResult, fmt: str) -> str:
    """The text for a query result in one of ``RESULT_FORMATS``."""
    if isinstance(result, ox.QueryTriples):
        data = ox.serialize(list(result), format=_GRAPH_FORMATS[fmt], prefixes=PREFIXES)
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


def table(headers: list[str], rows: list[list[str]]) -> str:
    widths = [len(h) for h in headers]
    for row in rows:
        widths = [max(w, len(cell)) for w, cell in zip(widths, row, strict=True)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    lines.extend("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows)
    return "\n".join(lines)
