"""``/store``: the SPARQL 1.1 Graph Store HTTP Protocol, as Oxigraph's server and Fuseki offer it.

``GET``/``HEAD`` ``/store?graph=IRI`` (or ``?default``) answer the graph in the format the Accept header
asks (Turtle by default, and for a browser, whose Accept prefers HTML and then XML); ``GET /store``
answers the whole dataset (TriG or N-Quads). ``PUT`` replaces a graph with the body, ``POST`` adds the
body to it (or, with no graph, adds a TriG or N-Quads body to the store), ``DELETE`` drops it. Writes
need ``Authorization: Bearer <token>``, and pass the checks of :mod:`cbrs.graph_store` (the shapes, the
map, superclasses) before anything is written; a refusal is the error's JSON with its HTTP status.
"""

from __future__ import annotations

from flask import Blueprint, Response, request

from cbrs.graph_store import GraphStore, GraphStoreError, Target
from cbrs.sparql_service import identity_header
from cbrs.web import context
from cbrs.web.sparql import bearer_token, misspelt_parameter

__all__ = ["blueprint"]

blueprint = Blueprint("graph_store", __name__)


def _target() -> Target:
    misspelt = misspelt_parameter(request.args, ("graph", "default"))
    if misspelt:  # "?grpah=" named the whole store: a GET read it all, a POST wrote where cbrs load would
        raise GraphStoreError(f"/store has no parameter {misspelt}")
    return Target.from_parameters(request.args.getlist("graph"), "default" in request.args)


def _store() -> GraphStore:
    return GraphStore(context.sparql())


@blueprint.route("/store", methods=["GET", "HEAD"])
def read() -> Response:
    accept = request.headers.get("Accept")
    if request.accept_mimetypes.best == "text/html":  # a browser following a link: Turtle, not RDF/XML
        accept = "text/turtle"
    data, media_type = _store().read(_target(), accept, request.remote_addr)
    # the body whole for HEAD too: the answer then drops it and keeps its Content-Length (RFC 9110, 9.3.2),
    # where an empty body said Content-Length: 0, a graph of no triples
    return Response(data, content_type=media_type)


@blueprint.after_request
def _headers(response: Response) -> Response:
    """The headers every answer of ``/sparql`` carries, on every answer of ``/store``, its errors too: the
    answer depends on Accept (and its CORS headers on Origin), and the ``Cbrs-Server`` header says what
    server answers (the errors had neither, a 200 ``Vary: Accept`` alone)."""
    response.vary.update(("Accept", "Origin"))
    response.headers.setdefault(*identity_header())
    return response


@blueprint.put("/store")
def replace() -> Response:
    created = _store().replace(_target(), request.get_data(), request.mimetype, bearer_token())
    return Response(status=201 if created else 204)


@blueprint.post("/store")
def add() -> Response:
    _store().add(_target(), request.get_data(), request.mimetype, bearer_token())
    return Response(status=204)


@blueprint.delete("/store")
def drop() -> Response:
    _store().drop(_target(), bearer_token())
    return Response(status=204)
