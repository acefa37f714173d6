"""One search over the store by name: classes and properties, advertisements, requirements and the
home's things.

A lab user knows a name (``Price``, ``ceiling camera``, ``FetchMyPen``), not where it lives: before,
each page had a filter of its own and none looked across them. The box in every page's header leads
here. Matches are ranked: an exact name first, then names that start with the text, then the rest;
a service whose inputs or outputs are of a matching concept comes last, saying which.
"""

from __future__ import annotations

import difflib
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, request, url_for

from cbrs.kb.namespaces import RDFS
from cbrs.web import context, services
from cbrs.web.links import expand_name, short
from cbrs.web.pages import FormError, Page, page
from cbrs.web.ranking import IN_LABEL, PREFIX, rank
from cbrs.web.taxonomy import current_taxonomy, local_name

blueprint = Blueprint("search", __name__)

MAX_TEXT = 200  # characters of a search text
SHOWN = 50  # matches listed per group; the count says how many there are

BY_CONCEPT = IN_LABEL + 1  # an advertisement found by the concept of an input or output


@page(blueprint, "/search")
def search() -> Page:
    text = (request.args.get("q") or "").strip()
    data: dict[str, Any] = {"q": text or None, "shown": SHOWN}
    shown = Page("search.html", "Search", data)
    if not text:
        return shown
    if len(text) > MAX_TEXT:
        raise FormError({"q": f"a search text has at most {MAX_TEXT} characters, not {len(text)}"}, page=shown)
    shown.title = f"Search: “{text}”"
    data["iri"] = _resource(text)
    # a prefixed name or IRI is looked for by its local name too: home:Position finds home:Position2D
    needle = (local_name(data["iri"]["iri"]) if data["iri"] else text).casefold()
    data["terms"] = _terms(needle)
    data["advertisements"] = _advertisements(needle, data["terms"]["all"])
    data["requirements"] = _requirements(needle)
    data["things"] = _things(needle)
    data["total"] = sum(data[group]["count"] for group in GROUPS)
    data["meant"] = _meant(needle) if not data["total"] else []
    for group in GROUPS:
        del data[group]["all"]
    return shown


GROUPS = ("terms", "advertisements", "requirements", "things")


def _group(found: list[tuple[int, str, dict[str, Any]]]) -> dict[str, Any]:
    found.sort(key=lambda item: (item[0], item[1].casefold()))
    return {"count": len(found), "matches": [row for _, _, row in found[:SHOWN]], "all": found}


def _resource(text: str) -> dict[str, str] | None:
    """The search text as an IRI or prefixed name the store has triples about, to go straight to."""
    if ":" not in text or any(c.isspace() for c in text):
        return None
    try:
        iri = expand_name(text)
        ox.NamedNode(iri)
    except ValueError:
        return None
    if not context.kb().select("resource_triples", {"resource": ox.NamedNode(iri)}):
        return None
    return {"iri": iri, "name": short(iri)}


def _terms(needle: str) -> dict[str, Any]:
    found = current_taxonomy()
    rows = []
    for term, kind in found.kinds.items():
        label = found.labels.get(term)
        score = rank(needle, (local_name(term),), (label,))
        if score is not None:
            rows.append((score, local_name(term), {**found.term(term), "kind": kind}))
    return _group(rows)


def _advertisements(needle: str, terms: list[tuple[int, str, dict[str, Any]]]) -> dict[str, Any]:
    """Advertisements by name, and then those with an input or output of a concept the text names."""
    concepts = {row["iri"] for score, _, row in terms if score <= PREFIX}
    rows = []
    for ad in services.advertisement_rows(context.kb()):
        score = rank(needle, (ad["service_name"], ad["device_name"], local_name(ad["service"])), (ad["label"],))
        via = sorted({c for c in (*ad["inputs"], *ad["outputs"]) if c in concepts})
        if score is None and via:
            score = BY_CONCEPT
        if score is not None:
            row = {**ad, "via": [{"iri": c, "name": short(c)} for c in via] if score == BY_CONCEPT else []}
            rows.append((score, ad["service_name"] or ad["name"], row))
    return _group(rows)


def _requirements(needle: str) -> dict[str, Any]:
    rows = []
    for requirement in services.requirement_rows(context.kb()):
        score = rank(needle, (local_name(requirement["requirement"]),), (requirement["label"],))
        if score is not None:
            rows.append((score, requirement["name"], requirement))
    return _group(rows)


def _things(needle: str) -> dict[str, Any]:
    """The home's things (rooms, furniture, objects, robots and arms, people, cameras, docking poses, and
    every other physical thing of the map with an extent or a position) by name or label: a lab's visitor,
    bookcase or pen was found nowhere but on the home's picture, and its reading lamp nowhere at all."""
    rows = []
    for thing in context.per_generation("search_home_things", _home_things):
        score = rank(needle, (thing["local"],), (thing["label"],))
        if score is not None:
            rows.append((score, thing["local"], thing))
    return _group(rows)


def _meant(needle: str) -> list[dict[str, str]]:
    """For a text that found nothing (a slip: "reading lamb", "celing camera"), the names and labels the
    search looks in that are closest to it, each with its search: a person who types is not left with four
    empty groups. difflib's ratio at least 0.8, the best three."""
    names: dict[str, str] = {}
    found = current_taxonomy()
    for term in found.kinds:
        names.setdefault(local_name(term).casefold(), local_name(term))
        label = found.labels.get(term)
        if label:
            names.setdefault(label.casefold(), label)
    for ad in services.advertisement_rows(context.kb()):
        for name in (ad["service_name"], ad["device_name"], ad["label"]):
            if name:
                names.setdefault(name.casefold(), name)
    for requirement in services.requirement_rows(context.kb()):
        for name in (local_name(requirement["requirement"]), requirement["label"]):
            if name:
                names.setdefault(name.casefold(), name)
    for thing in context.per_generation("search_home_things", _home_things):
        for name in (thing["local"], thing["label"]):
            if name:
                names.setdefault(name.casefold(), name)
    close = difflib.get_close_matches(needle, list(names), n=3, cutoff=0.8)
    return [{"text": names[key], "url": url_for("search.search", q=names[key])} for key in close]


def _home_things() -> list[dict[str, Any]]:
    """Each thing the home's page draws and lists (``cbrs.home_plan``), with its label; none when the map
    cannot be read (the home's page says why)."""
    from cbrs.home_plan import survey

    with context.lock():  # the map reader goes through the knowledge base's caches
        found = survey(context.kb())
    if found.semantic_map is None:
        return []
    facts = found.semantic_map.facts
    return [
        {
            "iri": entry.iri,
            "name": short(entry.iri),
            "local": entry.name,
            "label": next(iter(facts.get(entry.iri, {}).get(RDFS + "label", [])), None),
            "kind": entry.kind,
            "room": entry.room,
        }
        for entry in found.picture().entries
    ]
