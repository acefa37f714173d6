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
import re
from collections.abc import Callable, Collection, Iterable
from typing import Any
from urllib.parse import parse_qsl, urlsplit

from werkzeug.exceptions import InternalServerError
from werkzeug.http import HTTP_STATUS_CODES

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.sparql_service import SparqlService, identity_header

log = logging.getLogger("cbrs.web")

WSGIApp = Callable[[dict[str, Any], Callable[..., Any]], Iterable[bytes]]
_SHORT_FORMAT = ("format", "output")
_QUERY_TYPE = "application/sparql-query"
# What every answer of /sparql carries (the blueprint's Vary, the app's other after_request headers).
COMMON_HEADERS = (
    ("Vary", "Accept, Origin"),
    ("X-Content-Type-Options", "nosniff"),
    ("Referrer-Policy", "same-origin"),
    identity_header(),
)


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
        except Exception as error:
            status, body = error_answer(error)
            return _answer(start_response, environ, status, "application/json", body, error_headers(error))
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
            return plain_get(parameters) or (None, None)
        if method == "POST" and not parameters:
            length = plain_post_length(environ.get("CONTENT_TYPE"), environ.get("CONTENT_LENGTH"), self.max_body)
            if length is None:
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
        return names is None or host_allowed(environ.get("HTTP_HOST"), names)


def plain_get(parameters: list[tuple[str, str]]) -> tuple[str, str | None] | None:
    """The query and short format of a GET or HEAD this path answers: its only parameters one ``query``
    and at most one ``format`` or ``output``. None for any other."""
    names = [name for name, _ in parameters]
    if names.count("query") != 1 or any(names.count(n) > 1 for n in _SHORT_FORMAT):
        return None
    if set(names) - {"query", *_SHORT_FORMAT}:
        return None
    values = dict(parameters)
    return values["query"], values.get("format") or values.get("output")


_UTF8 = re.compile(r"charset\s*=\s*\"?utf-?8\"?\s*(?:;|$)", re.IGNORECASE)


def plain_post_length(content_type: str | None, content_length: str | None, max_body: int) -> int | None:
    """The body length of a POST this path answers: an ``application/sparql-query`` body of at most
    ``max_body`` bytes. None for any other."""
    media_type, _, parameters = (content_type or "").partition(";")
    if "charset" in parameters.lower() and not _UTF8.search(parameters):
        return None  # another charset: Flask's view decodes the body as declared
    try:
        length = int(content_length or "-1")
    except ValueError:
        return None
    return length if media_type.strip().lower() == _QUERY_TYPE and 0 <= length <= max_body else None


def host_allowed(host: str | None, names: Collection[str | None]) -> bool:
    """Whether a request's ``Host`` names one of ``names`` (as cbrs.web._check_host)."""
    if not host:
        return False
    try:
        return urlsplit("//" + host).hostname in names
    except ValueError:
        return False


def json_body(value: Any) -> bytes:
    return (json.dumps(value, separators=(",", ":")) + "\n").encode("utf-8")  # as Flask's jsonify writes it


def error_answer(error: Exception) -> tuple[int, bytes]:
    """The status and JSON body of ``/sparql``'s answer to ``error``, as cbrs.web's error handler answers
    a non-page request; anything but a KnowledgeBaseError is logged and answered 500."""
    if isinstance(error, KnowledgeBaseError):
        kind = getattr(error, "kind", type(error).__name__)
        return error.http_status, json_body({"error": kind, "message": str(error)})
    log.error("/sparql failed", exc_info=error)
    return 500, json_body({"error": "internal-server-error", "message": InternalServerError.description})


def error_headers(error: Exception) -> tuple[tuple[str, str], ...]:
    """The headers an answer to ``error`` adds: ``Retry-After`` for one that says when to try again (a
    busy server's, ``retry_after`` seconds), as cbrs.web's error handler adds them."""
    seconds = getattr(error, "retry_after", None)
    return (("Retry-After", str(seconds)),) if seconds else ()


class _Replay:
    """A request body already read, for Flask to read again."""

    def __init__(self, body: bytes) -> None:
        self.body = body

    def read(self, size: int = -1) -> bytes:
        data, self.body = (self.body, b"") if size < 0 else (self.body[:size], self.body[size:])
        return data

    def readline(self, size: int = -1) -> bytes:
        return self.read(size)


def _answer(
    start_response: Callable[..., Any],
    environ: dict[str, Any],
    status: int,
    media_type: str,
    body: bytes,
    extra: tuple[tuple[str, str], ...] = (),
) -> list[bytes]:
    headers = [("Content-Type", media_type), ("Content-Length", str(len(body))), *COMMON_HEADERS, *extra]
    start_response(f"{status} {HTTP_STATUS_CODES.get(status, 'unknown').upper()}", headers)
    return [] if environ.get("REQUEST_METHOD") == "HEAD" else [body]
