"""Where a sensor measures: the places of the semantic map a reading of it is about.

A sensor's effective area says where it measures: the places of the map of a class at or below one its
area names (``cbrs:effectiveArea home:LivingRoom``: world:LivingRoom), else the rooms of the map its box
overlaps. One that states no area measures where its device is: the rooms of the map that hold its
device's position (``home:x``, ``home:y``) or that its extent overlaps, else the room its
``home:isLocated`` names, followed through what it stands in or on (a thermometer located on a shelf that
is located in the bedroom). A device the map does not place (one mounted on a robot, which moves) gives
no place, and its sensor measures nowhere known. docs/execution.md, "Where a sensor measures".
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from cbrs.actions.areas import map_bounds
from cbrs.kb import EffectiveArea, KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.reasoner.sea import Bounds, overlap, within

__all__ = ["MapPlaces", "stated"]

_HOME = PREFIXES["home"]
ROOM = _HOME + "Room"
LOCATED = _HOME + "isLocated"


@dataclass(frozen=True)
class MapPlaces:
    """The things of the map with their stated classes, where the map puts them, and the taxonomy's
    superclasses (each class with itself): read once, in three named queries asked for at once."""

    types: Mapping[str, frozenset[str]]
    superclasses: Mapping[str, frozenset[str]]
    bounds: Mapping[str, Bounds]
    located: Mapping[str, str]

    @classmethod
    def read(cls, kb: KnowledgeBase) -> MapPlaces:
        fact_rows, type_rows, up_rows = kb.select_each(("map_facts", "map_types", "subclasses"))
        facts: dict[str, dict[str, str]] = {}
        for row in fact_rows:
            facts.setdefault(row["thing"].value, {}).setdefault(row["property"].value, row["value"].value)
        types: dict[str, set[str]] = {}
        for row in type_rows:
            types.setdefault(row["thing"].value, set()).add(row["type"].value)
        up: dict[str, set[str]] = {}
        for row in up_rows:
            up.setdefault(row["class"].value, {row["class"].value}).add(row["superclass"].value)
        bounds = {thing: found for thing, values in facts.items() if (found := map_bounds(values)) is not None}
        located = {thing: values[LOCATED] for thing, values in facts.items() if LOCATED in values}
        return cls(
            {thing: frozenset(classes) for thing, classes in types.items()},
            {concept: frozenset(above) for concept, above in up.items()},
            bounds,
            located,
        )

    def above(self, thing: str) -> frozenset[str]:
        """Every class of a thing of the map: those stated and their superclasses."""
        return frozenset().union(*(self.superclasses.get(c, {c}) for c in self.types.get(thing, ())))

    def of_classes(self, concepts: Iterable[str]) -> tuple[str, ...]:
        """The things of the map of a class at or below one of ``concepts``, by IRI."""
        wanted = set(concepts)
        return tuple(thing for thing in sorted(self.types) if wanted & self.above(thing))

    def rooms(self) -> tuple[str, ...]:
        """The rooms of the map the map gives an extent."""
        return tuple(thing for thing in self.of_classes((ROOM,)) if thing in self.bounds)

    def rooms_overlapping(self, box: Bounds) -> tuple[str, ...]:
        """The rooms of the map that hold a point, or that a box overlaps."""
        point = box[0] == box[1] and box[2] == box[3]
        return tuple(room for room in self.rooms() if (within if point else overlap)(box, self.bounds[room]))

    def rooms_of(self, thing: str) -> tuple[str, ...]:
        """The rooms a thing of the map is in: itself when it is a room; else those holding its position
        or overlapping its extent; else those of what its ``home:isLocated`` names, and so on up."""
        seen: set[str] = set()
        while thing not in seen:
            seen.add(thing)
            if ROOM in self.above(thing):
                return (thing,)
            if thing in self.bounds and (found := self.rooms_overlapping(self.bounds[thing])):
                return found
            if thing not in self.located:
                return ()
            thing = self.located[thing]
        return ()

    def measured(self, area: EffectiveArea | None, device: str | None) -> tuple[str, ...]:
        """The places a sensor with effective area ``area`` on ``device`` measures (the module's rule)."""
        if area is not None and area.areas:
            return self.of_classes(area.areas)
        if area is not None and area.bounds is not None:
            return self.rooms_overlapping(area.bounds)
        return self.rooms_of(device) if device else ()


def stated(area: EffectiveArea | None) -> bool:
    """Whether an effective area says where its component is effective: area concepts or a box."""
    return area is not None and (bool(area.areas) or area.bounds is not None)
