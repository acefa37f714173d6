"""Where a task's things are, and which components' service effective areas (SEA) cover them.

A step that acts on or perceives a thing of the task must use a component whose SEA covers where that
thing is: a ceiling camera over the bedroom cannot find a pen on the kitchen table. The things are the
requirement's inputs that name something the world graph places (the belief's perceived position when
composing for a run, else the semantic map's); a step's things are those of the inputs it is given,
directly or through the steps that feed it (the pen's colour feature leads the recogniser to the pen).
A component with no SEA model is effective everywhere. The rule that compares the two areas is
matchmaking's (``reasoner.sea``); docs/composition.md says why this one and not covering the task's.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from cbrs.kb import Advertisement, EffectiveArea, KnowledgeBase, Requirement
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.semantic_map import designate
from cbrs.reasoner.sea import Bounds, reaches, uncovered, within
from cbrs.reasoner.taxonomy import TaxonomyIndex

_HOME = PREFIXES["home"]


@dataclass(frozen=True)
class Whereabouts:
    """Where the thing a requirement input names is: its position (a point) or extent, and its room."""

    given_as: str  # the requirement input's name
    thing: str
    bounds: Bounds
    room: str | None  # the class of the room it is in (home:Kitchen)

    @property
    def area(self) -> EffectiveArea:
        return EffectiveArea((self.room,) if self.room else (), self.bounds)

    def text(self) -> str:
        x0, x1, y0, y1 = self.bounds
        at = f"at ({x0:.2f}, {y0:.2f})" if (x0, y0) == (x1, y1) else f"over x {x0:g}..{x1:g}, y {y0:g}..{y1:g}"
        room = f" in {shorten(self.room)}" if self.room else ""
        return f"{shorten(self.thing)} (the task's {self.given_as}) {at}{room}"


def locate(kb: KnowledgeBase, requirement: Requirement, names: Iterable[str], belief: bool) -> dict[str, Whereabouts]:
    """The whereabouts of the things ``requirement``'s inputs (called ``names``) designate, by input name.

    An input whose class designates no one thing (none, or several the requester does not own), or a
    thing the world graph does not place, has none: nothing is known to cover, so nothing is filtered."""
    rooms = _rooms(kb)
    found: dict[str, Whereabouts] = {}
    for name, parameter in zip(names, requirement.inputs, strict=True):
        if not parameter.type:
            continue
        try:
            thing = designate(kb, parameter.type, prefer=requirement.requested_by)
        except KnowledgeBaseError:  # none or ambiguous: the run refuses it with its own reason
            continue
        bounds = _position(kb, thing, belief)
        if bounds is not None:
            found[name] = Whereabouts(name, thing, bounds, _room_of(bounds, rooms))
    return found


def _position(kb: KnowledgeBase, thing: str, belief: bool) -> Bounds | None:
    """Where ``thing`` is: its perceived position (with ``belief``), its map position, or its extent."""
    if belief:
        for row in kb.select("world_positions", {"thing": thing}):
            x, y = float(row["x"].value), float(row["y"].value)
            return (x, x, y, y)
    facts: dict[str, str] = {}
    for row in kb.select("map_facts", {"thing": thing}):
        facts.setdefault(row["property"].value, row["value"].value)
    try:
        if _HOME + "x" in facts and _HOME + "y" in facts:
            x, y = float(facts[_HOME + "x"]), float(facts[_HOME + "y"])
            return (x, x, y, y)
        corners = [facts.get(_HOME + axis) for axis in ("minX", "maxX", "minY", "maxY")]
        if all(corner is not None for corner in corners):
            x0, x1, y0, y1 = (float(c) for c in corners if c is not None)
            return (x0, x1, y0, y1)
    except ValueError:  # the map checks say so when the map is read; here it is just not placed
        return None
    return None


def _rooms(kb: KnowledgeBase) -> list[tuple[str, Bounds]]:
    """The map's rooms as (class, extent)."""
    found = []
    for row in kb.select("designate", {"class": _HOME + "Room"}):
        extent = _position(kb, row["thing"].value, belief=False)
        if extent is not None:
            found.append((row["type"].value, extent))
    return sorted(found)


def _room_of(bounds: Bounds, rooms: list[tuple[str, Bounds]]) -> str | None:
    """The class of the room whose extent holds the thing (all of it; the first by class name)."""
    return next((concept for concept, extent in rooms if within(bounds, extent)), None)


class AreaRule:
    """Which components may serve a step, by the things it handles and the task's own area.

    ``task`` (the requirement's SEA) is where the whole task happens: no one step need cover it (the
    robot crosses the home while each camera sees one room), but a component effective only outside it
    cannot serve it."""

    def __init__(self, index: TaxonomyIndex, places: Mapping[str, Whereabouts], task: EffectiveArea | None) -> None:
        self.index = index
        self.places = dict(places)
        self.task = task

    def relevant(self, advertisements: Iterable[Advertisement]) -> bool:
        """Whether the rule can refuse any of ``advertisements`` (if not, composition need not ask it)."""
        return any(self.why_not(ad, self.places) is not None for ad in advertisements)

    def why_not(self, ad: Advertisement | None, things: Iterable[str]) -> str | None:
        """Why ``ad`` cannot serve a step handling ``things`` (requirement input names); None: it can."""
        if ad is None or ad.area is None:
            return None
        if self.task is not None and not reaches(self.index, self.task, ad.area):
            return f"its effective area ({area_text(ad.area)}) lies outside the task's ({area_text(self.task)})"
        for name in sorted(set(things)):
            place = self.places.get(name)
            if place is not None and uncovered(self.index, place.area, ad.area):
                return f"its effective area ({area_text(ad.area)}) does not cover {place.text()}"
        return None


def area_text(area: EffectiveArea) -> str:
    parts = [", ".join(shorten(a) for a in area.areas)] if area.areas else []
    if area.bounds:
        x0, x1, y0, y1 = area.bounds
        parts.append(f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}")
    return "; ".join(parts) or "unstated"


__all__ = ["AreaRule", "Whereabouts", "area_text", "locate"]
