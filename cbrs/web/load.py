"""Load a file: a lab's own Turtle (a class, a thing of the home, a component, a task) into one graph,
from the browser.

A person given a server's URL and its update token had no page that writes anything but a task: the SPARQL
editor runs queries only and points at ``/update`` with a header, and New task writes graph:requirements.
The tenth round's reading lamp (its class for the ontology, the lamp for the map) needed the command line.
This page is the Graph Store protocol's ``POST`` (:class:`cbrs.graph_store.GraphStore`, what ``cbrs
--store URL load --graph G FILE`` sends) behind a form: the same checks (shapes, the map, superclasses)
before anything is written, all or nothing. It needs the update token (the page's field or ``Authorization:
Bearer``) and, from a browser, this server's ``Origin``, as a task's save does.
"""

from __future__ import annotations

from pathlib import PurePath
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, request, url_for

from cbrs.graph_store import GraphStore, Target
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.namespaces import RDF, RDFS, GraphName
from cbrs.kb.vocab import CBRS
from cbrs.sparql_service import UpdateForbiddenError
from cbrs.task_drafts import declared_prefixes
from cbrs.web import context
from cbrs.web.links import short, use_text_prefixes
from cbrs.web.pages import FormError, Page, page
from cbrs.web.sparql import bearer_token, typed_token_refusal
from cbrs.web.tasks import from_own_page

blueprint = Blueprint("load", __name__)

# The graphs a lab's file goes into, with what each holds (cbrs load --graph NAME)
GRAPHS = {
    "ontology": "classes and properties (a lab's own kind of thing: lab10:ReadingLamp under home:Lamp)",
    "map": "the things of the home: rooms, furniture, objects with their size and place",
    "services": "advertisements: what a component offers",
    "requirements": "tasks and requirements (New task writes and checks one at a time)",
}
# A file's format by its name's ending, as cbrs load reads it
MEDIA_TYPES = {
    ".ttl": "text/turtle",
    ".nt": "application/n-triples",
    ".n3": "text/n3",
    ".rdf": "application/rdf+xml",
    ".owl": "application/rdf+xml",
    ".xml": "application/rdf+xml",
}
BODY_NAME = "<request body>"  # how the parser names what it read; the page names the file instead


@page(blueprint, "/load", methods=["GET", "POST"])
def load() -> Page:
    """The form; a POST adds the file's triples to the graph chosen (201), or says beside the field what
    is wrong and writes nothing."""
    chosen = request.form.get("graph", "") if request.method == "POST" else request.args.get("graph", "")
    data: dict[str, Any] = {"graphs": GRAPHS, "types": ",".join(MEDIA_TYPES), "form": {"graph": chosen}}
    shown = Page("load.html", "Load a file", data)
    if request.method != "POST":
        return shown
    upload = request.files.get("file")
    name = PurePath(upload.filename).name if upload is not None and upload.filename else ""
    errors = {}
    if chosen not in GRAPHS:
        errors["graph"] = f"choose the graph the file goes into: {', '.join(GRAPHS)}"
    media_type = MEDIA_TYPES.get(PurePath(name).suffix.lower())
    if not name:
        errors["file"] = "choose a file (Turtle, .ttl)"
    elif media_type is None:
        errors["file"] = f"{name}: cbrs reads {', '.join(MEDIA_TYPES)} files; save it as Turtle (.ttl)"
    if errors:
        raise FormError(errors, page=shown)
    typed = request.form.get("token", "").strip()
    node = GraphName[chosen.upper()].node
    try:
        from_own_page("loaded")
        token = bearer_token() or typed or None
        context.sparql().check_token(token)  # first: a page without the token learns nothing of the store
        assert upload is not None and media_type is not None  # checked above
        body = upload.read()
        misplaced = _misplaced(body, media_type, chosen)
        if misplaced:
            return _refused(shown, 400, "graph", f"{name} {misplaced}; nothing was loaded")
        before = _size(node)
        GraphStore(context.sparql()).add(Target(node.value), body, media_type, token)
    except UpdateForbiddenError as error:
        return _refused(shown, error.http_status, "token", typed_token_refusal(error, typed))
    except KnowledgeBaseError as error:  # not RDF, a shape or a map check refused it: nothing was written
        return _refused(shown, error.http_status, "file", str(error).replace(BODY_NAME, name))
    added = _size(node) - before
    shown.status = 201
    shown.title = f"Loaded {name}"
    shown.data["loaded"] = {
        "file": name,
        "graph": f"graph:{chosen}",
        "added": added,
        "next": {"home": url_for("home.home"), "search": url_for("search.search"), "tasks": url_for("tasks.tasks")},
    }
    return shown


def _misplaced(body: bytes, media_type: str, chosen: str) -> str | None:
    """What is wrong with putting the file's descriptions into the graph ``chosen``: a task belongs in
    graph:requirements and a component's advertisement in graph:services, which a file's header says and a
    person choosing from a list may miss. None when it describes neither, or does not parse (the load then
    says why, with the file's line)."""
    try:
        parsed = parse_bytes(body, BODY_NAME, ox.RdfFormat.from_media_type(media_type) or ox.RdfFormat.TURTLE)
    except KnowledgeBaseError:
        return None
    use_text_prefixes(declared_prefixes(body.decode("utf-8", "replace")))  # lab14:FetchMyMug, as the file writes it
    kb = context.kb()
    with context.lock():
        subclasses = kb.store.quads(None, ox.NamedNode(RDFS + "subClassOf"), ox.NamedNode(CBRS.Advertisement))
        advertised = {CBRS.Advertisement} | {
            str(q.subject.value) for q in subclasses if isinstance(q.subject, ox.NamedNode)
        }
    for quad in parsed.quads:
        subject, kind = quad.subject, quad.object
        if quad.predicate.value != RDF + "type" or not isinstance(subject, ox.NamedNode):
            continue
        if not isinstance(kind, ox.NamedNode):
            continue
        if kind.value == CBRS.Requirement and chosen != "requirements":
            return (
                f"describes a task ({short(subject.value)}, a cbrs:Requirement): tasks go into the requirements graph"
            )
        if kind.value in advertised and chosen != "services":
            return (
                f"describes a component's advertisement ({short(subject.value)}, a {short(kind.value)}): "
                "advertisements go into the services graph"
            )
    return None


def _refused(shown: Page, status: int, field: str, message: str) -> Page:
    """The form again, with what is wrong beside the field at fault (a JSON twin: ``error``, ``fields``)."""
    shown.status = status
    shown.data.update(error="invalid-form" if status == 400 else "refused", message=message, errors={field: message})
    return shown


def _size(node: Any) -> int:
    """The graph's triples now (the load says how many it added, as ``cbrs load`` does)."""
    with context.lock():
        return sum(1 for _ in context.kb().store.quads(graph=node))
