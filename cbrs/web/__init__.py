"""The HTTP side of ``cbrs serve``: the knowledge browser's pages and the SPARQL 1.1 Protocol endpoint.

``create_app`` builds the Flask application over the library objects a server holds; every error a
client causes is answered with a 4xx status and never a trace: an HTML page for a page, JSON
``{"error": kind, "message": text}`` for the ``.json`` twins and the endpoint.
"""

from __future__ import annotations

import functools
import importlib
import secrets
import threading
from collections.abc import Callable, Collection, Sequence
from typing import Any
from urllib.parse import urlsplit

from flask import Flask, Response, g, jsonify, make_response, render_template, request
from werkzeug.exceptions import HTTPException, MisdirectedRequest

from cbrs import __version__
from cbrs.kb.errors import KnowledgeBaseError, without_password
from cbrs.matchmakers import Matchmakers
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import links, warmup
from cbrs.web.context import EventLog, StreamSlots
from cbrs.web.pages import error_page, http_error_message, keep_error_headers, wants_json
from cbrs.web.sparql_wsgi import SparqlHotPath, error_headers
from cbrs.web.strict_request import StrictRequest

# The page blueprints, in navigation order: (module under cbrs.web, endpoint of its nav link, label).
PAGES: tuple[tuple[str, str, str], ...] = (
    ("overview", "overview.overview", "Overview"),
    ("taxonomy", "taxonomy.taxonomy", "Taxonomy"),
    ("services", "services.services", "Services"),
    ("editor", "editor.editor", "SPARQL"),
    ("matchmaking", "matchmaking.matchmaking", "Matchmaking"),
    ("plans", "plans.plans", "Plans"),
    ("home", "home.home", "Home map"),
    ("tasks", "tasks.tasks", "Tasks"),
    ("task_editor", "task_editor.task_editor", "New task"),
)
# Page blueprints reached from every page's header or from links, not from the navigation.
OTHER_PAGES: tuple[str, ...] = ("search", "load")


# Where the pages may load from and be shown: this server only, never in another site's frame.
CONTENT_SECURITY_POLICY = (
    "default-src 'self'; script-src 'self' 'nonce-{nonce}'; style-src 'self'; style-src-attr 'unsafe-inline'; "
    "img-src 'self' data:; connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'self'; "
    "frame-ancestors 'none'"
)
# A picture opened on its own is a document too: no script, whatever its text came from.
SVG_POLICY = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; frame-ancestors 'self'"
LOOPBACK_NAMES = frozenset({"127.0.0.1", "localhost", "::1"})
# Paths only programs ask (the protocols, the components' registrations): errors there are always JSON.
PROGRAM_PATHS = frozenset({"/sparql", "/update", "/store", "/components", "/healthz"})
PROGRAM_PREFIXES = ("/components/",)


