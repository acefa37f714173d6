"""What a semantic map must hold for the simulated home to be built from it, checked as one.

A lab that replaces the bundled home with its own (``cbrs load --graph map --replace``, docs/tasks.md "A
home of your own") writes every room, robot and person itself. The simulation takes rooms to make the
floor of, mobile robots (one; none, a home where only the arms work, and a task for a base is refused
before it runs; several, each built, a run driving the one its plan works), the arms on the torso (one or
two, a "left" and a "right" one, each side once; none, a home where the robots only drive), and any
number of people (none: a home where the robots only move things; several: a resident and a caregiver);
each base, each person and every docking pose start on the floor of a room, none inside a wall, a piece
of furniture or a robot's body. A map that lacks one of them, or puts a start where nothing could stand, is refused
with a :class:`HomeError` naming what it lacks and where, before anything is built or moves. A piece of
furniture objects stand on with no docking pose is built, and reported (:func:`undocked_supports`): the
arms of a robot beside it may reach it, but the mobile base has nowhere to park to fetch from it, so a
task that would is refused (:class:`NoDockingPoseError`, :func:`docked_place`). Before, a
map had to hold exactly one person: a home with nobody modelled, or two residents, stopped every task,
also those that never look for a person. Which person a step means is asked per run
(:mod:`kb.person_choice`); whether a camera sees the person or an object, before each run too, of the
camera the run's steps look with (``sim.sight``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

from cbrs.kb.semantic_map import HOME, MapError, Pose, SemanticMap, Thing, local_name

__all__ = [
    "NEEDS_BASE",
    "HomeError",
    "NoDockingPoseError",
    "NoMobileBaseError",
    "Undocked",
    "check_home",
    "docked_place",
    "undocked_supports",
]

_ARM_SIDES = ("left", "right")
NEEDS_BASE = "a robot with home:hasPlatform, home:hasMarker, home:x, home:y, home:sizeX and home:sizeY"
"""What graph:map says of a mobile base, for a message that asks for one."""


class HomeError(MapError, ValueError):
    """The semantic map lacks, or has too many of, what the simulated home is built from, or starts a
    robot or person where nothing can stand. ``thing`` is what is missing (a class) or misplaced.
    Also a ``ValueError``, which the simulation raised for some of these before."""


class NoMobileBaseError(HomeError):
    """A home with no mobile base (no robot of graph:map with home:hasPlatform or home:hasMarker), or with
    several (``bases``, their IRIs), asked for what only the base the simulation drives has: its drive, its
    pose, its platform or its marker. ``needed_by`` says who asked. A run is refused before this can happen,
    by the components it cannot run (``sim.run_checks.without_base``)."""

    def __init__(self, needed_by: str, bases: tuple[str, ...] = ()) -> None:
        self.needed_by, self.bases = needed_by, bases
        if bases:
            said = (
                f"has {len(bases)} individuals in the map ({', '.join(local_name(b) for b in bases)}), and "
                f"{needed_by} needs the one the simulation drives: a run drives the one its plan works, and none "
                "is chosen"
            )
        else:
            said = (
                f"has no individual in the map, and {needed_by} needs one: the home has no mobile base (add "
                f"{NEEDS_BASE} to graph:map, as ontologies/world.ttl has the bundled one)"
            )
        super().__init__(HOME + "MobileRobot", said)


class NoDockingPoseError(HomeError):
    """The object a task fetches stands only on things with no docking pose (``home:dockingPose``): the
    mobile base has nowhere to park to take it from there. ``thing`` is the object, ``supports`` what it
    is on (by the world graph, else the map)."""

    def __init__(self, thing: str, supports: tuple[str, ...]) -> None:
        self.supports = supports
        names = " and ".join(local_name(s) for s in supports)
        which = "which has no" if len(supports) == 1 else "none of which has a"
        super().__init__(
            thing,
            f"is on {names} (home:isLocatedOn), {which} home:dockingPose: the mobile base has nowhere to "
            f"park to fetch it; give {names} a home:dockingPose (a home:Pose2D with home:x, home:y and "
            "home:yaw, on a room's floor beside it, as lab4_trolley.ttl's Trolley1Dock in docs/examples)",
        )


@dataclass(frozen=True)
class Undocked:
    """A thing of the map that objects stand on and that has no docking pose, with those objects."""

    support: str
    objects: tuple[str, ...]

    @property
    def said(self) -> str:
        """The warning, in words."""
        held = ", ".join(local_name(o) for o in self.objects)
        return (
            f"{local_name(self.support)} holds {held} and has no home:dockingPose: a task that sends the "
            "mobile base to fetch from it is refused (an arm beside it may still reach it)"
        )


def undocked_supports(semantic_map: SemanticMap) -> list[Undocked]:
    """The things objects stand on (``home:isLocatedOn``) that have no docking pose, by IRI: no refusal
    of the home (a spice rack on a table, a wall cabinet, a sofa's book are there to be reached by the
    arms or not at all), but what ``cbrs home`` warns of."""
    held: dict[str, list[str]] = {}
    for obj in semantic_map.objects.values():
        thing = semantic_map.things.get(obj.support or "")
        if thing is not None and thing.dock is None:
            held.setdefault(thing.iri, []).append(obj.iri)
    return [Undocked(support, tuple(sorted(objects))) for support, objects in sorted(held.items())]


def docked_place(semantic_map: SemanticMap, thing: str, supports: Iterable[str]) -> Thing | None:
    """The first of ``supports`` (what ``thing`` is on, believed first, then by the map) that the mobile
    base can park at: a thing of the map with a docking pose. :class:`NoDockingPoseError` when it is on
    things of the map and none has one; None when it is on nothing the map gives an extent (rooms aside)."""
    rooms = semantic_map.rooms  # a room it is believed in is no support to park at
    known = [semantic_map.things[s] for s in dict.fromkeys(supports) if s in semantic_map.things and s not in rooms]
    for place in known:
        if place.dock is not None:
            return place
    if known:
        raise NoDockingPoseError(thing, tuple(place.iri for place in known))
    return None


def check_home(semantic_map: SemanticMap) -> None:
    """Refuse a map the simulated home cannot be built from (:class:`HomeError`), naming what is wrong."""
    semantic_map.extent()  # no rooms: a MapError of its own
    _check_counts(semantic_map)
    _check_arms(semantic_map)
    for iri, what, pose in _starts(semantic_map):
        _check_floor(semantic_map, iri, what, pose)


def _check_arms(semantic_map: SemanticMap) -> None:
    """Each arm has a side, "left" or "right", of its own: one arm or two, either side (none: the robots only
    drive, and a task for an arm is refused before it runs)."""
    sides: dict[str, list[str]] = {}
    for iri in sorted(semantic_map.arms):
        side = semantic_map.arms[iri].side
        if side not in _ARM_SIDES:
            raise HomeError(
                iri,
                f'has home:armSide {side!r}: an arm is on the "left" or the "right" of its robot (which way it folds '
                "when idle, and the name its steps use); write one of them",
            )
        sides.setdefault(side, []).append(iri)
    for side, iris in sides.items():
        if len(iris) > 1:
            other = "right" if side == "left" else "left"
            raise HomeError(
                iris[1],
                f'has home:armSide "{side}", as {local_name(iris[0])} has: the simulated robot takes one arm a side; '
                f'give one of them home:armSide "{other}", or take one out of graph:map',
            )


def _check_counts(semantic_map: SemanticMap) -> None:
    """Mobile bases are any number (none, one, several: each built); two whose footprints overlap where the
    map starts them are refused, naming both."""
    robots = [semantic_map.robots[iri] for iri in sorted(semantic_map.robots)]
    for i, one in enumerate(robots):
        for other in robots[i + 1 :]:
            apart = math.hypot(one.start.x - other.start.x, one.start.y - other.start.y)
            room = (math.hypot(*one.footprint) + math.hypot(*other.footprint)) / 2
            if apart < room:
                raise HomeError(
                    other.iri,
                    f"starts at ({other.start.x:.2f}, {other.start.y:.2f}), {apart:.2f} m from {local_name(one.iri)} "
                    f"at ({one.start.x:.2f}, {one.start.y:.2f}): two mobile bases start at least {room:.2f} m apart "
                    "(half of each footprint's diagonal); move one",
                )


def _starts(semantic_map: SemanticMap) -> Iterator[tuple[str, str, Pose]]:
    """(IRI, what it is, pose) of everything that starts or parks on the floor."""
    for robot in semantic_map.robots.values():
        yield robot.iri, "starts", robot.start
    for person in semantic_map.people.values():
        yield person.iri, "starts", person.start
    for iri in sorted(semantic_map.things):
        dock = semantic_map.things[iri].dock
        if dock is not None:
            yield iri, "has its docking pose", dock


def _check_floor(semantic_map: SemanticMap, iri: str, what: str, pose: Pose) -> None:
    """``pose`` is on the floor of a room, and inside no wall, furniture or robot body."""
    rooms = [semantic_map.things[r] for r in sorted(semantic_map.rooms) if r in semantic_map.things]
    where = f"({pose.x:.2f}, {pose.y:.2f})"
    if not any(room.box.contains_xy(pose.x, pose.y) for room in rooms):
        extents = "; ".join(
            f"{room.name} x {room.box.min_x:g}-{room.box.max_x:g}, y {room.box.min_y:g}-{room.box.max_y:g}"
            for room in rooms
        )
        raise HomeError(iri, f"{what} at {where}, in no room of the map ({extents}): move it onto a room's floor")
    solid = sorted(semantic_map.walls | semantic_map.furniture | semantic_map.bodies)
    for other in solid:
        thing = semantic_map.things.get(other)
        if thing is not None and thing.box.contains_xy(pose.x, pose.y):
            raise HomeError(
                iri,
                f"{what} at {where}, inside {local_name(other)} (x {thing.box.min_x:g}-{thing.box.max_x:g}, "
                f"y {thing.box.min_y:g}-{thing.box.max_y:g}): move it where nothing stands",
            )
