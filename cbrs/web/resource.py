"""The page of any IRI: every triple it is the subject or the object of, grouped by predicate, with its graph,
and the first triples that use it as their predicate (a link to a property was a 404 when the store said
nothing about the property itself: rdf:type and rdfs:label, linked from every resource page).

Every IRI link of the browser leads here (``links.py``). The resource page is not in the navigation, so
it is registered by the taxonomy blueprint (:func:`attach`) rather than through ``PAGES``; its own error
handlers answer a missing, malformed or unknown IRI with an HTML page, or JSON on the ``.json`` twin.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, Response, jsonify, make_response, render_template, request, url_for
from flask.blueprints import BlueprintSetupState
from markupsafe import Markup, escape
from werkzeug.exceptions import BadRequest, HTTPException

from cbrs.kb.errors import KnowledgeBaseError, NotFoundError
from cbrs.kb.namespaces import OWL, RDF, RDFS, XSD, GraphName
from cbrs.web import context
from cbrs.web.graphs import about as graph_note
from cbrs.web.links import display_text, expand_name, iri_link, short
from cbrs.web.pages import Page, error_page, http_error_message, keep_error_headers, page, wants_json

blueprint = Blueprint("resource", __name__)

RDF_TYPE = RDF + "type"
# Values listed per predicate and direction: owl:Class on OWLS-TC is the object of 13,000 rdf:type
# triples, a page of 3.8 MB; the count says how many there are, the SPARQL endpoint has them all.
MAX_VALUES = 500
# Types whose members have a page in the taxonomy.
TERM_TYPES = frozenset(
    {OWL + "Class", RDFS + "Class", OWL + "ObjectProperty", OWL + "DatatypeProperty", RDF + "Property"}
)


def iri_parameter(name: str = "iri") -> str:
    """The full IRI in request parameter ``name`` (an absolute IRI or ``prefix:local``), or 400 saying why."""
    given = (request.values.get(name) or "").strip()
    if not given:
        raise BadRequest(f"the {name!r} parameter is missing: give an IRI, e.g. ?{name}=home:RobotPosition")
    try:
        full = expand_name(given)
        ox.NamedNode(full)  # pyoxigraph checks the IRI's syntax
    except ValueError as error:
        raise BadRequest(f"{name}={given!r} is not an IRI: {error}") from error
    return full


def term_data(term: ox.NamedNode | ox.BlankNode | ox.Literal | ox.Triple) -> dict[str, Any]:
    """A term as JSON: ``{"type": "iri" | "bnode" | "literal", "value", "name"?, "datatype"?, "language"?}``."""
    if isinstance(term, ox.NamedNode):
        return {"type": "iri", "value": term.value, "name": short(term.value)}
    if isinstance(term, ox.Literal):
        found: dict[str, Any] = {"type": "literal", "value": term.value}
        if term.language:
            found["language"] = term.language
        else:
            found["datatype"] = term.datatype.value
        return found
    if isinstance(term, ox.BlankNode):
        return {"type": "bnode", "value": term.value}
    return {"type": "triple", "value": str(term)}


def term_html(term: dict[str, Any]) -> Markup:
    """A term dict (from :func:`term_data`, or a SPARQL JSON binding) as HTML: IRIs linked, literals typed."""
    kind = term.get("type")
    if kind in ("iri", "uri"):
        return iri_link(term["value"])
    if kind == "bnode":
        return Markup(f"<code>_:{escape(term['value'])}</code>")
    if kind not in ("literal", "typed-literal"):
        return Markup(f"<code>{escape(term.get('value', ''))}</code>")
    text = Markup(f'<span class="literal">{escape(term["value"])}</span>')
    language = term.get("language") or term.get("xml:lang")
    datatype = term.get("datatype")
    if language:
        return text + Markup(f' <span class="lang">@{escape(language)}</span>')
    if datatype and datatype != XSD + "string":
        return text + Markup(f' <span class="datatype" title="{escape(datatype)}">{escape(short(datatype))}</span>')
    return text


blueprint.add_app_template_global(term_html, "term_html")


def attach(state: BlueprintSetupState) -> None:
    """Register the resource page on the app another page blueprint is being registered on (once)."""
    if "resource" not in state.app.blueprints:
        state.app.register_blueprint(blueprint)


@page(blueprint, "/resource")
def resource() -> Page:
    iri = iri_parameter()
    kb = context.kb()
    rows = kb.select("resource_triples", {"resource": ox.NamedNode(iri)})
    graph = _named_graph(iri)
    uses = kb.select("predicate_uses", {"predicate": ox.NamedNode(iri)})  # the query reads MAX_VALUES + 1
    if not rows and graph is None and not uses:
        raise NotFoundError(iri)
    outgoing = _grouped(row for row in rows if row["direction"].value == "out")
    incoming = _grouped(row for row in rows if row["direction"].value == "in")
    label = min((row["other"].value for row in rows if _is(row, "out", RDFS + "label")), default=None)
    types = {row["other"].value for row in rows if _is(row, "out", RDF_TYPE)}
    pages = []
    if types & TERM_TYPES:
        pages.append({"text": "In the taxonomy", "href": url_for("taxonomy.concept", iri=iri)})
    if rows and kb.select("description", {"description": ox.NamedNode(iri)}):
        pages.append({"text": "Service description (six-tuple)", "href": url_for("services.service", iri=iri)})
    if graph is not None and graph["triples"]:
        pages.append({"text": "The graph's triples (Turtle)", "href": url_for("graph_store.read", graph=iri)})
    data = {
        "iri": iri,
        "name": short(iri),
        "label": label,
        "pages": pages,
        "counts": {
            "outgoing": _count(outgoing),
            "incoming": _count(incoming),
            "entailed": sum(row["graph"].value == GraphName.ENTAILED.iri for row in rows),
        },
        "outgoing": outgoing,
        "incoming": incoming,
        "graph": graph,
        "as_predicate": {
            "triples": [
                {"subject": term_data(row["subject"]), "object": term_data(row["object"]), "graph": row["graph"].value}
                for row in uses[:MAX_VALUES]
            ],
            "more": len(uses) > MAX_VALUES,
            "query": _uses_query(iri) if uses else None,
        },
    }
    if not wants_json():  # the page's rows; the twin keeps one value per triple
        for group in (*outgoing, *incoming):
            group["rows"] = _merged(group["values"])
    return Page("resource.html", display_text(iri), data)


def _merged(values: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per value with the graphs that state it, in the order the values come: a lab's file loaded
    into graph:ontology and graph:map, as the examples say to, showed each of its triples twice."""
    rows: dict[tuple[str, ...], dict[str, Any]] = {}
    for value in values:
        term = value["term"]
        key = (term["type"], term["value"], term.get("datatype", ""), term.get("language", ""))
        rows.setdefault(key, {"term": term, "graphs": []})["graphs"].append(value["graph"])
    return list(rows.values())


