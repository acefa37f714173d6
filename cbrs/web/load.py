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

from flask import Blueprint, request, url_for

from cbrs.graph_store import GraphStore, Target
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import GraphName
from cbrs.kb.placement import MisplacedDescriptionError
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
        from_own_page("loaded into the store", "a file")  # "a task may be loaded": the page loads files
        token = bearer_token() or typed or None
        context.sparql().check_token(token)  # first: a page without the token learns nothing of the store
        assert upload is not None and media_type is not None  # checked above
        body = upload.read()
        before = _size(node)
        GraphStore(context.sparql()).add(Target(node.value), body, media_type, token)
    except UpdateForbiddenError as error:
        return _refused(shown, error.http_status, "token", typed_token_refusal(error, typed))
    except MisplacedDescriptionError as error:  # the graph chosen is the fault, not the file
        return _refused(shown, error.http_status, "graph", _misplaced(error, body, name))
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


def _misplaced(error: MisplacedDescriptionError, body: bytes, name: str) -> str:
    """The library's refusal of a task or advertisement in the wrong graph (:func:`cbrs.kb.placement.check_placement`,
    which ``cbrs load --graph`` and the Graph Store meet too) in the page's words: the description named as the
    pages name it, by the prefix its file declares when the store has nothing of its namespace (lab14:FetchMyMug)."""
    use_text_prefixes(declared_prefixes(body.decode("utf-8", "replace")))
    rule = error.rule.replace(f"graph:{error.belongs.value}", f"the {error.belongs.value} graph")
    named = f"{short(error.subject)}, a {short(error.described_as)}"
    return f"{name} describes {error.what} ({named}): {rule}; nothing was loaded"


def _refused(shown: Page, status: int, field: str, message: str) -> Page:
    """The form again, with what is wrong beside the field at fault (a JSON twin: ``error``, ``fields``)."""
    shown.status = status
    shown.data.update(error="invalid-form" if status == 400 else "refused", message=message, errors={field: message})
    return shown


def _size(node: Any) -> int:
    """The graph's triples now (the load says how many it added, as ``cbrs load`` does)."""
    with context.lock():
        return sum(1 for _ in context.kb().store.quads(graph=node))
