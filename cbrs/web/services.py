"""The services: the advertisements table (filterable by component kind), the requirements, and a page per
service description with its six-tuple ⟨DN, SN, SC, IOPE, SEA, QoS⟩ as ``cbrs show`` gives it."""

from __future__ import annotations

import difflib
from collections.abc import Iterator
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, current_app, request, url_for

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import NotFoundError
from cbrs.kb.model import Advertisement, Requirement
from cbrs.kb.namespaces import RDF, RDFS
from cbrs.kb.store import Term
from cbrs.kb.vocab import CBRS
from cbrs.web import context, resource
from cbrs.web.links import RESOURCE_ENDPOINT, display_text, expand_name, short
from cbrs.web.meets import INLINE_ADVERTISEMENTS, requirements_met, shown_inline
from cbrs.web.pages import FormError, Page, page

blueprint = Blueprint("services", __name__)

MATCH_ENDPOINT = "matchmaking.matchmaking"
PLAN_ENDPOINT = "plans.plans"
PAGE_ROWS = 200  # advertisements a services page shows (CBRS_SERVICES_ROWS); ?page= gives the others


@page(blueprint, "/services")
def services() -> Page:
    kb = context.kb()
    rows = advertisement_rows(kb)
    kinds: dict[str, int] = {}
    for row in rows:
        kinds[row["kind"]] = kinds.get(row["kind"], 0) + 1
    data: dict[str, Any] = {
        "kind": None,
        "kinds": [{"iri": k, "name": short(k), "count": n} for k, n in sorted(kinds.items())],
        "total": len(rows),
        "count": len(rows),
        "page": 1,
        "pages": 1,
        "first": 1 if rows else 0,
        "advertisements": rows,
        "requirements": requirement_rows(kb),
    }
    shown = Page("services.html", "Services", data)
    given = (request.args.get("kind") or "").strip()
    if given:
        try:
            kind = _kind(given)
        except ValueError as error:  # hom:Camera: the prefix is what is wrong, and its did-you-mean says so
            data["kind"] = given
            raise FormError({"kind": str(error)}, page=shown) from None
        if kind not in kinds:
            names = {short(k): k for k in kinds}
            near = difflib.get_close_matches(short(kind), list(names), n=1)
            meant = f"; did you mean {near[0]}? The kinds are" if near else "; the kinds are"
            message = f"no advertisement is of kind {given!r}{meant} {', '.join(sorted(names))}"
            data["kind"] = given
            raise FormError({"kind": message}, page=shown)
        data["kind"] = kind
        rows = [row for row in rows if row["kind"] == kind]
        shown.title = f"Services: {short(kind)}"
    _paged(data, rows, shown)
    return shown