def has_page(iri: str) -> bool:
    """Whether :func:`resource` shows ``iri`` rather than answering 404: a triple names it as subject or
    object, it names a graph, or triples use it as their predicate (the page's own three reads, cheapest
    first). Other pages use it to link an IRI they cannot show themselves (the service page of a class)."""
    kb = context.kb()
    if _named_graph(iri) is not None or kb.describes(iri):
        return True
    return bool(kb.select("predicate_uses", {"predicate": ox.NamedNode(iri)}))


def _uses_query(iri: str) -> str:
    """The SPARQL editor's text that lists every triple with ``iri`` as its predicate (shown to the user
    and run only by the editor; ``iri`` passed :func:`iri_parameter`, so it holds no ``>``)."""
    return f"SELECT ?subject ?object ?graph\nWHERE {{ GRAPH ?graph {{ ?subject <{iri}> ?object }} }}"


def _named_graph(iri: str) -> dict[str, Any] | None:
    """``{"triples": n}`` if ``iri`` names a graph of the store (one of cbrs's, even empty, or any other
    that holds triples), with ``holds`` and ``written_by`` for one of cbrs's (:mod:`cbrs.web.graphs`).
    Every page links graph names here: the overview's table, the graph column of every triple; a graph
    is the subject of no triple, so each such link was a 404."""
    statistics = context.per_generation("graph_statistics", context.kb().statistics)
    if iri in statistics or iri in {graph.iri for graph in GraphName}:
        return {"triples": statistics.get(iri, 0), **(graph_note(iri) or {})}
    return None


def _is(row: dict[str, Any], direction: str, predicate: str) -> bool:
    return bool(row["direction"].value == direction and row["predicate"].value == predicate)


def _count(groups: list[dict[str, Any]]) -> int:
    return sum(group["count"] for group in groups)


def _grouped(rows: Iterable[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows of one direction as ``[{"predicate", "name", "count", "values": [{"term", "graph"}]}]``,
    rdf:type first; at most :data:`MAX_VALUES` values a predicate, ``count`` says how many there are.
    Only the values shown are made into JSON (owl:Class on OWLS-TC has 13,362 under rdf:type)."""
    groups: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        groups.setdefault(row["predicate"].value, []).append(row)
    order = sorted(groups, key=lambda p: (p != RDF_TYPE, short(p).casefold()))
    return [
        {
            "predicate": p,
            "name": short(p),
            "count": len(groups[p]),
            "values": [
                {"term": term_data(row["other"]), "graph": row["graph"].value}
                for row in sorted(groups[p], key=_row_order)[:MAX_VALUES]
            ],
        }
        for p in order
    ]


def _row_order(row: dict[str, Any]) -> tuple[bool, int, str]:
    """What the store states before what the alignments entail from it, then the other term as SPARQL
    orders terms (the named query does not sort: on OWLS-TC sorting owl:Class's 13,362 rows took 2.5 to
    4 s, reading them 0.14 s)."""
    other = row["other"]
    kind = 0 if isinstance(other, ox.BlankNode) else 1 if isinstance(other, ox.NamedNode) else 2
    return row["graph"].value == GraphName.ENTAILED.iri, kind, other.value


# The resource blueprint is not in PAGES, so the app's handlers would answer its errors in JSON; these
# answer them as the other pages do: an HTML page, or JSON on the twin.


@blueprint.errorhandler(KnowledgeBaseError)
def _library_error(error: KnowledgeBaseError) -> tuple[Response | str, int]:
    if not wants_json():
        return error_page(error), error.http_status
    return _failure(error.http_status, getattr(error, "kind", type(error).__name__), "Not found", str(error))


@blueprint.errorhandler(HTTPException)
def _http_error(error: HTTPException) -> Response:
    shown = _failure(error.code or 500, error.name.lower().replace(" ", "-"), error.name, http_error_message(error))
    return keep_error_headers(make_response(*shown), error)


def _failure(status: int, kind: str, title: str, message: str) -> tuple[Response | str, int]:
    if wants_json():
        return jsonify(error=kind, message=message), status
    return render_template("error.html", title=title if status == 404 else "Error", message=message), status