def create_app(
    sparql: SparqlService,
    cors_origins: Sequence[str] = (),
    tasks: TaskRunner | None = None,
    matchmakers: Matchmakers | None = None,
    own_origins: Callable[[], Collection[str]] | None = None,
    server_names: Sequence[str] = (),
) -> Flask:
    """The Flask app over ``sparql``'s knowledge base: the browser's pages, ``/sparql``, ``/update`` and
    ``/healthz``. Without ``tasks`` or ``matchmakers``, the app makes its own.

    ``own_origins`` gives the origins this server's pages are served from (``http://127.0.0.1:8080``...),
    from the address it was told to bind, never from a request's ``Host`` header (which DNS rebinding
    sets). ``cbrs serve`` passes them; then a request whose ``Host`` names none of them (when bound to
    loopback, or not one of ``server_names`` when bound to a routable address) is refused, and a task
    may be started only from those pages or with the update token.
    """
    from cbrs.web.graph_store import blueprint as graph_store_blueprint
    from cbrs.web.sparql import blueprint

    # A remote store's URL may carry HTTP basic credentials: every page's footer, /healthz and the
    # overview showed them to anyone who could reach the port.
    shown_location = without_password(sparql.kb.store.location)
    app = Flask(__name__)
    app.request_class = StrictRequest  # a parameter that is not UTF-8 is a 400, not a changed text
    app.debug = False  # whatever FLASK_DEBUG says: the debugger runs code and tracebacks show internals
    app.config["MAX_CONTENT_LENGTH"] = 3 * sparql.config.max_query_bytes + 4096  # form encoding triples bytes
    app.json.sort_keys = False  # type: ignore[attr-defined]
    app.config["CBRS_WARM_UP_TRIPLES"] = warmup.DEFAULT_TRIPLES
    runner = tasks or TaskRunner(sparql.kb, sparql.lock, read_only=sparql.config.read_only)
    log = EventLog()
    runner.subscribe(log.add)
    sparql.on_update(lambda: log.add("/cbrs/events", {"event": "store_updated"}))
    app.extensions.update(
        {
            "cbrs.sparql": sparql,
            "cbrs.tasks": runner,
            "cbrs.matchmakers": matchmakers or Matchmakers(sparql),
            "cbrs.events": log,
            "cbrs.closing": threading.Event(),
            "cbrs.own_origins": own_origins,
            "cbrs.streams": StreamSlots(),
        }
    )
    app.register_blueprint(blueprint)
    app.register_blueprint(graph_store_blueprint)
    for module in (*(module for module, _, _ in PAGES), *OTHER_PAGES):
        app.register_blueprint(importlib.import_module(f"cbrs.web.{module}").blueprint)
    page_blueprints = {module for module, _, _ in PAGES} | set(OTHER_PAGES)
    allowed = frozenset(cors_origins)
    named = frozenset(server_names)
    links.install(app)

    known: list[frozenset[str | None] | None] = []

    def names() -> frozenset[str | None] | None:
        if known:
            return known[0]
        own = frozenset(own_origins()) if own_origins is not None else frozenset()
        if own:  # the server is listening: its address and port stay what they are
            known.append(host_names(own, allowed, named))
        return host_names(own, allowed, named)

    # plain /sparql queries skip Flask's request machinery (cbrs.web.sparql_wsgi), with the same answers
    app.wsgi_app = SparqlHotPath(app.wsgi_app, sparql, names, app.config["MAX_CONTENT_LENGTH"])  # type: ignore[method-assign]

    @app.context_processor
    def shared() -> dict[str, Any]:
        twin = "/index.json" if request.path == "/" else request.path + ".json"
        if request.query_string:
            twin += "?" + request.query_string.decode("utf-8", "replace")
        return {
            "navigation": [(endpoint, label) for _, endpoint, label in PAGES],
            "endpoints": set(app.view_functions),
            "json_twin": twin,
            "version": __version__,
            "store_location": shown_location,
            "csp_nonce": _nonce(),
            "warming": warming.note() if (warming := warmup.current(app)) is not None else None,
        }

    def as_page() -> bool:
        if g.get("sparql_protocol"):  # a SPARQL client's request to a page's path (/query)
            return False
        return request.blueprint in page_blueprints and not wants_json()  # a .json twin, or JSON negotiated

    @app.before_request
    def first_page() -> None:
        if as_page():  # a person is browsing: import what the next pages need (cbrs.web.warmup)
            warmup.preload_once(app)

    @app.get("/healthz")
    def health() -> Response | tuple[Response, int]:
        """200 while the process serves; 503 once the store's disk refused a write (or a query's snapshot),
        which the store remembers (``Store.failure``) until a write succeeds: a monitor of this path saw
        "ok" while every write failed on a full disk. No store read: this stays as cheap as the process."""
        failure = sparql.kb.store.failure
        fields = {"version": __version__, "store": shown_location, "writable": sparql.writable}
        if failure is not None:
            return jsonify(status="failing", error=str(failure), **fields), 503
        return jsonify(status="ok", **fields)

    @app.errorhandler(KnowledgeBaseError)
    def library_error(error: KnowledgeBaseError) -> tuple[Response | str, int]:
        if as_page():
            return error_page(error), error.http_status
        notes = {"notes": error.__notes__} if getattr(error, "__notes__", None) else {}  # "nothing was changed"
        answer = _error(getattr(error, "kind", type(error).__name__), str(error), **notes)
        answer.headers.extend(error_headers(error))  # a busy server's Retry-After
        return answer, error.http_status

    def for_programs() -> bool:
        """A path only programs use (the protocol endpoints, a ``.json`` twin): its errors are JSON even
        when the request accepts HTML, as curl's ``*/*`` does (a 405 or 404 there came as a page)."""
        path = request.path
        return path.endswith(".json") or path in PROGRAM_PATHS or path.startswith(PROGRAM_PREFIXES)

    @app.errorhandler(HTTPException)
    def http_error(error: HTTPException) -> Response:
        status = error.code or 500
        message = http_error_message(error)
        shown: str | Response
        if not (g.get("sparql_protocol") or for_programs()) and (
            as_page() or (request.blueprint is None and request.accept_mimetypes.accept_html)
        ):
            shown = render_template("error.html", title=error.name, message=message)
        else:
            shown = _error(error.name.lower().replace(" ", "-"), message)
        return keep_error_headers(make_response(shown, status), error)

    @app.before_request
    def preflight() -> Response | None:
        if own_origins is not None:
            _check_host(own_origins(), allowed, named)
        if request.method == "OPTIONS" and request.headers.get("Origin") in allowed:
            return Response(status=204)
        return None

    @app.after_request
    def cors(response: Response) -> Response:
        if response.status_code == 204 or (response.status_code == 201 and response.calculate_content_length() == 0):
            response.headers.pop("Content-Type", None)  # no content, so no type (Flask would label it text/html)
        response.headers["X-Content-Type-Options"] = "nosniff"
        response.headers.setdefault("Referrer-Policy", "same-origin")
        if response.mimetype == "text/html":
            response.headers["Content-Security-Policy"] = CONTENT_SECURITY_POLICY.format(nonce=_nonce())
            response.headers["X-Frame-Options"] = "DENY"
        elif response.mimetype == "image/svg+xml":
            response.headers["Content-Security-Policy"] = SVG_POLICY
        origin = request.headers.get("Origin")
        if origin is not None and origin in allowed:
            response.headers["Access-Control-Allow-Origin"] = origin
            response.vary.add("Origin")  # beside Accept, which the SPARQL answers vary on too
            response.headers["Access-Control-Allow-Methods"] = "GET, POST, OPTIONS"
            response.headers["Access-Control-Allow-Headers"] = "Accept, Authorization, Content-Type"
        return response

    return app


