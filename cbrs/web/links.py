"""IRIs shown as links: every IRI on a page leads to the page that shows its triples in and out."""

from __future__ import annotations

from flask import Flask, url_for
from markupsafe import Markup, escape

from cbrs.kb.namespaces import shorten

RESOURCE_ENDPOINT = "resource.resource"


def iri_url(iri: str) -> str:
    return url_for(RESOURCE_ENDPOINT, iri=iri)


def name_parts(iri: str) -> tuple[str, str]:
    """``iri`` as it is shown: ``("", prefixed name)``; for an IRI that no prefix shortens (all of
    OWLS-TC's), the part after its last ``/`` split at ``#``: ``("my_ontology.owl#", "Car")`` rather
    than ``http://127.0.0.1/ontology/my_ontology.owl#Car``, which filled table columns and hid the
    local name at the end. An IRI without such a tail is shown whole."""
    short = shorten(iri)
    if short != iri:
        return "", short
    _, scheme, rest = iri.partition("://")
    _host, slash, path = rest.partition("/")
    if not scheme or not slash or not path or iri.endswith("/"):  # no path to take a tail of
        return "", iri
    namespace, hash_, local = path.rsplit("/", 1)[-1].rpartition("#")
    if not hash_ or not local:
        return "", path.rsplit("/", 1)[-1]
    return namespace + "#", local


def display_text(iri: str) -> str:
    """:func:`name_parts` as plain text (a picture's box, a tooltip)."""
    return "".join(name_parts(iri))


def display_name(iri: str, label: str | None = None) -> Markup:
    """How a link shows ``iri``: ``label`` if given, else :func:`name_parts` with the file part muted
    and the whole IRI left to the link's title. A label equal to the IRI counts as none (pages pass
    the prefixed name along, which for such an IRI is the IRI itself)."""
    if label and label != iri:
        return escape(label)
    namespace, local = name_parts(iri)
    if not namespace:
        return escape(local)
    return Markup(f'<span class="ns">{escape(namespace)}</span>{escape(local)}')


def iri_link(iri: str, label: str | None = None) -> Markup:
    """``<a href="/resource?iri=...">prefix:name</a>``, or the short name alone if there is no such page."""
    text = display_name(iri, label)
    try:
        href = iri_url(iri)
    except Exception:  # the resource page is not registered (a reduced app)
        return Markup(f'<span title="{escape(iri)}">{text}</span>')
    return Markup(f'<a href="{escape(href)}" title="{escape(iri)}">{text}</a>')


def install(app: Flask) -> None:
    app.add_template_global(iri_link, "iri_link")
    app.add_template_global(iri_url, "iri_url")
    app.add_template_global(display_name, "display_name")
    app.add_template_filter(shorten, "short")
