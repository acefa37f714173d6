"""What the home's pages call the things of the map that none of their own groups draws: a lab's lamp, a
tap lever, a door sensor.

The picture (:mod:`cbrs.home_plan`) drew what the map reader sorts the map into (rooms, walls, furniture,
water dispensers, objects, robots, arms, people, cameras, docking poses), so ``lab10:ReadingLamp1``, a
``home:Lamp`` with an extent in the living room, was on no page and the search did not find it. The rule
here comes from the store alone: an individual of the map with an extent (``home:minX`` ..) or a position
(``home:x``, ``home:y``) that is a ``home:PhysicalObject`` by the taxonomy is one of the home's things,
and its kind is the class it is grouped by: its ancestor just below the first of :data:`GROUPED_UNDER` it
falls under (``home:Appliance`` for a reading lamp, ``home:ApplianceComponent`` for a tap lever, a lab's
own class under ``home:PhysicalObject`` for itself), named by that class's label. A room, a region or a
docking pose is a place or a pose, not a physical object, and stays out. docs/web.md, "The home".
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from cbrs.kb.knowledge_base import KnowledgeBase
from cbrs.kb.namespaces import RDFS
from cbrs.kb.semantic_map import HOME, SemanticMap, local_name

__all__ = ["GROUPED_UNDER", "PHYSICAL", "Kind", "others", "position", "read_kinds"]

PHYSICAL = HOME + "PhysicalObject"
"""What a thing of the map must be, by the taxonomy, to be one of the home's things."""
GROUPED_UNDER = (HOME + "Artifact", PHYSICAL)
"""A thing is grouped by its class just below the first of these it is under: nearly everything made is a
``home:Artifact``, so the level below it (appliance, device, furniture, building element, ...) says what a
thing is; a lab's class straight under ``home:PhysicalObject`` is its own group."""


@dataclass(frozen=True)
class Kind:
    """The class a thing is grouped by, and its name on the pages (the class's label, else its local name
    in words)."""

    iri: str
    name: str

    @property
    def plural(self) -> str:
        if self.name.endswith(("s", "x", "ch", "sh")):
            return self.name + "es"
        if re.search(r"[^aeiou]y$", self.name):
            return self.name[:-1] + "ies"
        return self.name + "s"


def others(smap: SemanticMap) -> list[str]:
    """The map's things with an extent or a position that none of the reader's groups holds: what the
    pages list and draw as they are (:func:`read_kinds` says which of them are physical things)."""
    grouped: set[str] = set().union(
        smap.rooms,
        smap.walls,
        smap.furniture,
        smap.bodies,
        smap.dispensers,
        smap.objects,
        smap.robots,
        smap.people,
        smap.cameras,
        smap.arms,
    )
    found = {iri for iri in smap.things if iri not in grouped}
    found |= {iri for iri, values in smap.facts.items() if HOME + "x" in values and HOME + "y" in values}
    return sorted(found - grouped)


def position(smap: SemanticMap, iri: str) -> tuple[float, float, float | None] | None:
    """A thing's ``home:x``, ``home:y`` (and ``home:z``), None when it has no single number for x or y."""
    values = smap.facts.get(iri, {})
    found: list[float | None] = []
    for axis in ("x", "y", "z"):
        said = set(values.get(HOME + axis, []))
        if len(said) != 1:
            found.append(None)
            continue
        try:
            found.append(float(said.pop()))
        except ValueError:
            found.append(None)
    x, y, z = found
    return None if x is None or y is None else (x, y, z)


def read_kinds(
    kb: KnowledgeBase, smap: SemanticMap, iris: Iterable[str], grouped_under: Sequence[str] = GROUPED_UNDER
) -> dict[str, Kind]:
    """The kind of each of ``iris`` that is a physical thing by the taxonomy; the others are left out.
    Three rounds of named queries (``subclasses`` of the things' classes, of their ancestors, the
    groups' labels by ``resource_triples``), each asked at once."""
    asserted = {iri: smap.types.get(iri, ()) for iri in iris}
    supers = _superclasses(kb, {t for types in asserted.values() for t in types})
    ancestors = {iri: set().union(*(supers.get(t, {t}) for t in types)) for iri, types in asserted.items()}
    physical = {iri: found for iri, found in ancestors.items() if PHYSICAL in found}
    supers |= _superclasses(kb, set().union(*physical.values()) - supers.keys())
    groups: dict[str, str] = {}
    for iri, found in physical.items():
        root = next((r for r in grouped_under if r in found), PHYSICAL)
        below = sorted(a for a in found if a != root and root in supers.get(a, ()))
        top = [a for a in below if not any(b != a and b in supers.get(a, ()) for b in below)]
        groups[iri] = top[0] if top else root
    names = _labels(kb, sorted(set(groups.values())))
    return {iri: Kind(group, names[group]) for iri, group in groups.items()}


def _superclasses(kb: KnowledgeBase, classes: set[str]) -> dict[str, set[str]]:
    """Each class's superclasses, itself included (none for a class the store does not declare)."""
    asked = sorted(classes)
    if not asked:  # no request at all to a remote store
        return {}
    answers = kb.queries.select_each(kb.store, [("subclasses", {"class": c}) for c in asked])
    return {c: {c} | {row["superclass"].value for row in rows} for c, rows in zip(asked, answers, strict=True)}


def _labels(kb: KnowledgeBase, classes: list[str]) -> dict[str, str]:
    """Each class's English (else untagged, else any) label, else its local name in words."""
    if not classes:
        return {}
    answers = kb.queries.select_each(kb.store, [("resource_triples", {"resource": c}) for c in classes])
    names = {}
    for concept, rows in zip(classes, answers, strict=True):
        labels = [
            row["other"]
            for row in rows
            if row["direction"].value == "out" and row["predicate"].value == RDFS + "label" and "other" in row
        ]
        ranked = sorted(labels, key=lambda t: (_language(t) != "en", _language(t) is not None, t.value))
        words = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", " ", local_name(concept)).lower()
        names[concept] = ranked[0].value if ranked else words
    return names


def _language(term: object) -> str | None:
    return getattr(term, "language", None)
