"""Where a task's things are, and which components' service effective areas (SEA) cover them.

A step that acts on or perceives a thing of the task must use a component whose SEA covers where that
thing is: a ceiling camera over the bedroom cannot find a pen on the kitchen table. The things are the
requirement's inputs that name something the world graph places (the belief's perceived position when
composing for a run, else the semantic map's). A step's things are those of the inputs it is given
directly, and those a value another step derived from them is about, when that value leads to the thing:
a thing itself (a place), where it is (spatial data) or how to recognise it (a feature) is what a
component perceives or acts on the thing with (the pen's colour feature leads the recogniser to the
pen); other information only tells the step about it (a speaker given the weight a scale measured of
the cup need not be where the cup is). ``Leads`` decides by the taxonomy, from the classes the store
marks with ``cbrs:areaRole`` (or ``ComposeConfig.area_informs`` and ``area_leads`` name). A component
with no SEA model is effective everywhere. The comparison's parts are matchmaking's (``reasoner.sea``:
an area concept covers the rooms at or below it by is-a or has-part links; boxes hold or overlap);
docs/composition.md says why rooms come before boxes here, and why no step need cover the task's whole
area.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from cbrs.actions.errors import ActionsError
from cbrs.kb import Advertisement, EffectiveArea, KnowledgeBase, Requirement
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.semantic_map import designate
from cbrs.reasoner.sea import Bounds, covers_concept, overlap, reaches, within
from cbrs.reasoner.taxonomy import TaxonomyIndex

_HOME = PREFIXES["home"]


@dataclass(frozen=True)
class Whereabouts:
    """Where the thing a requirement input names is: its position (a point) or extent, and its rooms (the
    classes of those its point is in or its extent overlaps: a door in the wall between two is in both)."""

    given_as: str  # the requirement input's name
    thing: str
    bounds: Bounds
    rooms: tuple[str, ...]

    @property
    def point(self) -> bool:
        return self.bounds[0] == self.bounds[1] and self.bounds[2] == self.bounds[3]

    def text(self) -> str:
        x0, x1, y0, y1 = self.bounds
        at = f"at ({x0:.2f}, {y0:.2f})" if self.point else f"over x {x0:g}..{x1:g}, y {y0:g}..{y1:g}"
        rooms = f" in {' and '.join(shorten(r) for r in self.rooms)}" if self.rooms else ""
        return f"{shorten(self.thing)} (the task's {self.given_as}) {at}{rooms}"


@dataclass(frozen=True)
class WorldPlaces:
    """Where the world graph puts things (the semantic map's positions and extents, and with ``belief``
    the perceived positions over them) and their classes: read once per composition, in three queries."""

    types: Mapping[str, tuple[str, ...]]
    bounds: Mapping[str, Bounds]
    rooms: tuple[tuple[str, Bounds], ...]  # (room class, extent)

    @classmethod
    def read(cls, kb: KnowledgeBase, index: TaxonomyIndex, belief: bool) -> WorldPlaces:
        facts: dict[str, dict[str, str]] = {}
        reads = ("map_facts", "map_types", "world_positions") if belief else ("map_facts", "map_types")
        fact_rows, type_rows, *positions = kb.select_each(reads)  # one request to a remote store
        for row in fact_rows:
            facts.setdefault(row["thing"].value, {}).setdefault(row["property"].value, row["value"].value)
        types: dict[str, list[str]] = {}
        for row in type_rows:
            types.setdefault(row["thing"].value, []).append(row["type"].value)
        bounds = {thing: found for thing, values in facts.items() if (found := map_bounds(values)) is not None}
        if belief:
            for row in positions[0]:
                thing, x, y = row["thing"].value, float(row["x"].value), float(row["y"].value)
                bounds[thing] = (x, x, y, y)
                if "type" in row and row["type"].value not in types.get(thing, []):
                    types.setdefault(thing, []).append(row["type"].value)
        rooms = tuple(
            sorted(
                (concept, bounds[thing])
                for thing, concepts in types.items()
                if thing in facts and thing in bounds
                for concept in concepts
                if index.is_a(concept, _HOME + "Room")
            )
        )
        return cls({k: tuple(v) for k, v in types.items()}, bounds, rooms)

    def locate(
        self, kb: KnowledgeBase, index: TaxonomyIndex, requirement: Requirement, names: Iterable[str]
    ) -> dict[str, Whereabouts]:
        """The whereabouts of the things ``requirement``'s inputs (called ``names``) designate, by input name.

        An input whose class designates no one thing (none, or several the requester does not own), or a
        thing the world graph does not place, has none: nothing is known to cover, so nothing is filtered.
        """
        found: dict[str, Whereabouts] = {}
        for name, parameter in zip(names, requirement.inputs, strict=True):
            concept = parameter.type
            if not concept:
                continue
            things = [t for t, types in self.types.items() if any(index.is_a(c, concept) for c in types)]
            if len(things) > 1:  # several: the executor's choice (those the requester owns), or none
                try:
                    things = [designate(kb, concept, prefer=requirement.requested_by)]
                except KnowledgeBaseError:
                    continue
            if len(things) == 1 and things[0] in self.bounds:
                where = self.bounds[things[0]]
                found[name] = Whereabouts(name, things[0], where, self.rooms_of(where))
        return found

    def rooms_of(self, bounds: Bounds) -> tuple[str, ...]:
        """The classes of the rooms that hold a point, or that an extent overlaps."""
        point = bounds[0] == bounds[1] and bounds[2] == bounds[3]
        return tuple(dict.fromkeys(c for c, extent in self.rooms if (within if point else overlap)(bounds, extent)))


def map_bounds(values: Mapping[str, str]) -> Bounds | None:
    """A thing's map position (a point) or else its extent, from its map facts (property IRI: lexical
    value); None when the map places it nowhere."""
    try:
        if _HOME + "x" in values and _HOME + "y" in values:
            x, y = float(values[_HOME + "x"]), float(values[_HOME + "y"])
            return (x, x, y, y)
        corners = [values.get(_HOME + axis) for axis in ("minX", "maxX", "minY", "maxY")]
        if all(corner is not None for corner in corners):
            x0, x1, y0, y1 = (float(c) for c in corners if c is not None)
            return (x0, x1, y0, y1)
    except ValueError:  # the map checks say so when the map is read for a run; here it is just not placed
        return None
    return None


class UnknownAreaClassError(ActionsError):
    """A class marked with an area role (``cbrs:areaRole`` in the store, or ``ComposeConfig.area_informs`` /
    ``area_leads``) is no class of the store's taxonomy, or a mark is no role."""

    http_status = 400

    def __init__(self, concept: str, why: str = "which is no class of the taxonomy") -> None:
        self.concept = concept
        super().__init__(
            f"an area role (cbrs:areaRole, or ComposeConfig.area_informs / area_leads) marks {concept}, {why}: "
            "correct it or load the ontology that declares it"
        )


