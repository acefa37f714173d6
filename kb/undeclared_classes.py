"""Things a write states to be of a class that nothing in the store declares.

A task finds a thing by a class it is stated to be of, or one below it, so a thing of a misspelt class is
found by no task: ``lab11:Flask2 a lab11:Flsk`` loaded without a word, and a task naming ``lab11:Flask``
found the other flask, or none. Not refused: a lab's class may come in a later file. So a load into the map
says so (``cbrs load``, and ``cbrs update`` of an ``INSERT DATA``), with the declared class of the same
namespace it reads as a slip of (:func:`kb.shapes.did_you_mean`). A class is declared when it is the subject
of a statement in any graph; the classes of OWL, RDF, RDFS and XSD need none. docs/tasks.md, "Add an object".

An update by a pattern (``INSERT { } WHERE { }``, ``DELETE/INSERT``) says not which quads it writes until it
has run: :class:`MapTypes` keeps graph:map's ``rdf:type`` statements before it and gives those it added.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

from pyoxigraph import NamedNode, Quad

from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.shapes import did_you_mean
from cbrs.kb.store import Store

__all__ = ["MapTypes", "UndeclaredClass", "written_undeclared_classes"]

_RDF_TYPE = PREFIXES["rdf"] + "type"
_BUILT_IN = tuple(PREFIXES[name] for name in ("owl", "rdf", "rdfs", "xsd"))
"""The vocabularies whose classes a file may state things to be of without declaring them."""
_MAY_WRITE_MAP = re.compile(r"map|\\[uU]|GRAPH(?:\s|#[^\n]*\n)*[?$]|\b(?:ALL|NAMED)\b", re.IGNORECASE)
"""An update that might write graph:map, read loosely (its name, an escape, a variable graph, ALL or NAMED), as
the knowledge base reads it to check the map; any other leaves the map as it was: its statements are not read."""


@dataclass(frozen=True)
class UndeclaredClass:
    """``thing`` is stated to be of ``concept``, which nothing in the store declares; ``meant``: the declared
    class it reads as a slip of, if any."""

    thing: str
    concept: str
    meant: str | None = None

    def text(self) -> str:
        meant = f" (did you mean {_local(self.meant)}, {self.meant}?)" if self.meant else ""
        return (
            f"{_local(self.thing)} ({self.thing}) is stated to be of class {_local(self.concept)} ({self.concept}),"
            f" which nothing in the store declares{meant}: a task finds a thing by a class it is stated to be"
            " of, or one below it; declare the class (in the ontology graph) or correct its name"
        )


def written_undeclared_classes(store: Store, quads: Iterable[Quad]) -> list[UndeclaredClass]:
    """Of the ``rdf:type`` statements among ``quads`` (what a write put in the store), those whose class the
    store declares nowhere, each class once, with the thing first stated to be of it."""
    found: list[UndeclaredClass] = []
    seen: set[str] = set()
    for quad in quads:
        concept = quad.object
        if quad.predicate.value != _RDF_TYPE or not isinstance(concept, NamedNode):
            continue
        if concept.value in seen or concept.value.startswith(_BUILT_IN):
            continue
        seen.add(concept.value)
        if next(iter(store.quads(concept, None, None, None)), None) is not None:
            continue
        thing = quad.subject.value if isinstance(quad.subject, NamedNode) else str(quad.subject)
        found.append(UndeclaredClass(thing, concept.value, did_you_mean(store, concept.value)))
    return found


class MapTypes:
    """graph:map's ``rdf:type`` statements before an update by a pattern, to give those it added
    (:meth:`added`) once it has run. Only those are kept: a class is named by them alone, and the map's
    other statements (positions, sizes) are most of it. An update that cannot write the map keeps none."""

    def __init__(self, store: Store, update: str) -> None:
        self._store = store
        self._before = _map_types(store) if _MAY_WRITE_MAP.search(update) else None

    def added(self) -> list[Quad]:
        """The map's ``rdf:type`` statements now that were not there before, in a stable order."""
        if self._before is None:
            return []
        return sorted(_map_types(self._store) - self._before, key=str)

    def undeclared(self) -> list[UndeclaredClass]:
        """:func:`written_undeclared_classes` of what the update added to the map."""
        added = self.added()
        return written_undeclared_classes(self._store, added) if added else []


def _map_types(store: Store) -> set[Quad]:
    return set(store.quads(None, NamedNode(_RDF_TYPE), None, GraphName.MAP.node))


def _local(iri: str) -> str:
    return iri.rsplit("#", 1)[-1].rsplit("/", 1)[-1]
