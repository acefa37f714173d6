"""The SPARQL editor: write or pick a named query, run it with the endpoint's limits, read the result as a
table (or Turtle), and download it from ``/sparql`` in CSV or JSON. The query travels in the URL, so a
result can be linked to.

A SELECT is run with a ``LIMIT`` of one row more than the page shows (:mod:`cbrs.web.row_limit`): the
engine stops there, the extra row says the result was cut, and the downloads run the query as written.
A CONSTRUCT or DESCRIBE shows as many triples as a SELECT shows rows: on OWLS-TC, ``CONSTRUCT WHERE
{ ?s ?p ?o }`` made a page of 21 MB that Chromium had not drawn after a minute."""

from __future__ import annotations

import json
import time
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, Response, current_app, request, url_for

from cbrs.kb.errors import KnowledgeBaseError, QuerySyntaxError, UnknownQueryError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.sparql_hints import operation_kind, store_prefixes_used
from cbrs.sparql_service import BOM, Answer, EndpointBusyError, QueryTimeoutError
from cbrs.unmentioned_names import unmentioned_names
from cbrs.web import context
from cbrs.web.pages import FormError, Page, page, wants_json
from cbrs.web.prefixes import derived
from cbrs.web.row_limit import bounded
from cbrs.web.sparql import protocol_answer, wants_protocol

blueprint = Blueprint("editor", __name__)

MAX_ROWS = 1000  # rows shown (and in the twin), CBRS_EDITOR_ROWS; the downloads carry all of them
FIRST_EXAMPLE = "advertisements"
# Download formats offered for each result form: (label, the endpoint's format= short name).
DOWNLOADS = {
    "select": (("CSV", "csv"), ("JSON", "json"), ("TSV", "tsv"), ("XML", "xml")),
    "graph": (("Turtle", "turtle"), ("N-Triples", "ntriples"), ("JSON-LD", "jsonld"), ("RDF/XML", "rdfxml")),
}


@blueprint.before_request
def _sparql_client() -> Response | None:
    """``/query`` is also where Oxigraph's layout puts the query endpoint: a SPARQL client (SPARQLWrapper,
    rdflib, Jena, curl) asking there gets the endpoint's answer, a browser the editor."""
    if request.path == "/query" and wants_protocol():
        return protocol_answer()
    return None


@blueprint.after_request
def _vary(response: Response) -> Response:
    if request.path == "/query":  # the page or the endpoint's answer, by the Accept header
        response.vary.update(("Accept", "Origin"))
    return response


@page(blueprint, "/query", methods=["GET", "POST"])
def editor() -> Page:
    kb = context.kb()
    examples = [_example(name) for name in kb.queries.names()]
    chosen = request.values.get("example")
    text = request.values.get("query")
    rows = int(current_app.config.get("CBRS_EDITOR_ROWS", MAX_ROWS))
    data: dict[str, Any] = {
        "query": text,
        "example": chosen,
        "result": None,
        "downloads": [],
        "examples": examples,
        "max_rows": rows,
    }
    shown = Page("editor.html", "SPARQL", data)
    if text is None:
        try:
            data["query"] = kb.queries.get(chosen or FIRST_EXAMPLE).text
        except UnknownQueryError as error:
            data["query"] = ""
            raise FormError({"example": str(error)}, page=shown) from error
        return shown
    if not text.strip():
        raise FormError({"query": "write a query, or pick one of the examples"}, page=shown)
    run, added = with_store_prefixes(text)
    data["added_prefixes"] = [{"prefix": prefix, "namespace": namespace} for prefix, namespace in added.items()]
    data["full_query"] = run
    started = time.perf_counter()
    try:
        data["result"] = _answer(run, rows)
    except QuerySyntaxError as error:
        message = _update_refused() if operation_kind(text) == "update" else str(error)
        if added and operation_kind(text) != "update":
            message += f" (lines counted with the {len(added)} PREFIX lines put above the query)"
        raise FormError({"query": message}, page=shown) from error
    except KnowledgeBaseError as error:  # a timeout, a result too large, busy workers, an evaluation error
        if wants_json():
            raise
        data["failure"] = str(error)
        data["advice"] = _advice(error)
        shown.status = error.http_status
        return shown
    data["elapsed_ms"] = round((time.perf_counter() - started) * 1000, 1)
    if _empty(data["result"]):  # a misspelt term matches nothing: say which names name nothing
        data["notes"] = unmentioned_names(kb, text.removeprefix(BOM), added)
    form = "graph" if data["result"]["kind"] == "graph" else "select"
    data["downloads"] = [
        {"label": label, "format": short, "href": url_for("sparql.sparql", query=run, format=short)}
        for label, short in DOWNLOADS[form]
    ]
    return shown


def _empty(result: dict[str, Any]) -> bool:
    """Whether the page's result (:func:`_result`) holds nothing: no row, no triple, or an ASK's false."""
    return not result["boolean"] if result["kind"] == "ask" else result["count"] == 0


def _advice(error: KnowledgeBaseError) -> str | None:
    """What a person does next about a refused or stopped query, in the words of a class on one server: the
    endpoint's "all 4 query workers are busy; retry shortly (setting query_workers)" named an
    administrator's setting and not that the text is fine and others' queries hold the server."""
    config = context.sparql().config
    if isinstance(error, EndpointBusyError):
        if error.client is not None:
            most = min(config.workers_per_client, config.workers)
            return (
                f"Your computer already runs {most} queries, the most one may run at once; "
                f"each may take up to {config.timeout:g} s. Run this one again when one of them has ended."
            )
        return (
            f"The server runs at most {config.workers} queries at once, and that many are running now (other "
            f"people's, or yours: each may take up to {config.timeout:g} s). Nothing is wrong with this query "
            "as far as the server has read it: run it again in a few seconds."
        )
    if isinstance(error, QueryTimeoutError):
        return (
            f"A query is stopped after {config.timeout:g} s. Patterns that share no variable multiply each "
            "other's rows (every ?a ?b ?c beside every ?d ?e ?f); give them a variable in common, name a class "
            "or a property instead of a variable, or add LIMIT 100 at the end."
        )
    return None


