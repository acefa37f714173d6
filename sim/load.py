"""A load cell under a place of the simulated home: what rests on it and the weight it bears, from the physics.

A lab's device that is no camera (a kitchen scale's plate, a shelf's presence mat) senses the world by
what stands on it. The simulation stands in for that hardware from pybullet's contacts of the last
physics step and the bodies' masses, never from the map, so an empty plate weighs nothing whatever a
plan believes (docs/components.md, "The simulation's sensors"):

- a *place* is a body of the home (a table, the tray): the contacts it bears from above; or a thing of
  the map with an extent and no body (a scale's plate on the table, the region below the tap): the
  contacts whose point lies in its floor plan and between its lowest and highest height (give or take
  ``SURFACE_TOLERANCE``), whatever body supports them;
- a contact bears load when its normal is within ``SUPPORT_ANGLE`` of the vertical (a side touch bears
  none); the body above it *rests* on the place;
- the *load* is the sum of those contacts' normal forces, their vertical parts, over ``GRAVITY``: the mass
  a load cell under the place reads, with whatever stands on what rests there (a cup on a saucer);
- each resting body comes with its mass in the simulation (its base and its links: the cup's water
  surface is a link of 1 g).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pybullet as p

from cbrs.kb.semantic_map import Thing, local_name
from cbrs.sim.errors import UnknownPlaceError, WorldClosedError
from cbrs.sim.world import GRAVITY, HomeWorld

__all__ = ["SUPPORT_ANGLE", "SURFACE_TOLERANCE", "Load", "Resting", "measure_load"]

SURFACE_TOLERANCE = 0.01
"""m: how far above or below a place's extent a contact may lie and still be on it (the table's top is
where the map puts it to within a millimetre; a resting body's contacts lie on it to within the solver's
penetration)."""
SUPPORT_ANGLE = 45.0
"""Degrees from the vertical within which a contact's normal bears load (a cup leaning on a wall bears
on the wall, not on the plate under it)."""


@dataclass(frozen=True)
class Resting:
    """A body that stands on the place: its name in the simulation, its IRI when the map has it, its mass."""

    name: str
    iri: str | None
    mass_kg: float


@dataclass(frozen=True)
class Load:
    """What a load cell under ``place`` (an IRI, or a body's name) read at ``time`` (simulated seconds)."""

    place: str
    time: float
    load_kg: float
    resting: tuple[Resting, ...]


@dataclass(frozen=True)
class _Place:
    iri: str
    body: int | None
    thing: Thing | None


def measure_load(
    world: HomeWorld,
    place: str,
    tolerance: float = SURFACE_TOLERANCE,
    support_angle: float = SUPPORT_ANGLE,
) -> Load:
    """What rests on ``place`` (an IRI or a local name) now, and the weight it bears (the module's rules);
    :class:`UnknownPlaceError` for a name that is no body and no place with an extent."""
    if world.closed:
        raise WorldClosedError(world.client)
    where = _resolve(world, place)
    upright = math.cos(math.radians(support_angle))
    force = 0.0
    resting: set[int] = set()
    for contact in p.getContactPoints(physicsClientId=world.client):
        a, b, on_a, on_b, normal, pushed = contact[1], contact[2], contact[5], contact[6], contact[7], contact[9]
        if normal[2] >= upright:  # the normal points from B to A: A is above
            upper, lower = a, b
        elif normal[2] <= -upright:
            upper, lower = b, a
        else:
            continue
        if where.body is not None:
            if lower != where.body or upper == where.body:
                continue
        elif where.thing is None or not _inside(where.thing, on_a, on_b, tolerance):
            continue
        force += pushed * abs(normal[2])
        resting.add(upper)
    bodies = tuple(sorted((_resting(world, body) for body in resting), key=lambda r: r.name))
    return Load(where.iri, world.time, force / GRAVITY, bodies)


def _resolve(world: HomeWorld, place: str) -> _Place:
    """The body or the extent ``place`` names: a map thing by IRI or local name, an object, or a body."""
    things = world.map.things
    thing = things.get(place) or next((t for t in things.values() if t.name == place), None)
    obj = world.map.objects.get(place) or next((o for o in world.map.objects.values() if o.name == place), None)
    name = thing.name if thing is not None else obj.name if obj is not None else place
    iri = thing.iri if thing is not None else obj.iri if obj is not None else place
    body = world.bodies.get(name)
    if body is None and thing is None:
        raise UnknownPlaceError(place)
    return _Place(iri, body, thing)


def _inside(thing: Thing, on_a: tuple[float, ...], on_b: tuple[float, ...], tolerance: float) -> bool:
    x, y, z = ((u + v) / 2.0 for u, v in zip(on_a, on_b, strict=True))
    box = thing.box
    return box.contains_xy(x, y) and box.min_z - tolerance <= z <= box.max_z + tolerance


def _resting(world: HomeWorld, body: int) -> Resting:
    name = world.name_of(body) or f"body {body}"
    links = p.getNumJoints(body, physicsClientId=world.client)
    mass = sum(p.getDynamicsInfo(body, link, physicsClientId=world.client)[0] for link in range(-1, links))
    return Resting(name, _iri(world, name), mass)


def _iri(world: HomeWorld, name: str) -> str | None:
    """The map's IRI of the body named ``name`` (bodies are named by their IRI's local name)."""
    return next((iri for iri in sorted(world.map.types) if local_name(iri) == name), None)
