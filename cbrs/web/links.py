"""IRIs shown as links: every IRI on a page leads to the page that shows its triples in and out."""

from __future__ import annotations

import re
from collections.abc import Mapping

import pyoxigraph as ox
from flask import Flask, g, has_app_context, url_for
from markupsafe import Markup, escape

from cbrs.iri_tail import tail_parts
from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.kb.namespaces import PREFIXES, expand, shorten
from cbrs.web import context
from cbrs.web.prefixes import by_namespace, derived, namespace

RESOURCE_ENDPOINT = "resource.resource"
TEXT_PREFIXES = "cbrs_text_prefixes"  # flask.g: namespace -> prefix a text of this request declares


def iri_url(iri: str) -> str:
    return url_for(RESOURCE_ENDPOINT, iri=iri)


def short(iri: str) -> str:
    """``iri`` as a prefixed name wherever the browser shortens one: with cbrs's declared prefixes first,
    then with the prefixes derived for the store's other namespaces (:mod:`cbrs.web.prefixes`:
    ``books:Novel``); else the IRI itself."""
    declared = shorten(iri)
    if declared != iri:
        return declared
    ns = namespace(iri)
    prefix = by_namespace().get(ns) if ns is not None else None
    local = iri[len(ns) :] if ns is not None else ""
    if prefix is None and ns is not None and has_app_context():
        prefix = g.get(TEXT_PREFIXES, {}).get(ns)
    if prefix is not None and local and all(ch.isalnum() or ch in "_-." for ch in local):
        return f"{prefix}:{local}"
    return iri


def use_text_prefixes(prefixes: Mapping[str, str]) -> None:
    """For the rest of this request, :func:`short` also names an IRI with ``prefixes`` (name → namespace, a
    text's own ``@prefix`` lines) where no declared or derived prefix covers it: New task's draft of a lab's
    first task (lab14:FetchMyMug), whose namespace the store has nothing of yet. A name the pages give
    another namespace is not taken."""
    taken = {*PREFIXES, *derived()}
    g.setdefault(TEXT_PREFIXES, {}).update({ns: name for name, ns in prefixes.items() if name and name not in taken})


def expand_name(name: str) -> str:
    """A prefixed name the pages show (declared or derived prefix) or an IRI, as an IRI; ``ValueError``
    for a name that is neither (as :func:`cbrs.kb.namespaces.expand`).

    An IRI the store holds is read as itself whatever its scheme: the pages link every IRI they show by
    its text, and since a name of an undeclared prefix is refused (``hom:Cup``), the link to a stored
    ``javascript:alert(1)//x`` or ``isbn:0451450523`` answered 400. A slip names nothing stored."""
    prefix, sep, local = name.partition(":")
    if sep and prefix not in PREFIXES:
        ns = derived().get(prefix)
        if ns is not None:
            return ns + local
    try:
        return expand(name)
    except UnknownPrefixError:
        if _stored(name):
            return name
        raise


def _stored(iri: str) -> bool:
    """Whether the app's store has a triple with ``iri`` as its subject, predicate or object."""
    if not has_app_context():
        return False
    try:
        node = ox.NamedNode(iri)
    except ValueError:
        return False
    store = context.kb().store
    patterns: tuple[dict[str, ox.NamedNode], ...] = ({"subject": node}, {"object": node}, {"predicate": node})
    return any(next(iter(store.quads(**pattern)), None) is not None for pattern in patterns)


def task_name(task: str) -> str:
    """``task`` as the planner reads it (:func:`cbrs.task_names.task_iri`): a name with a prefix the pages
    derived for a lab's namespace (``lab5:FetchPenForVisitor``, as the lists and links show it) as its IRI;
    anything else as typed. The planner knows the declared prefixes alone."""
    prefix, sep, _ = task.partition(":")
    if not sep or prefix in PREFIXES or task.startswith(prefix + "://"):
        return task
    try:
        return expand_name(task)
    except ValueError:
        return task


def name_parts(iri: str) -> tuple[str, str]:
    """``iri`` as it is shown: ``("", prefixed name)`` with a declared or derived prefix
    (:func:`short`); for an IRI that neither shortens, its tail (:func:`tail_parts`)."""
    short_name = short(iri)
    if short_name != iri:
        return "", short_name
    return tail_parts(iri)


def display_text(iri: str) -> str:
    """:func:`name_parts` as plain text (a picture's box, a tooltip)."""
    return "".join(name_parts(iri))


def shown_term(name: str) -> str:
    """A term a page's heading or title names as the pages show it (:func:`display_text`) when it is an
    IRI, else as written: "Plan for https://example.org/lab5#FetchPenForVisitor" headed the plan of a lab's
    task that the list beside it names ``lab5:FetchPenForVisitor``."""
    return display_text(name) if "://" in name else name


def shown_task(listed: str, iri: str | None) -> str:
    """A task as the pages name it, ``listed`` as the list (or the user) spells it: by the rule a run's events
    and record use (:func:`cbrs.tasks.shown_name`), with the pages' own prefixes (:func:`short`); a name
    that means no task (``iri`` None) as :func:`shown_term` shows it."""
    from cbrs.tasks import shown_name

    return shown_name(listed, iri, short) if iri else shown_term(listed)


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


# An IRI inside a sentence: up to a space, a quote or an angle bracket, and not ending in the sentence's
# punctuation (a reason that ends "... of <IRI>." or "(<IRI>)").
_IRI_IN_TEXT = re.compile(r"""https?://[^\s<>"']*[^\s<>"'.,;:)\]]""")


def short_text(text: str) -> str:
    """``text`` with each IRI in it shortened as the pages show it (:func:`short`): the executor's reasons
    ("injected failure of https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01") read better
    as ``svc:LocateMobileRobot_CeilingCamera01``, as the step's component beside them is shown."""
    return _IRI_IN_TEXT.sub(lambda found: short(found.group(0)), text)


def install(app: Flask) -> None:
    app.add_template_global(iri_link, "iri_link")
    app.add_template_global(iri_url, "iri_url")
    app.add_template_global(display_name, "display_name")
    app.add_template_filter(short, "short")
    app.add_template_filter(short_text, "short_text")
    app.add_template_filter(shown_term, "shown_term")
