"""The overview page: what the store holds, and what happened lately."""

from __future__ import annotations

from flask import Blueprint

from cbrs.kb.namespaces import GraphName, shorten
from cbrs.web import context
from cbrs.web.pages import Page, page

blueprint = Blueprint("overview", __name__)


@page(blueprint, "/")
def overview() -> Page:
    kb = context.kb()
    statistics = kb.statistics()
    graphs = [
        {"graph": graph.iri, "name": shorten(graph.iri), "triples": statistics.get(graph.iri, 0)} for graph in GraphName
    ]
    counts = {
        "services": len(kb.select("advertisements")),
        "requirements": len(kb.select("requirements")),
        "actions": len({row["action"].value for row in kb.select("actions")}),
        "triples": sum(statistics.values()),
    }
    return Page(
        "overview.html",
        "Overview",
        {"store": kb.store.location, "graphs": graphs, "counts": counts, "events": context.events().recent()},
    )
