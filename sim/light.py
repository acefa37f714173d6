"""The simulated home's light sensors: the illuminance a sensor board reads in its room.

The physics renders no light level, so the simulated light sensor reads what the store states: a place of
the map says its light level in lux (``home:lightLevel``, in graph:map: ``world:LivingRoom home:lightLevel
12.0`` for a room at night), else the nearest of its classes that states one (the bundled ``home.ttl``
gives ``home:Room`` 300 lx, a room lit by day). A sensor reads the places of the map its effective area
names (``cbrs:effectiveArea home:LivingRoom``: the living rooms), their mean where it names several; one
whose area names no place has nowhere to read and fails, saying so. The reading is a ``home:Illuminance``
in lux (docs/values.md): ``{"@type": ".../home#Illuminance", "lux": 300.0}``. docs/execution.md, "A sensed
precondition in the simulated home".
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import NotFoundError
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.sim.context import SimContext, SkillFailed

__all__ = ["ILLUMINANCE", "light_levels", "measure_illuminance"]

ILLUMINANCE = PREFIXES["home"] + "Illuminance"


def light_levels(kb: KnowledgeBase, areas: tuple[str, ...]) -> dict[str, float]:
    """The light level (lux) of each place of the map of a class at or below one of ``areas``: its own,
    else its nearest class's (the one with the most superclasses among those that state one); a place
    with neither is left out."""
    stated_rows, type_rows, up_rows = kb.select_each(("light_levels", "map_types", "subclasses"))
    stated: dict[str, float] = {}
    for row in stated_rows:
        try:
            stated.setdefault(row["subject"].value, float(row["lux"].value))
        except ValueError:
            continue
    up: dict[str, set[str]] = {}
    for row in up_rows:
        up.setdefault(row["class"].value, {row["class"].value}).add(row["superclass"].value)
    types: dict[str, set[str]] = {}
    for row in type_rows:
        types.setdefault(row["thing"].value, set()).add(row["type"].value)
    found: dict[str, float] = {}
    for thing, classes in sorted(types.items()):
        above = set().union(*(up.get(c, {c}) for c in classes))
        if not any(area in above for area in areas):
            continue
        if thing in stated:
            found[thing] = stated[thing]
            continue
        candidates = sorted((c for c in above if c in stated), key=lambda c: (-len(up.get(c, ())), c))
        if candidates:
            found[thing] = stated[candidates[0]]
    return found


def measure_illuminance(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
    """The running component's reading: the light level of the places its effective area names."""
    iri = ctx.component or ""
    try:
        area = ctx.kb.description(iri).area
    except NotFoundError:
        raise SkillFailed(f"{device}: {shorten(iri)} is no longer described, so where it measures is unknown") from None
    if area is None or not area.areas:
        raise SkillFailed(f"{device}: its effective area names no place, so it has nowhere to read the light")
    levels = light_levels(ctx.kb, area.areas)
    if not levels:
        named = ", ".join(shorten(a) for a in area.areas)
        raise SkillFailed(
            f"{device}: no place of the map of {named} states a light level (home:lightLevel), nor does its class"
        )
    lux = sum(levels.values()) / len(levels)
    return {"illuminance": {"@type": ILLUMINANCE, "lux": round(lux, 3)}}