LEADS = PREFIXES["cbrs"] + "LeadsToThing"
INFORMS = PREFIXES["cbrs"] + "InformsOfThing"


@dataclass(frozen=True)
class Leads:
    """Which values a step is given lead it to the thing they were derived from, by the classes marked
    with a role (``roles``: class -> :data:`LEADS` or :data:`INFORMS`): a value's class takes the role of
    its nearest marked classes (a mark below another wins), leading when any of those leads; a class
    below no mark leads (the rule that ties a step to more things is the safe one)."""

    index: TaxonomyIndex
    roles: Mapping[str, str]

    @classmethod
    def of(cls, index: TaxonomyIndex, informs: Iterable[str], leads: Iterable[str]) -> Leads:
        """The rule from two lists of marked classes (``ComposeConfig.area_informs`` and ``area_leads``)."""
        return cls(index, {**{c: INFORMS for c in informs}, **{c: LEADS for c in leads}})

    def __post_init__(self) -> None:
        for concept, role in self.roles.items():  # a misspelt class would silently change every plan
            if concept not in self.index:
                raise UnknownAreaClassError(concept)
            if role not in (LEADS, INFORMS):
                why = f"with {shorten(role)}, which is no area role (cbrs:LeadsToThing or cbrs:InformsOfThing)"
                raise UnknownAreaClassError(concept, why)

    def __call__(self, concept: str | None) -> bool:
        """Whether a value of class ``concept`` (None: untyped, so unknown) leads to its thing."""
        if not concept:
            return True
        marked = [c for c in self.roles if self.index.is_a(concept, c)]
        nearest = [c for c in marked if not any(o != c and self.index.is_a(o, c) for o in marked)]
        return not nearest or any(self.roles[c] == LEADS for c in nearest)


