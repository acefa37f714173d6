"""A task's precondition on a sensed state, decided by a sensor of the store before the first step.

A precondition ``(place, home:hasStatus, S)`` no test of the environment decides is taken as given
(:mod:`actions.task_preconditions`). Where the store says what ``S`` is in measured terms (``S
home:holdsWhen`` a condition on a quantity, :mod:`kb.measured_states`: ``lab9:Dark``, a
``home:Illuminance`` below 50 lx), a reading decides it instead: :class:`PreconditionSensing` finds the
components that can take one (an output of the quantity's class or one below it, no inputs, an effective
area that covers the place: its area concepts by composition's rule, ``reasoner.sea.covers_concept``,
else its box overlapping the place's extent in the map, as ``actions.areas`` compares them; one that
states no area measures where its device is, :mod:`actions.sensor_places`, and covers the place when the
room of the map its device is in is that place or of its class by the same rule), invokes the first through the run's
container as the executor invokes a step's component (a simulated one or one in another process over the
bridge, with its own call timeout and the run's faults), and compares the reading with the bound in the
condition's unit, converted where the store says how (:class:`kb.measured_states.Units`). A sensor that
fails, or gives no reading within the sensing timeout, passes the question to the next; when none can
answer, the precondition stays taken as given and the run says why. A precondition ``(thing, home:hasColour,
K)`` is decided by the colour the map states of the thing (:mod:`kb.stated_colours`), no sensor asked.
docs/execution.md, "A task's preconditions".
"""

from __future__ import annotations

import collections.abc
import time
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cbrs.actions.components import Container, LifecycleState, Status
from cbrs.actions.sensor_places import MapPlaces
from cbrs.kb import Advertisement, KnowledgeBase, Statement
from cbrs.kb.measured_states import MeasuredCondition, MeasuredConditionError, Units, conditions_by_status
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.semantic_map import AmbiguousDesignatorError, UnresolvedDesignatorError, designate
from cbrs.kb.stated_colours import HAS_COLOUR
from cbrs.kb.stated_quantities import StatedQuantities
from cbrs.reasoner.names import local_name
from cbrs.reasoner.sea import Bounds, covers_concept, overlap
from cbrs.reasoner.taxonomy import TaxonomyIndex

__all__ = ["HAS_STATUS", "PreconditionSensing", "Sensed", "SensingConfig"]

HAS_STATUS = PREFIXES["home"] + "hasStatus"


@dataclass(frozen=True)
class Sensed:
    """What sensing found of one precondition: ``holds`` True or False by a reading (``how``: ``12 lx by
    SensorBoard01``), or None when no sensor could tell (``how``: why not). ``bound`` is the condition's
    (``below 50 lx``); ``sensor`` the component that read it, ``device`` its device's name and ``reading``
    what it read (``12 lx``)."""

    holds: bool | None
    how: str
    bound: str = ""
    sensor: str = ""
    reading: str = ""
    device: str = ""
    stated: bool = False  # decided by what the map states (``sensor`` the property), no sensor's reading
    rule: str = "its home:holdsWhen"
    """Where ``bound`` comes from, as a refusal names it."""


@dataclass(frozen=True)
class SensingConfig:
    """Whether a run senses its preconditions on measured states, and how long one sensor has (seconds of
    wall-clock time); the ``precondition_sensing`` and ``precondition_sensing_timeout`` settings."""

    enabled: bool = True
    timeout: float = 10.0

    def __post_init__(self) -> None:
        if not self.timeout > 0:
            raise ValueError(f"precondition_sensing_timeout {self.timeout!r}: a number of seconds above 0")

    @classmethod
    def from_settings(cls) -> SensingConfig:
        from cbrs.settings import setting

        return cls(
            bool(setting("precondition_sensing").resolve()), float(setting("precondition_sensing_timeout").resolve())
        )


class _Failed(Exception):
    """A sensor's invocation that gave no reading."""


