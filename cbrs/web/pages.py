"""Pages with a JSON twin: every page ``/x`` is also ``/x.json``, the same data without the markup.

A view returns a :class:`Page`; :func:`page` registers both routes and renders whichever was asked. A
form whose input is wrong raises :class:`FormError`; the page is shown again with the message next to
the field (status 400), and the twin answers ``{"error": "invalid-form", "fields": {...}}``.

A page that programs act on (``page(..., negotiate=True)``: the tasks pages) also answers its twin at
its own path when the request prefers JSON (:func:`prefers_json`), as HTTP APIs negotiate: a program
that posts a run to ``/tasks`` with ``Accept: application/json`` got the HTML page.
"""

from __future__ import annotations

import difflib
import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from flask import Blueprint, Response, current_app, jsonify, make_response, render_template, request
from werkzeug.exceptions import HTTPException, MethodNotAllowed, NotFound, RequestEntityTooLarge
from werkzeug.http import HTTP_STATUS_CODES

from cbrs.kb.errors import KnowledgeBaseError, NotFoundError


@dataclass
class Page:
    template: str
    title: str
    data: dict[str, Any] = field(default_factory=dict)
    status: int = 200
    headers: dict[str, str] = field(default_factory=dict)  # sent with either rendering (a 202's Location)


class FormError(KnowledgeBaseError):
    """Input in a form is wrong; ``fields`` maps each field name to what is wrong with it."""

    http_status = 400
    kind = "invalid-form"

    def __init__(self, fields: dict[str, str], page: Page | None = None) -> None:
        self.fields = fields
        self.page = page  # shown again, with the messages beside the fields
        super().__init__("; ".join(f"{name}: {message}" for name, message in fields.items()))


View = Callable[..., Page]


_NEGOTIATED = "cbrs.negotiated_pages"  # app.extensions: the endpoints that answer JSON when it is preferred


def wants_json() -> bool:
    """Whether this request gets a page's JSON twin: its ``.json`` path, or a negotiating page asked for JSON."""
    if request.path.endswith(".json"):
        return True
    return request.endpoint in current_app.extensions.get(_NEGOTIATED, ()) and prefers_json()


def prefers_json() -> bool:
    """``Accept`` ranks ``application/json`` above ``text/html``; or ranks them alike (``*/*``, or no
    ``Accept``) and the body is JSON, which no browser form sends. A browser names ``text/html`` first."""
    accept = request.accept_mimetypes
    json, html = accept["application/json"], accept["text/html"]
    return json > html or (json == html and request.is_json)


def page(blueprint: Blueprint, rule: str, negotiate: bool = False, **options: Any) -> Callable[[View], View]:
    """Register ``view`` at ``rule`` (HTML) and ``rule + '.json'`` (its twin); with ``negotiate``, ``rule``
    answers the twin too when the request prefers JSON (:func:`prefers_json`)."""

    def register(view: View) -> View:
        @functools.wraps(view)
        def respond(**kwargs: Any) -> Response:
            try:
                shown = view(**kwargs)
            except FormError as error:
                if wants_json():
                    return _negotiated(jsonify(error="invalid-form", message=str(error), fields=error.fields), 400)
                if error.page is None:
                    raise
                shown = error.page
                shown.status = 400
                shown.data = {**shown.data, "errors": error.fields}
            if wants_json():
                answer = jsonify(shown.data)
            else:
                answer = make_response(render_template(shown.template, title=shown.title, **shown.data))
            answer.headers.update(shown.headers)
            return _negotiated(answer, shown.status)

        def _negotiated(answer: Response, status: int) -> Response:
            answer.status_code = status
            if negotiate and not request.path.endswith(".json"):
                answer.vary.add("Accept")  # the same URL answers HTML or JSON: caches must key on Accept
            return answer

        json_rule = "/index.json" if rule == "/" else rule + ".json"
        blueprint.add_url_rule(rule, view.__name__, respond, **options)
        blueprint.add_url_rule(json_rule, view.__name__ + "_json", respond, **options)
        if negotiate:
            blueprint.record_once(
                lambda state: state.app.extensions.setdefault(_NEGOTIATED, set()).add(f"{state.name}.{view.__name__}")
            )
        return view

    return register


def error_page(error: KnowledgeBaseError) -> str:
    """A library error as a page, titled by its status ("Not Found"; every such page said "Error"). An
    IRI the store lacks (:class:`NotFoundError`) is named as the pages name it (``home:Pen``, not
    ``<https://w3id.org/cbrs/home#Pen>``), with a link to its own page when the store has triples about
    it under another role (an individual asked for as a class)."""
    from cbrs.web.links import iri_url, short
    from cbrs.web.resource import has_page

    status = error.http_status
    title = HTTP_STATUS_CODES.get(status, "Error")
    if not isinstance(error, NotFoundError):
        return render_template("error.html", title=title, message=str(error))
    name = short(error.iri)
    message = f"no {error.what} {name} in the store" if name != error.iri else str(error)
    own = iri_url(error.iri) if request.endpoint != "resource.resource" and has_page(error.iri) else None
    return render_template(
        "error.html", title=title, message=message, missing={"iri": error.iri, "name": name, "page": own}
    )


def http_error_message(error: HTTPException) -> str:
    """What to tell the client of a Werkzeug error. A 405 names the methods the path takes, and a path
    that no route serves the nearest that do (Werkzeug's own texts, "The method is not allowed for the
    requested URL." and "... please check your spelling", leave a client to guess them)."""
    if isinstance(error, MethodNotAllowed) and error.valid_methods:
        allowed = sorted(set(error.valid_methods) - {"OPTIONS"})
        return f"{request.method} is not allowed on {request.path}: use {' or '.join(allowed)}"
    if isinstance(error, NotFound) and request.url_rule is None:
        paths = {rule.rule for rule in current_app.url_map.iter_rules() if "<" not in rule.rule}
        near = difflib.get_close_matches(request.path, sorted(paths - {"/static"}), n=3, cutoff=0.7)
        meant = f"; did you mean {' or '.join(near)}?" if near else ""
        return f"nothing is served at {request.path}{meant} (the pages start at /, the SPARQL endpoint is /sparql)"
    if isinstance(error, RequestEntityTooLarge):  # Werkzeug: "The data value transmitted exceeds the capacity limit."
        limit = current_app.config.get("MAX_CONTENT_LENGTH")
        most = f" of {limit:,} bytes" if limit else ""
        return (
            f"the request is larger than this server's limit{most} (from the setting max_query_bytes): split the "
            "file, or ask whoever started cbrs serve to load it with cbrs load"
        )
    return error.description or error.name


def keep_error_headers(response: Response, error: HTTPException) -> Response:
    """Give an error answered with our own body the headers Werkzeug's answer would carry: a 405's
    ``Allow`` (RFC 9110 requires it), a 401's ``WWW-Authenticate``."""
    for name, value in error.get_headers():
        if name.lower() != "content-type":
            response.headers[name] = value
    return response