class AreaRule:
    """Which components may serve a step, by the things it handles and the task's own area.

    ``task`` (the requirement's SEA) is where the whole task happens: no one step need cover it (the
    robot crosses the home while each camera sees one room), but a component effective only outside it
    cannot serve it. With ``boxes`` off, two areas that both name area concepts are compared by those
    alone (the thing's room against the component's rooms), and boxes only when a side names none."""

    def __init__(
        self,
        index: TaxonomyIndex,
        places: Mapping[str, Whereabouts],
        task: EffectiveArea | None,
        boxes: bool = False,
        leads: Leads | None = None,
    ) -> None:
        self.index = index
        self.leads = leads or Leads(index, {})  # by default every value leads to its thing
        self.places = dict(places)
        self.task = task
        self.boxes = boxes
        # asked for every step's alternatives: by component, things, and (thing, input, class) leading to them
        self._why: dict[tuple[str, frozenset[str], frozenset[tuple[str, str, str | None]]], str | None] = {}

    def relevant(self, advertisements: Iterable[Advertisement]) -> bool:
        """Whether the rule can refuse any of ``advertisements`` (if not, composition need not ask it)."""
        return any(self.why_not(ad, self.places) is not None for ad in advertisements)

    def passes_on(self, concept: str | None) -> bool:
        """Whether a step given a value as a ``concept`` (its input's class) must be where the things the
        value is about are: it leads to them, rather than only informing of them (docs/composition.md)."""
        return self.leads(concept)

    def why_not(
        self, ad: Advertisement | None, things: Iterable[str], via: Mapping[str, tuple[str, str | None]] | None = None
    ) -> str | None:
        """Why ``ad`` cannot serve a step handling ``things`` (requirement input names); None: it can.
        ``via``: for a thing the step is not given directly, the (name, class) of its input whose value leads
        to it, which the reason names (the refusal said only which thing, not what tied the step to it)."""
        if ad is None or ad.area is None:
            return None
        handled = frozenset(t for t in things if t in self.places)
        leads = frozenset((t, *via[t]) for t in handled if via and t in via)
        key = (ad.iri, handled, leads)
        if key not in self._why:
            self._why[key] = self._why_not(ad.area, handled, {t: (name, concept) for t, name, concept in leads})
        return self._why[key]

    def _why_not(
        self, area: EffectiveArea, things: frozenset[str], via: Mapping[str, tuple[str, str | None]]
    ) -> str | None:
        if self.task is not None and not reaches(self.index, *self._compared(self.task, area)):
            return f"its effective area ({area_text(area)}) lies outside the task's ({area_text(self.task)})"
        for name in sorted(things):
            place = self.places[name]
            if not self._reaches(place, area):
                return f"its effective area ({area_text(area)}) does not cover {place.text()}{_led(via.get(name))}"
        return None

    def _reaches(self, place: Whereabouts, area: EffectiveArea) -> bool:
        """Whether a component effective in ``area`` can act on or perceive the thing at ``place``: one of
        its rooms is an area the component names or below one (by boxes, or when a side names no area:
        its point is in the component's box, its extent overlaps it). Nothing to compare: it can."""
        by_rooms = bool(place.rooms and area.areas)
        if by_rooms and not (self.boxes and area.bounds):
            return any(covers_concept(self.index, offered, room) for offered in area.areas for room in place.rooms)
        if area.bounds:
            return (within if place.point else overlap)(place.bounds, area.bounds)
        return True

    def _compared(self, wanted: EffectiveArea, offered: EffectiveArea) -> tuple[EffectiveArea, EffectiveArea]:
        """The two areas as compared: by their concepts alone when both name some and boxes are off."""
        if self.boxes or not (wanted.areas and offered.areas):
            return wanted, offered
        return EffectiveArea(wanted.areas), EffectiveArea(offered.areas)


def _led(via: tuple[str, str | None] | None) -> str:
    """What ties a step to a thing it is not given directly: its input whose value is about the thing and of a
    class that leads to it (docs/composition.md, "Values that lead to a thing"), and the mark that unties it."""
    if via is None:
        return ""
    name, concept = via
    if not concept:
        return f", which its input {name} (of no class, so taken to lead to its thing) is about"
    kind = shorten(concept)
    return (
        f", which its input {name} ({kind}, a class that leads to its thing) is about; if a {kind} only informs"
        f" a step of its thing, mark the class cbrs:InformsOfThing (e.g. {kind} cbrs:areaRole"
        " cbrs:InformsOfThing, loaded into the ontology graph)"
    )


def area_text(area: EffectiveArea) -> str:
    parts = [", ".join(shorten(a) for a in area.areas)] if area.areas else []
    if area.bounds:
        x0, x1, y0, y1 = area.bounds
        parts.append(f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}")
    return "; ".join(parts) or "unstated"


__all__ = [
    "INFORMS",
    "LEADS",
    "AreaRule",
    "Leads",
    "UnknownAreaClassError",
    "Whereabouts",
    "WorldPlaces",
    "area_text",
    "map_bounds",
]