def _error(kind: str, message: str, **extra: Any) -> Response:
    return jsonify(error=kind, message=message, **extra)


def _nonce() -> str:
    """This response's script nonce: inline scripts of our templates carry it, injected ones cannot."""
    if "csp_nonce" not in g:
        g.csp_nonce = secrets.token_urlsafe(16)
    return str(g.csp_nonce)


def _check_host(own: Collection[str], cors_origins: Collection[str], server_names: frozenset[str]) -> None:
    """Refuse a request whose ``Host`` is not a name of this server, when it serves only loopback or was
    told its names (``server_names``).

    A page of another site whose name was made to resolve to 127.0.0.1 (DNS rebinding) reaches the
    server as same-origin to the browser, with its own name in ``Host``: that is what gives it away.
    """
    given = urlsplit("//" + request.host).hostname
    names = host_names(frozenset(own), frozenset(cors_origins), server_names)
    if names is not None and given not in names:
        raise MisdirectedRequest(
            f"this server answers to {', '.join(sorted(n for n in names if n))}, not to {given!r} "
            "(a page whose name resolves to this machine is not one of its own)"
        )


@functools.lru_cache(maxsize=16)
def host_names(
    own: frozenset[str], cors_origins: frozenset[str], server_names: frozenset[str] = frozenset()
) -> frozenset[str | None] | None:
    """The host names a request may give: when the server binds only loopback, or was told the names
    clients reach it by (``server_names``, the ``server_names`` setting); ``None``: any (bound to a
    routable address with no names given, clients use names we cannot know)."""
    hosts = {urlsplit(origin).hostname for origin in own}
    if not hosts or (not server_names and not hosts <= LOOPBACK_NAMES | {None}):
        return None
    return frozenset(hosts | LOOPBACK_NAMES | server_names | {urlsplit(origin).hostname for origin in cors_origins})
