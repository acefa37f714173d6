"""Pages with a JSON twin: every page ``/x`` is also ``/x.json``, the same data without the markup.

A view returns a :class:`Page`; :func:`page` registers both routes and renders whichever was asked. A
form whose input is wrong raises :class:`FormError`; the page is shown again with the message next to
the field (status 400), and the twin answers ``{"error": "invalid-form", "fields": {...}}``.
"""

from __future__ import annotations

import difflib
import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from flask import Blueprint, Response, current_app, jsonify, render_template, request
from werkzeug.exceptions import HTTPException, MethodNotAllowed, NotFound

from cbrs.kb.errors import KnowledgeBaseError


@dataclass
class Page:
    template: str
    title: str
    data: dict[str, Any] = field(default_factory=dict)
    status: int = 200


class FormError(KnowledgeBaseError):
    """Input in a form is wrong; ``fields`` maps each field name to what is wrong with it."""

    http_status = 400
    kind = "invalid-form"

    def __init__(self, fields: dict[str, str], page: Page | None = None) -> None:
        self.fields = fields
        self.page = page  # shown again, with the messages beside the fields
        super().__init__("; ".join(f"{name}: {message}" for name, message in fields.items()))


View = Callable[..., Page]


def wants_json() -> bool:
    return request.path.endswith(".json")


def page(blueprint: Blueprint, rule: str, **options: Any) -> Callable[[View], View]:
    """Register ``view`` at ``rule`` (HTML) and ``rule + '.json'`` (its twin)."""

    def register(view: View) -> View:
        @functools.wraps(view)
        def respond(**kwargs: Any) -> Response | tuple[Response, int] | str | tuple[str, int]:
            try:
                shown = view(**kwargs)
            except FormError as error:
                if wants_json():
                    return jsonify(error="invalid-form", message=str(error), fields=error.fields), 400
                if error.page is None:
                    raise
                shown = error.page
                shown.status = 400
                shown.data = {**shown.data, "errors": error.fields}
            if wants_json():
                return jsonify(shown.data), shown.status
            return render_template(shown.template, title=shown.title, **shown.data), shown.status

        json_rule = "/index.json" if rule == "/" else rule + ".json"
        blueprint.add_url_rule(rule, view.__name__, respond, **options)
        blueprint.add_url_rule(json_rule, view.__name__ + "_json", respond, **options)
        return view

    return register


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
    return error.description or error.name


def keep_error_headers(response: Response, error: HTTPException) -> Response:
    """Give an error answered with our own body the headers Werkzeug's answer would carry: a 405's
    ``Allow`` (RFC 9110 requires it), a 401's ``WWW-Authenticate``."""
    for name, value in error.get_headers():
        if name.lower() != "content-type":
            response.headers[name] = value
    return response