def _paged(data: dict[str, Any], rows: list[dict[str, Any]], shown: Page) -> None:
    """Cut the advertisements into pages of ``CBRS_SERVICES_ROWS`` rows (``?page=``, from 1). OWLS-TC's
    1,136 rows made a page of 1.3 MB that the browser laid out at once."""
    size = int(current_app.config.get("CBRS_SERVICES_ROWS", PAGE_ROWS))
    pages = max(1, -(-len(rows) // size))
    given = (request.args.get("page") or "1").strip()
    data.update({"count": len(rows), "pages": pages, "advertisements": rows[:size], "first": 1 if rows else 0})
    if not given.isdigit() or not 1 <= int(given) <= pages:
        raise FormError({"page": f"{given!r} is not a page from 1 to {pages}"}, page=shown)
    number = int(given)
    start = (number - 1) * size
    data.update({"page": number, "advertisements": rows[start : start + size], "first": start + 1 if rows else 0})


def _kind(given: str) -> str:
    """A kind as typed: a prefixed name (a derived prefix too), an IRI, or a bare name in the core namespace;
    ``ValueError`` (:class:`~cbrs.kb.name_errors.UnknownPrefixError` for ``hom:Camera``) for a name that is
    none: it was taken as typed, and the list said only that no advertisement was of that kind."""
    return expand_name(given if ":" in given else "cbrs:" + given)


@page(blueprint, "/service")
def service() -> Page:
    iri = resource.iri_parameter()
    kb = context.kb()
    try:
        with context.lock():
            description = kb.description(iri)
    except NotFoundError as error:
        if error.iri != iri:
            raise
        return _not_a_description(kb, iri)
    role = "requirement" if isinstance(description, Requirement) else "advertisement"
    data: dict[str, Any] = {"role": role, **description.to_dict(), "conditions_as_text": _text_only(kb, iri)}
    match = MATCH_ENDPOINT in current_app.view_functions
    if isinstance(description, Requirement):
        data["match"] = url_for(MATCH_ENDPOINT, requirement=iri) if match else None
        planned = PLAN_ENDPOINT in current_app.view_functions  # compose it into services, as cbrs plan does
        data["plan"] = url_for(PLAN_ENDPOINT, task=short(iri)) if planned else None
    elif isinstance(description, Advertisement):
        data["requirements"] = _requirements_for(kb, description) if match else []
        data["similar"] = _similar_url(data) if match else None
        data["meets"], data["meets_url"] = _meets(kb, iri) if match else ([], None)
    return Page("service.html", display_text(iri), data)


NEAR_MISS = 0.75  # how close (difflib's ratio) a service's name must be to the one asked to be proposed


def _not_a_description(kb: KnowledgeBase, iri: str) -> Page:
    """404 for an IRI that is no advertisement or requirement, with the ways on: the IRI's own page if
    the store names it (a class, an individual: the page answered only "no service description"), and
    the services whose names are close to it (a typo)."""
    name = short(iri)
    shown = RESOURCE_ENDPOINT in current_app.view_functions and resource.has_page(iri)
    if shown:
        message = f"{name} is in the store, but not as a service description (an advertisement or a requirement)"
    else:
        message = f"no service description {name} in the store, and nothing else of that name"
    data = {
        "error": "NotFoundError",
        "message": message,
        "iri": iri,
        "name": name,
        "resource": url_for(RESOURCE_ENDPOINT, iri=name) if shown else None,
        "meant": _near_misses(kb, iri),
        "services": url_for("services.services"),
    }
    return Page("service_missing.html", "Not a service description", data, status=404)


def _near_misses(kb: KnowledgeBase, iri: str, count: int = 3) -> list[dict[str, str]]:
    """The advertisements and requirements whose names are closest to ``iri``'s, closest first."""
    rows = [(row["service"], row["name"], "advertisement") for row in advertisement_rows(kb)]
    rows += [(row["requirement"], row["name"], "requirement") for row in requirement_rows(kb)]
    asked = short(iri)
    by_name = {(name if asked != iri else full).casefold(): (full, name, role) for full, name, role in rows}
    near = difflib.get_close_matches(asked.casefold(), list(by_name), n=count, cutoff=NEAR_MISS)
    found = [by_name[key] for key in near]
    return [
        {"iri": full, "name": name, "role": role, "href": url_for("services.service", iri=name)}
        for full, name, role in found
        if full != iri
    ]


def _meets(kb: KnowledgeBase, iri: str) -> tuple[list[dict[str, Any]] | None, str | None]:
    """The requirements the advertisement meets, or ``None`` and the link that lists them on a big store
    (:func:`cbrs.web.meets.shown_inline`)."""
    limit = int(current_app.config.get("CBRS_MEETS_INLINE", INLINE_ADVERTISEMENTS))
    if shown_inline(len(advertisement_rows(kb)), limit, request.args.get("meets") == "all"):
        return [m.to_dict() for m in requirements_met(iri)], None
    return None, url_for("services.service", iri=iri, meets="all", _anchor="meets-heading")


_TEXT_ROLES = {CBRS.Precondition: "precondition", CBRS.Effect: "effect", CBRS.DeleteEffect: "delete effect"}


def _text_only(kb: KnowledgeBase, iri: str) -> list[dict[str, str]]:
    """The conditions an OWL-S description gave that the loader could not make statements of, kept as
    their text (``rdfs:seeAlso`` of the model, :mod:`cbrs.kb.owls`): matching does not use them, but
    the page said "No preconditions." of a service that has one (33 of OWLS-TC's 212 expressions)."""
    store = kb.store
    found = []
    for model in _nodes(store.quads(ox.NamedNode(iri), ox.NamedNode(CBRS.hasOWLSModel))):
        for kept in _nodes(store.quads(model, ox.NamedNode(RDFS + "seeAlso"))):
            kinds = {
                q.object.value
                for q in store.quads(kept, ox.NamedNode(RDF + "type"))
                if isinstance(q.object, ox.NamedNode)
            }
            role = next((_TEXT_ROLES[k] for k in sorted(kinds) if k in _TEXT_ROLES), None)
            texts = [q.object for q in store.quads(kept, ox.NamedNode(CBRS.conditionText))]
            if role is not None:
                found += [{"role": role, "text": t.value} for t in texts if isinstance(t, ox.Literal)]
    return sorted(found, key=lambda c: (c["role"], c["text"]))


def _nodes(quads: Iterator[ox.Quad]) -> list[ox.NamedNode | ox.BlankNode]:
    return [q.object for q in quads if isinstance(q.object, ox.NamedNode | ox.BlankNode)]


def _similar_url(description: dict[str, Any]) -> str | None:
    """The matchmaking page asked for what this advertisement offers, written as a requirement: its
    inputs, outputs, preconditions and effects. It ranks the services like this one, itself first; before,
    a service page could only rank the stored requirements."""

    def statements(key: str) -> str:
        return "\n".join(" ".join(short(s[k]) for k in ("subject", "predicate", "object")) for s in description[key])

    asked = {
        "inputs": " ".join(short(p["type"]) for p in description["inputs"]),
        "outputs": " ".join(short(p["type"]) for p in description["outputs"]),
        "preconditions": statements("preconditions"),
        "effects": statements("effects"),
        "deletes": statements("deletes"),
    }
    if not (asked["outputs"] or asked["effects"] or asked["deletes"]):  # nothing a requirement could ask for
        return None
    values: dict[str, Any] = {k: v for k, v in asked.items() if v}
    return url_for(MATCH_ENDPOINT, **values)


def _split(term: Term | None) -> list[str]:
    """A ``GROUP_CONCAT`` of IRIs as a list in IRI order, as ``cbrs services`` gives it: the store's
    order differs between stores (:func:`cbrs.output.sorted_lists`)."""
    return sorted(term.value.split()) if term is not None else []


def _value(term: Term | None) -> str | None:
    return term.value if term is not None else None


def _advertisement_row(row: dict[str, Term]) -> dict[str, Any]:
    iri = row["service"].value
    return {
        "service": iri,
        "name": short(iri),
        "label": _value(row.get("label")),
        "kind": _value(row.get("kind")),
        "device_name": _value(row.get("deviceName")),
        "service_name": _value(row.get("serviceName")),
        "category": _value(row.get("category")),
        "inputs": _split(row.get("inputs")),
        "outputs": _split(row.get("outputs")),
    }


def advertisement_rows(kb: KnowledgeBase) -> list[dict[str, Any]]:
    """Every advertisement as a row of the services table, read once per store generation (the services
    page and the search both list them; OWLS-TC has 1,136). The rows are shared: do not change them."""
    return context.per_generation(
        "advertisement_rows", lambda: [_advertisement_row(r) for r in kb.select("advertisements")]
    )


def requirement_rows(kb: KnowledgeBase) -> list[dict[str, Any]]:
    """Every requirement as a row of the requirements table, shared as :func:`advertisement_rows` are."""
    return context.per_generation("requirement_rows", lambda: _requirement_rows(kb))


def _requirement_rows(kb: KnowledgeBase) -> list[dict[str, Any]]:
    return [
        {
            "requirement": row["requirement"].value,
            "name": short(row["requirement"].value),
            "label": _value(row.get("label")),
            "requested_by": _value(row.get("requestedBy")),
            "task": _value(row.get("task")),
            "inputs": _split(row.get("inputs")),
            "outputs": _split(row.get("outputs")),
        }
        for row in kb.select("requirements")
    ]


def _requirements_for(kb: KnowledgeBase, ad: Advertisement) -> list[dict[str, Any]]:
    """Every requirement, to pick one to match against; first those asking for an output this service gives."""
    offered = {p.type for p in ad.outputs}
    rows = [{**row, "shares_output": bool(offered & set(row["outputs"]))} for row in requirement_rows(kb)]
    return sorted(rows, key=lambda r: (not r["shares_output"], r["name"].casefold()))
