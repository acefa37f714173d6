"""IRIs shown as links: every IRI on a page leads to the page that shows its triples in and out."""

from __future__ import annotations

from flask import Flask, url_for
from markupsafe import Markup, escape

from cbrs.kb.namespaces import shorten

RESOURCE_ENDPOINT = "resource.resource"


def iri_url(iri: str) -> str:
    return url_for(RESOURCE_ENDPOINT, iri=iri)


def iri_link(iri: str, label: str | None = None) -> Markup:
    """``<a href="/resource?iri=...">prefix:name</a>``, or the short name alone if there is no such page."""
    text = escape(label or shorten(iri))
    try:
        href = iri_url(iri)
    except Exception:  # the resource page is not registered (a reduced app)
        return Markup(f'<span title="{escape(iri)}">{text}</span>')
    return Markup(f'<a href="{escape(href)}" title="{escape(iri)}">{text}</a>')


def install(app: Flask) -> None:
    app.add_template_global(iri_link, "iri_link")
    app.add_template_global(iri_url, "iri_url")
    app.add_template_filter(shorten, "short")