class PreconditionSensing:
    """Asks the store's sensors about preconditions on measured states (the module's rule).

    ``container``: the run's, whose factory makes each component as a step's would be made (a remote one
    over the bridge, with its call timeout; an injected fault strikes here as in a step). ``timeout``:
    seconds of wall-clock time one sensor has to give its reading, on top of any call timeout of its own.
    ``runnable``: the components the run can make (its registry). ``passed``: those the run passes over
    now (``actions.breaker``), not asked."""

    def __init__(
        self,
        kb: KnowledgeBase,
        container: Container,
        runnable: collections.abc.Container[str],
        index: TaxonomyIndex,
        timeout: float,
        passed: Collection[str] = (),
        advertisements: Sequence[Advertisement] | None = None,
        given: Mapping[str, Any] | None = None,
    ) -> None:
        self.kb, self.container, self.runnable, self.index, self.timeout = kb, container, runnable, index, timeout
        self.passed = frozenset(passed)
        self.designated = {  # the things the run's inputs name, with the class each was asked as
            str(value["@id"]): str(value["@type"])
            for value in (given or {}).values()
            if isinstance(value, Mapping) and "@id" in value and "@type" in value
        }
        self._ads = advertisements
        self._conditions: dict[str, MeasuredCondition | MeasuredConditionError] | None = None
        self._units: Units | None = None
        self._rooms: tuple[tuple[str, Bounds], ...] | None = None
        self._map: MapPlaces | None = None
        self._stated_quantities: StatedQuantities | None = None

    def __call__(self, statement: Statement) -> Sensed | None:
        """What a reading says of ``statement``; None where the store gives its status no measured
        condition (it is not this module's to decide)."""
        if statement.predicate == HAS_COLOUR:
            return self._stated_colour(statement)
        if statement.predicate != HAS_STATUS:
            return None
        if self._conditions is None:
            self._conditions = conditions_by_status(self.kb)
        condition = self._conditions.get(statement.object)
        if condition is None:
            return None
        if isinstance(condition, MeasuredConditionError):
            raise condition  # the store says this status is measured, and not how: refused, naming it
        units = self.units()
        bound = condition.text(units)
        sensors = self.sensors(condition.quantity, statement.subject)
        failures = []
        for ad, output in sensors:
            device = ad.device_name or local_name(ad.iri)
            try:
                value = self._invoke(ad.iri).get(output)
            except _Failed as failed:
                failures.append(f"{device} ({shorten(ad.iri)}) failed: {failed}")
                continue
            reading = units.reading(value, condition.unit)  # a UnitError refuses the run, naming the unit
            converted = units.convert(reading.value, reading.unit, condition.unit)
            said = f"{reading.value:g} {units.symbol(reading.unit)}"
            if reading.unit != condition.unit:
                said += f" ({converted:g} {units.symbol(condition.unit)})"
            return Sensed(condition.holds(converted), f"{said} by {device}", bound, ad.iri, said, device)
        stated = self._stated(statement)  # no sensor read it: what the map states of the thing decides
        if stated is not None:
            return stated
        if not sensors:
            return Sensed(None, self._none_covers(condition.quantity, statement.subject), bound)
        return Sensed(None, "; ".join(failures), bound)

    def _stated_colour(self, statement: Statement) -> Sensed | None:
        """``statement`` (a colour of a thing) decided by the colour name the map states of the thing
        (:class:`kb.stated_colours.StatedColours`); None where it decides nothing (no name, a name no
        window tied to a class has, no one thing). The thing as :meth:`_stated` finds it."""
        thing = self._thing(statement)
        if thing is None:
            return None
        quantities = self._quantities()
        holds = quantities.colours.decide(thing, statement.object, quantities.is_a)
        if holds is None:
            return None
        name = quantities.colours.names.get(thing, "")
        classes = ", ".join(shorten(each) for each in sorted(quantities.colours.classes.get(thing, ())))
        of = f'"{name}" of {shorten(thing)}'
        how = f"\"{name}\", the map's home:colourName of {shorten(thing)}, a colour window's of {classes}"
        bound = "of a thing whose colour name is a colour window's tied to it or to a class below it"
        return Sensed(
            holds, how, bound, PREFIXES["home"] + "colourName", of, "the map", stated=True, rule="home:windowColour"
        )

    def _quantities(self) -> StatedQuantities:
        """What the store states of its things (levels and colour names), read once, when a precondition
        first needs it: most runs have none that the map decides."""
        if self._stated_quantities is None:
            self._stated_quantities = StatedQuantities.read(self.kb)
        return self._stated_quantities

    def _thing(self, statement: Statement) -> str | None:
        """The thing ``statement`` is about: the subject itself when it is a thing of the map; else the one
        thing the run's inputs name of the subject's class or one below it (``given``); else the one thing of
        the subject's class, designated as the run designates a task's input (the statement's object its
        guarantee); none or several: None."""
        subject = statement.subject
        meant = sorted(iri for iri, concept in self.designated.items() if self._is_a(concept, subject))
        try:
            if subject not in self.index:
                return subject
            if len(meant) == 1:
                return meant[0]
            return designate(self.kb, subject, guarantees=(statement.object,))
        except (UnresolvedDesignatorError, AmbiguousDesignatorError):
            return None

    def _stated(self, statement: Statement) -> Sensed | None:
        """``statement`` decided by the level of its status's quantity that the thing it is about states in
        the map (:mod:`kb.stated_quantities`); None where it states none. The thing: the subject itself when
        it is a thing of the map; else the one thing the run's inputs name of the subject's class or one below
        it (``given``); else the one thing of the subject's class, designated as the run designates a task's
        input (the precondition's status its guarantee); none or several: None."""
        thing = self._thing(statement)
        if thing is None:
            return None
        found = self._quantities().decide(thing, statement.object)
        if found is None:
            return None
        of = f"{found.reading} of {shorten(thing)}"
        how = f"{found.reading}, the map's {shorten(found.level.prop)} of {shorten(thing)}"
        return Sensed(found.holds, how, found.bound, found.level.prop, of, "the map", stated=True)

    def _none_covers(self, quantity: str, subject: str) -> str:
        """Why no sensor reads ``quantity`` for a precondition about ``subject``: none covers it, or it is no
        place (a flask's weight: a sensor's effective area covers places, and one that reads a thing, as a
        scale does, takes it as an input, which sensing gives none)."""
        said = f"no sensor of {shorten(quantity)} covers {shorten(subject)}"
        place = PREFIXES["home"] + "Place"
        if any(self._is_a(concept, place) for concept in self._places(subject)):
            return said
        return (
            f"{said}: {shorten(subject)} is no place, and a sensor reads a measured state of the place its "
            f"effective area covers, not of a thing; nor does the map state a level of {shorten(quantity)} of"
            " it (a property with home:levelOf and home:levelUnit, as home:massKg is of home:ObjectWeight)"
        )

    def units(self) -> Units:
        if self._units is None:
            self._units = Units.read(self.kb)
        return self._units

    def sensors(self, quantity: str, place: str) -> list[tuple[Advertisement, str]]:
        """The components that can read ``quantity`` at ``place`` now, each with the output that gives
        it: the most specific output class first (a room temperature before a temperature), then by IRI."""
        ads = self._ads if self._ads is not None else self.kb.advertisements()
        found = []
        for ad in ads:
            if ad.inputs or ad.iri in self.passed or ad.iri not in self.runnable:
                continue
            if self.container.state(ad.iri) is LifecycleState.ERROR:
                continue
            outputs = [p for p in ad.outputs if p.name and p.type and self._is_a(p.type, quantity)]
            if outputs and self._covers(ad, place):
                found.append((-self._depth(outputs[0].type or ""), ad.iri, ad, outputs[0].name or ""))
        return [(ad, output) for _, _, ad, output in sorted(found, key=lambda f: (f[0], f[1]))]

    def _is_a(self, concept: str, ancestor: str) -> bool:
        return concept == ancestor or (concept in self.index and self.index.is_a(concept, ancestor))

    def _depth(self, concept: str) -> int:
        return len(self.index.is_a_ancestors(concept)) if concept in self.index else 0

    def _covers(self, ad: Advertisement, place: str) -> bool:
        """Whether ``ad``'s effective area covers ``place`` (a class of places, or a place of the map):
        by its area concepts when it names some, else by its box against the place's extent, else (it
        states none) by the rooms of the map its device is in: the place itself, or a room of a class that
        covers the place's."""
        area = ad.area
        places = self._places(place)
        if area is not None and area.areas:
            return any(covers_concept(self.index, offered, concept) for offered in area.areas for concept in places)
        if area is not None and area.bounds is not None:
            return any(overlap(extent, area.bounds) for concept, extent in self._room_extents() if concept in places)
        if not ad.device:
            return False
        where = self._map_places()
        rooms = where.rooms_of(ad.device)
        if place not in self.index:
            return place in rooms
        offered = {concept for room in rooms for concept in where.types.get(room, ())}
        return any(covers_concept(self.index, concept, place) for concept in offered)

    def _map_places(self) -> MapPlaces:
        if self._map is None:
            self._map = MapPlaces.read(self.kb)
        return self._map

    def _places(self, place: str) -> tuple[str, ...]:
        """The place's classes: itself when it is one, else those the map gives it."""
        if place in self.index:
            return (place,)
        return tuple(row["type"].value for row in self.kb.select("map_types") if row["thing"].value == place)

    def _room_extents(self) -> tuple[tuple[str, Bounds], ...]:
        if self._rooms is None:
            from cbrs.actions.areas import WorldPlaces

            self._rooms = WorldPlaces.read(self.kb, self.index, belief=False).rooms
        return self._rooms

    def _invoke(self, iri: str) -> dict[str, Any]:
        """The outputs of one invocation of ``iri`` with no inputs, as a step's: started, ticked until it
        ends, aborted (its component put in the error state, as the executor does) when it fails or
        gives nothing within the timeout."""
        container = self.container
        deadline = time.monotonic() + self.timeout
        try:
            container.start(iri, {})
            while (status := container.tick(iri)) is Status.RUNNING:
                if time.monotonic() >= deadline:
                    raise _Failed(f"no reading within {self.timeout:g} s")
        except _Failed as failed:
            container.abort(iri, str(failed))
            raise
        except Exception as error:  # a component may raise anything: it failed, the run goes on
            container.abort(iri, f"{type(error).__name__}: {error}")
            raise _Failed(f"{type(error).__name__}: {error}") from error
        if status is Status.FAILED:
            reason = container.reason(iri) or "failed"
            container.abort(iri, reason)
            raise _Failed(reason)
        return dict(container.component(iri).outputs)
