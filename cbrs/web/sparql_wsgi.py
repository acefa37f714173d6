"""The hot path of ``/sparql``: a plain query answered without Flask's request machinery.

A robot's point lookup costs Oxigraph about a tenth of a millisecond; Flask's request context, URL
routing, hooks and response object cost three times that, and so decided the endpoint's rate. This
WSGI middleware, wrapped around the Flask app (``app.wsgi_app``), answers the commonest request
itself: a ``GET`` or ``HEAD`` whose only parameters are one ``query`` and optionally ``format`` or
``output``, or a ``POST`` of an ``application/sparql-query`` body with no parameters, from a client
that sends no ``Origin`` (no CORS to answer) and names this server in ``Host``. It calls the same
:meth:`cbrs.sparql_service.SparqlService.query` with the same limits and answers with the same
status, headers and body as the Flask view (``tests/test_sparql_endpoint.py`` compares the two).
Any other request, and any request it is unsure of, goes to Flask unchanged.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Collection, Iterable
from typing import Any
from urllib.parse import parse_qsl, urlsplit

from werkzeug.exceptions import InternalServerError
from werkzeug.http import HTTP_STATUS_CODES

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.sparql_service import SparqlService

log = logging.getLogger("cbrs.web")

WSGIApp = Callable[[dict[str, Any], Callable[..., Any]], Iterable[bytes]]
_SHORT_FORMAT = ("format", "output")
_QUERY_TYPE = "application/sparql-query"
# What every answer of /sparql carries (the blueprint's Vary, the app's other after_request headers).
_COMMON = [("Vary", "Accept, Origin"), ("X-Content-Type-Options", "nosniff"), ("Referrer-Policy", "same-origin")]


class SparqlHotPath:
    """Answers plain ``/sparql`` queries directly and hands every other request to ``app``."""

    def __init__(
        self,
        app: WSGIApp,
        sparql: SparqlService,
        host_names: Callable[[], Collection[str | None] | None],
        max_body: int,
    ) -> None:
        self.app = app
        self.sparql = sparql
        self.host_names = host_names  # the names Host may give, None for any (as cbrs.web._check_host)
        self.max_body = max_body

    def __call__(self, environ: dict[str, Any], start_response: Callable[..., Any]) -> Iterable[bytes]:
        text, short_format = self._plain_query(environ)
        if text is None:
            return self.app(environ, start_response)
        try:
            answer = self.sparql.query(
                text, environ.get("HTTP_ACCEPT"), short_format, client=environ.get("REMOTE_ADDR")
            )
        except KnowledgeBaseError as error:  # as cbrs.web's error handler answers a non-page request
            kind = getattr(error, "kind", type(error).__name__)
            return _json(start_response, environ, error.http_status, {"error": kind, "message": str(error)})
        except Exception:
            log.exception("/sparql failed")
            message = InternalServerError.description
            return _json(start_response, environ, 500, {"error": "internal-server-error", "message": message})
        return _answer(start_response, environ, 200, answer.media_type + "; charset=utf-8", answer.body)

    def _plain_query(self, environ: dict[str, Any]) -> tuple[str | None, str | None]:
        """The query text and short format of a request this path answers; (None, None) for Flask's."""
        if environ.get("PATH_INFO") != "/sparql" or "HTTP_ORIGIN" in environ or not self._host_ok(environ):
            return None, None
        method = environ.get("REQUEST_METHOD")
        try:
            parameters = parse_qsl(environ.get("QUERY_STRING", ""), keep_blank_values=True, errors="strict")
        except (UnicodeDecodeError, ValueError):
            return None, None
        if method in ("GET", "HEAD"):
            names = [name for name, _ in parameters]
            if names.count("query") != 1 or any(names.count(n) > 1 for n in _SHORT_FORMAT):
                return None, None
            if set(names) - {"query", *_SHORT_FORMAT}:
                return None, None
            values = dict(parameters)
            short = values.get("format") or values.get("output")
            return values["query"], short
        if method == "POST" and not parameters:
            media_type = environ.get("CONTENT_TYPE", "").partition(";")[0].strip().lower()
            try:
                length = int(environ.get("CONTENT_LENGTH") or "-1")
            except ValueError:
                return None, None
            if media_type != _QUERY_TYPE or not 0 <= length <= self.max_body:
                return None, None
            body = environ["wsgi.input"].read(length)
            try:
                text = body.decode("utf-8")
            except UnicodeDecodeError:
                environ["wsgi.input"] = _Replay(body)  # Flask reads it again and names the error
                return None, None
            return text, None
        return None, None

    def _host_ok(self, environ: dict[str, Any]) -> bool:
        names = self.host_names()
        if names is None:
            return True
        host = environ.get("HTTP_HOST")
        if not host:
            return False
        try:
            return urlsplit("//" + host).hostname in names
        except ValueError:
            return False


class _Replay:
    """A request body already read, for Flask to read again."""

    def __init__(self, body: bytes) -> None:
        self.body = body

    def read(self, size: int = -1) -> bytes:
        data, self.body = (self.body, b"") if size < 0 else (self.body[:size], self.body[size:])
        return data

    def readline(self, size: int = -1) -> bytes:
        return self.read(size)


def _json(start_response: Callable[..., Any], environ: dict[str, Any], status: int, value: Any) -> list[bytes]:
    body = (json.dumps(value, separators=(",", ":")) + "\n").encode("utf-8")  # as Flask's jsonify writes it
    return _answer(start_response, environ, status, "application/json", body)


def _answer(
    start_response: Callable[..., Any], environ: dict[str, Any], status: int, media_type: str, body: bytes
) -> list[bytes]:
    headers = [("Content-Type", media_type), ("Content-Length", str(len(body))), *_COMMON]
    start_response(f"{status} {HTTP_STATUS_CODES.get(status, 'unknown').upper()}", headers)
    return [] if environ.get("REQUEST_METHOD") == "HEAD" else [body]