def _update_refused() -> str:
    """What the editor says of an update: it was "SPARQL syntax error: ... POST it as update= ... with the
    update token", which a new user read as a fault of the text, and on a read-only server there is no token."""
    said = "This is a SPARQL update; the editor runs queries and changes nothing."
    if context.sparql().writable:
        return (
            f"{said} To add a file's triples from the browser, use the Load a file page (/load); a program "
            "can POST the update to /update (form field update=) with the update token (docs/serving.md)."
        )
    return f"{said} This server takes no updates: it was started read-only (no update token set)."


def with_store_prefixes(text: str) -> tuple[str, dict[str, str]]:
    """``text`` with a ``PREFIX`` line put above it for each prefix derived for the store
    (:mod:`cbrs.web.prefixes`) that it uses and does not declare, and those prefixes: the results show
    ``books:Novel``, and a query may name it so, although the endpoint knows only cbrs's own prefixes.
    The rule is ``cbrs query``'s (:func:`cbrs.kb.sparql_hints.store_prefixes_used`)."""
    text = text.removeprefix(BOM)
    added = store_prefixes_used(text, derived)  # the table is read only for a query that may use one
    lines = "".join(f"PREFIX {prefix}: <{namespace}>\n" for prefix, namespace in added.items())
    return lines + text, added


def _answer(text: str, rows: int) -> dict[str, Any]:
    """The result of ``text`` as the page shows it (:func:`_result`), read no further than it needs.

    A graph's ``LIMIT`` counts solutions, and a solution may add no new triple: when the bounded
    solutions gave no more triples than the page shows, only the whole result can say whether it has
    more, so it is read then (a small result, or one whose solutions repeat triples)."""
    answer, cut = _run(text, rows)
    result = _result(answer.body, answer.media_type, rows)
    if cut and result["kind"] == "graph" and not result["truncated"]:
        answer = context.sparql().query(text, short_format="turtle", client=request.remote_addr)
        result = _result(answer.body, answer.media_type, rows)
    return result


def _run(text: str, rows: int) -> tuple[Answer, bool]:
    """The answer to ``text``, cut at ``rows`` + 1 solutions so that the engine stops producing and
    serialising solutions past what the page shows, and whether it was cut so (SELECT and ASK come back
    as SPARQL JSON results, CONSTRUCT and DESCRIBE as Turtle)."""
    sparql = context.sparql()
    limited = bounded(text, rows + 1)
    if limited is not None and limited.changed:
        try:
            return sparql.query(limited.text, short_format="turtle", client=request.remote_addr), True
        except QuerySyntaxError:
            pass  # the error as the parser reports it for the text the user wrote, lines and columns included
    return sparql.query(text, short_format="turtle", client=request.remote_addr), False


def _example(name: str) -> dict[str, Any]:
    query = context.kb().queries.get(name)
    parameters = [
        {"name": p.name, "kind": p.kind, "required": p.required, "description": p.description}
        for p in query.parameters.values()
    ]
    return {"name": name, "title": query.title, "text": query.text, "parameters": parameters}


def _result(body: bytes, media_type: str, shown: int) -> dict[str, Any]:
    """The answer as the page shows it: ``{"kind": "select", "vars", "rows", "count", "truncated"}``,
    ``{"kind": "ask", "boolean"}`` or ``{"kind": "graph", "turtle", "count", "truncated"}``. ``rows``
    are the first ``shown`` (a graph's ``turtle``, its first ``shown`` triples); ``count`` is how many
    the page shows, and ``truncated`` says the result has more."""
    if media_type == "text/turtle":
        triples = list(dict.fromkeys(ox.parse(body, ox.RdfFormat.TURTLE)))
        first = triples[:shown]
        return {"kind": "graph", "turtle": _turtle(first), "count": len(first), "truncated": len(triples) > shown}
    parsed = json.loads(body)
    if "boolean" in parsed:
        return {"kind": "ask", "boolean": bool(parsed["boolean"])}
    rows = parsed["results"]["bindings"]
    return {
        "kind": "select",
        "vars": parsed["head"].get("vars", []),
        "rows": rows[:shown],
        "count": min(len(rows), shown),
        "truncated": len(rows) > shown,
    }


def _turtle(triples: list[ox.Triple]) -> str:
    """``triples`` as Turtle, with the prefixes the pages show for the namespaces they use (declared, and
    derived for the store's own namespaces, :mod:`cbrs.web.prefixes`)."""
    namespaces = {namespace: prefix for prefix, namespace in {**derived(), **PREFIXES}.items()}
    used: dict[str, str] = {}
    for triple in triples:
        for term in (triple.subject, triple.predicate, triple.object):
            if isinstance(term, ox.NamedNode):
                iri = term.value
                for end in (iri.rfind("#"), iri.rfind("/")):
                    prefix = namespaces.get(iri[: end + 1]) if end >= 0 else None
                    if prefix is not None:
                        used[prefix] = iri[: end + 1]
    text = ox.serialize(triples, format=ox.RdfFormat.TURTLE, prefixes=dict(sorted(used.items())))
    return text.decode("utf-8") if text is not None else ""
