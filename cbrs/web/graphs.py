"""What each of cbrs's named graphs holds and what writes it, as the pages say it beside the graph.

A new store's graph:world, graph:plans and graph:liveness hold no triple, and the overview listed them
with a 0 and nothing else; their pages said "It is the subject of no triple." and "It is the object of
no triple.", which is true of every graph and says nothing of what would fill it. The words are data,
``ontologies/graphs.toml``, read once a process.
"""

from __future__ import annotations

import functools
import tomllib

from cbrs.kb.namespaces import GraphName
from cbrs.kb.resources import ontology_dir

__all__ = ["about"]


def about(iri: str) -> dict[str, str] | None:
    """``{"holds", "written_by"}`` for one of cbrs's graphs; None for any other graph or IRI."""
    return _notes().get(iri)


@functools.cache
def _notes() -> dict[str, dict[str, str]]:
    listed = tomllib.loads((ontology_dir() / "graphs.toml").read_text(encoding="utf-8"))
    return {
        GraphName(name).iri: {"holds": note["holds"], "written_by": note["written_by"]} for name, note in listed.items()
    }
