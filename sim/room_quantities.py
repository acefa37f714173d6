"""The simulated home's room sensors: the light level, air temperature or humidity a sensor reads.

The physics renders no light, heat or moisture, so a simulated room sensor reads what the store states. A
property of places says which quantity it is a level of and in which unit (``home:lightLevel home:levelOf
home:Illuminance ; home:levelUnit unit:LUX``; ``home:airTemperature`` in degrees Celsius and
``home:relativeHumidity`` in percent, home.ttl; a lab's own property in a unit of its own is read alike). A
place of the map states its level (``world:LivingRoom home:lightLevel 12.0`` in graph:map), else the
nearest of its classes that states one does (home.ttl: ``home:Room`` 300 lx, 21 °C, 45 %). A sensor reads
the places it measures (:mod:`actions.sensor_places`: those its effective area names, else the room its
device is in), their mean where it measures several, and gives each of its outputs, of a quantity's class
or one below it, as a reading of its output's class under the key of the level's unit (docs/values.md):
``{"@type": ".../home#Temperature", "celsius": 21.0}``. A sensor that measures no place of the map, or
places no level is stated of, fails, saying so. docs/execution.md, "A sensed precondition in the
simulated home". Things state levels the same way (``home:massKg``, a ``home:ObjectWeight`` in
kilograms); a sensor here reads places only, and a thing's own level decides a precondition on it where no
sensor reads it (:mod:`kb.stated_quantities`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cbrs.actions.sensor_places import MapPlaces, stated
from cbrs.kb import Advertisement, KnowledgeBase
from cbrs.kb.errors import NotFoundError
from cbrs.kb.measured_states import UnitError, Units
from cbrs.kb.namespaces import shorten
from cbrs.kb.stated_quantities import stated_levels
from cbrs.sim.context import SimContext, SkillFailed

__all__ = ["Level", "levels", "measure"]


@dataclass(frozen=True)
class Level:
    """A level a place states, or its class: the number, its unit and the property that states it."""

    value: float
    unit: str
    prop: str


def levels(kb: KnowledgeBase, quantity: str, places: tuple[str, ...], where: MapPlaces) -> dict[str, Level]:
    """The level of ``quantity`` (a class of reading) of each of ``places`` (things of the map): its own,
    else its nearest class's (the one with the most superclasses among those that state one), stated with
    a property that is a level of ``quantity`` or a class above it (the most specific first); a place with
    neither is left out. A property with no unit (``home:levelUnit``) is not read: its numbers could be in
    any unit."""
    kinds = where.superclasses.get(quantity, frozenset({quantity}))
    found = [s for s in stated_levels(kb.select("place_levels")) if s.quantity in kinds]
    found.sort(key=lambda s: (-len(where.superclasses.get(s.quantity, ())), s.prop))
    by_subject: dict[str, Level] = {}
    for s in found:
        by_subject.setdefault(s.thing, Level(s.value, s.unit, s.prop))
    result: dict[str, Level] = {}
    for place in places:
        if place in by_subject:
            result[place] = by_subject[place]
            continue
        above = where.above(place)
        nearest = sorted((c for c in above if c in by_subject), key=lambda c: (-len(where.superclasses.get(c, ())), c))
        if nearest:
            result[place] = by_subject[nearest[0]]
    return result


def measure(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """The running component's reading of each of its outputs: the level of the places it measures."""
    iri = ctx.component or ""
    try:
        ad = ctx.kb.description(iri)
    except NotFoundError:
        raise SkillFailed(f"{device}: {shorten(iri)} is no longer described, so where it measures is unknown") from None
    where = MapPlaces.read(ctx.kb)
    on = ad.device if isinstance(ad, Advertisement) else None
    places = where.measured(ad.area, on)
    if not places:
        if stated(ad.area):
            named = ", ".join(shorten(a) for a in ad.area.areas) if ad.area and ad.area.areas else "its box"
            raise SkillFailed(f"{device}: its effective area ({named}) holds no place of the map: nowhere to read")
        raise SkillFailed(
            f"{device}: it states no effective area, and the map puts its device ({shorten(on or '?')}) in no room"
            " (home:x and home:y, an extent, or home:isLocated), so it has nowhere to read"
        )
    units = Units.read(ctx.kb)
    outputs: dict[str, Any] = {}
    for parameter in ad.outputs:
        if not parameter.name or not parameter.type:
            continue
        found = levels(ctx.kb, parameter.type, places, where)
        if not found:
            raise SkillFailed(
                f"{device}: no place it measures ({', '.join(shorten(p) for p in places)}) states a level of"
                f" {shorten(parameter.type)} (a property with home:levelOf and home:levelUnit), nor does its class"
            )
        unit = next(iter(found.values())).unit
        try:
            values = [units.convert(level.value, level.unit, unit) for level in found.values()]
            key = units.by_iri[unit].key if unit in units.by_iri else ""
        except UnitError as error:
            raise SkillFailed(f"{device}: {error}") from error
        if not key:
            raise SkillFailed(f"{device}: the store gives {shorten(unit)} no reading key (home:readingKey)")
        outputs[parameter.name] = {"@type": parameter.type, key: round(sum(values) / len(values), 3)}
    return outputs
