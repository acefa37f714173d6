"""The HTTP side of ``cbrs serve``: the SPARQL 1.1 Protocol endpoint (and the knowledge browser).

``create_app`` builds the Flask application over the library objects a server holds; every error a
client causes is answered as JSON ``{"error": kind, "message": text}`` with a 4xx status, never a trace.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from flask import Flask, Response, jsonify, request
from werkzeug.exceptions import HTTPException

from cbrs import __version__
from cbrs.sparql_service import SparqlService
from kb.errors import KnowledgeBaseError


def create_app(sparql: SparqlService, cors_origins: Sequence[str] = ()) -> Flask:
    """The Flask app answering ``/sparql``, ``/update`` and ``/healthz`` for ``sparql``'s knowledge base."""
    from cbrs.web.sparql import blueprint

    app = Flask(__name__)
    app.config["MAX_CONTENT_LENGTH"] = 3 * sparql.config.max_query_bytes + 4096  # form encoding triples bytes
    app.extensions["cbrs.sparql"] = sparql
    app.register_blueprint(blueprint)
    allowed = frozenset(cors_origins)

    @app.get("/healthz")
    def health() -> Response:
        return jsonify(status="ok", version=__version__, store=sparql.kb.store.location, writable=sparql.writable)

    @app.errorhandler(KnowledgeBaseError)
    def library_error(error: KnowledgeBaseError) -> tuple[Response, int]:
        return _error(getattr(error, "kind", type(error).__name__), str(error)), error.http_status

    @app.errorhandler(HTTPException)
    def http_error(error: HTTPException) -> tuple[Response, int]:
        status = error.code or 500
        return _error(error.name.lower().replace(" ", "-"), error.description or error.name), status

    @app.before_request
    def preflight() -> Response | None:
        if request.method == "OPTIONS" and request.headers.get("Origin") in allowed:
            return Response(status=204)
        return None

    @app.after_request
    def cors(response: Response) -> Response:
        origin = request.headers.get("Origin")
        if origin is not None and origin in allowed:
            response.headers["Access-Control-Allow-Origin"] = origin
            response.headers["Vary"] = "Origin"
            response.headers["Access-Control-Allow-Methods"] = "GET, POST, OPTIONS"
            response.headers["Access-Control-Allow-Headers"] = "Accept, Authorization, Content-Type"
        return response

    return app


def _error(kind: str, message: str, **extra: Any) -> Response:
    return jsonify(error=kind, message=message, **extra)
