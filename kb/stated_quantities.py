"""A thing's quantities the map states, and the measured statuses they decide.

A property says which quantity it is a level of and in which unit (``home:levelOf``, ``home:levelUnit``):
``home:massKg`` an ``home:ObjectWeight`` in kilograms, ``home:lightLevel`` an ``home:Illuminance`` in lux
(home.ttl; a lab's own property, a flask's volume in litres, alike). What a thing of the map states with
such a property is what the store knows of that quantity of it, so a status defined by a measured
condition (:mod:`kb.measured_states`: ``lab11:Full``, an object weight of 0.4 kg and more) is decided of
the thing by it where no sensor reads it: :class:`StatedQuantities`. Only the thing's own statement counts:
a class's level (``home:Room`` 300 lx) is the simulated home's stand-in for what its sensors read, not
knowledge of one thing. Used by a run's preconditions (:mod:`actions.precondition_sensing`) and, where a
task's class names several things, to tell them apart by what the task guarantees of the one it means
(:func:`kb.semantic_map.designate`), with the colour each states (:mod:`kb.stated_colours`). docs/execution.md,
"A thing's quantities stated in the map".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cbrs.kb.measured_states import MeasuredCondition, MeasuredConditionError, UnitError, Units, conditions_by_status
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.stated_colours import COLOUR, HAS_COLOUR, StatedColours

if TYPE_CHECKING:
    from cbrs.kb.knowledge_base import KnowledgeBase
    from cbrs.kb.model import Requirement

__all__ = ["HAS_STATUS", "Stated", "StatedLevel", "StatedQuantities", "guaranteed_statuses", "stated_levels"]

HAS_STATUS = PREFIXES["home"] + "hasStatus"
IsA = Callable[[str, str], bool]


@dataclass(frozen=True)
class StatedLevel:
    """A number a thing of the map states with a property that is a level of ``quantity`` in ``unit``."""

    thing: str
    prop: str
    value: float
    quantity: str
    unit: str


@dataclass(frozen=True)
class Stated:
    """What a thing's stated level says of a measured status: ``holds`` by ``level``; ``reading`` the level
    as the run words it (``0.55 kg``; ``50 °F (10 °C)`` in another unit than the condition's) and ``bound``
    the condition's (``at least 0.4 kg``)."""

    holds: bool
    level: StatedLevel
    reading: str
    bound: str


@dataclass(frozen=True)
class StatedQuantities:
    """The levels the things of the store state, by thing, the taxonomy's superclasses (each class with
    itself) and the colour classes of the things (:class:`kb.stated_colours.StatedColours`), read once: the
    named queries ``place_levels``, ``subclasses`` and ``thing_colours`` asked at once."""

    levels: Mapping[str, tuple[StatedLevel, ...]]
    superclasses: Mapping[str, frozenset[str]]
    units: Units
    conditions: Mapping[str, MeasuredCondition | MeasuredConditionError]
    colours: StatedColours = field(default_factory=lambda: StatedColours({}))

    @classmethod
    def read(cls, kb: KnowledgeBase) -> StatedQuantities:
        level_rows, up_rows, colour_rows = kb.select_each(("place_levels", "subclasses", "thing_colours"))
        found: dict[str, list[StatedLevel]] = {}
        for level in stated_levels(level_rows):
            found.setdefault(level.thing, []).append(level)
        up: dict[str, set[str]] = {}
        for row in up_rows:
            up.setdefault(row["class"].value, {row["class"].value}).add(row["superclass"].value)
        return cls(
            {thing: tuple(levels) for thing, levels in found.items()},
            {concept: frozenset(above) for concept, above in up.items()},
            Units.read(kb),
            conditions_by_status(kb),
            StatedColours.of_rows(colour_rows),
        )

    def is_a(self, concept: str, ancestor: str) -> bool:
        return concept == ancestor or ancestor in self.superclasses.get(concept, ())

    def level(self, thing: str, quantity: str) -> StatedLevel | None:
        """The level of ``quantity`` ``thing`` states itself, by a property that is a level of it or of a class
        below it (a narrower measurement is one of it): the most specific quantity first, then by property;
        None where it states none."""
        found = [level for level in self.levels.get(thing, ()) if self.is_a(level.quantity, quantity)]
        found.sort(key=lambda level: (-len(self.superclasses.get(level.quantity, ())), level.prop, level.value))
        return found[0] if found else None

    def condition(self, status: str) -> MeasuredCondition | None:
        """The measured condition of ``status``; None where it has none; its error where the store states it so
        that nothing can decide it."""
        condition = self.conditions.get(status)
        if isinstance(condition, MeasuredConditionError):
            raise condition
        return condition

    def decide(self, thing: str, status: str) -> Stated | None:
        """Whether ``status`` holds of ``thing`` by the level of its condition's quantity ``thing`` states;
        None where ``status`` has no measured condition or ``thing`` states no level of it. A level in a unit
        that does not convert to the condition's is :class:`UnitError`, naming it."""
        condition = self.condition(status)
        if condition is None:
            return None
        level = self.level(thing, condition.quantity)
        if level is None:
            return None
        value = self.units.convert(level.value, level.unit, condition.unit)
        said = f"{level.value:g} {self.units.symbol(level.unit)}"
        if level.unit != condition.unit:
            said += f" ({value:g} {self.units.symbol(condition.unit)})"
        return Stated(condition.holds(value), level, said, condition.text(self.units))

    def meeting(self, things: Iterable[str], statuses: Collection[str]) -> list[str]:
        """Those of ``things`` of which no status of ``statuses`` is decided false by what they state (each
        is kept where its levels decide nothing): the things a requester who guarantees ``statuses`` of the
        one it means can mean. A colour among ``statuses`` (a class at or below ``home:Colour``) is decided
        by the thing's colour name (:meth:`kb.stated_colours.StatedColours.decide`)."""
        kept = []
        for thing in things:
            colours = [self.colours.decide(thing, s, self.is_a) for s in statuses if self.is_a(s, COLOUR)]
            try:
                decided = [self.decide(thing, status) for status in statuses if not self.is_a(status, COLOUR)]
            except (UnitError, MeasuredConditionError):
                decided = []  # nothing decidable: the run's own check names the error
            if all(found is None or found.holds for found in decided) and False not in colours:
                kept.append(thing)
        return kept


def stated_levels(rows: Iterable[Mapping[str, Any]]) -> list[StatedLevel]:
    """The levels of the ``place_levels`` query's ``rows`` (of a place, a class of places or a thing) that are
    finite numbers in a stated unit: a number in no stated unit could be in any, and is not read."""
    found = []
    for row in rows:
        if "unit" not in row:
            continue
        try:
            value = float(row["value"].value)
        except ValueError:
            continue
        if math.isfinite(value):
            prop, quantity = row["property"].value, row["quantity"].value
            found.append(StatedLevel(row["subject"].value, prop, value, quantity, row["unit"].value))
    return found


def guaranteed_statuses(requirement: Requirement, concept: str, is_a: IsA | None = None) -> tuple[str, ...]:
    """The statuses and colours ``requirement``'s preconditions guarantee of the thing its input of class
    ``concept`` names: ``(C, home:hasStatus, S)`` and ``(C, home:hasColour, K)`` with ``C`` that class or one
    above it (``is_a``; without it, that class alone)."""
    return tuple(
        sorted(
            {
                p.object
                for p in requirement.preconditions
                if p.predicate in (HAS_STATUS, HAS_COLOUR)
                and (p.subject == concept or (is_a is not None and _safe(is_a, concept, p.subject)))
            }
        )
    )


def _safe(is_a: IsA, concept: str, ancestor: str) -> bool:
    try:
        return is_a(concept, ancestor)
    except KeyError:
        return False
