"""What a semantic map must hold for the simulated home to be built from it, checked as one.

A lab that replaces the bundled home with its own (``cbrs load --graph map --replace``, docs/tasks.md "A
home of your own") writes every room, robot and person itself. The simulation takes rooms to make the
floor of, one mobile robot and a dual-arm robot with a left and a right arm, and any number of people
(none: a home where the robots only move things; several: a resident and a caregiver); the base, each
person and every docking pose start on the floor of a room, none inside a wall, a piece of furniture or
a robot's body. A map that lacks one of them, or puts a start where nothing could stand, is refused
with a :class:`HomeError` naming what it lacks and where, before anything is built or moves. Before, a
map had to hold exactly one person: a home with nobody modelled, or two residents, stopped every task,
also those that never look for a person. Which person a step means is asked per run
(:mod:`kb.person_choice`); whether a camera sees the person or an object, before each run too, of the
camera the run's steps look with (``sim.sight``).
"""

from __future__ import annotations

from collections.abc import Iterator

from cbrs.kb.semantic_map import HOME, MapError, Pose, SemanticMap, local_name

__all__ = ["HomeError", "check_home"]

_ARM_SIDES = ("left", "right")


class HomeError(MapError, ValueError):
    """The semantic map lacks, or has too many of, what the simulated home is built from, or starts a
    robot or person where nothing can stand. ``thing`` is what is missing (a class) or misplaced.
    Also a ``ValueError``, which the simulation raised for some of these before."""


def check_home(semantic_map: SemanticMap) -> None:
    """Refuse a map the simulated home cannot be built from (:class:`HomeError`), naming what is wrong."""
    semantic_map.extent()  # no rooms: a MapError of its own
    _check_counts(semantic_map)
    arms = sorted(arm.side for arm in semantic_map.arms.values())
    if arms != list(_ARM_SIDES):
        raise HomeError(
            HOME + "Arm",
            f"is missing: the map's arms have the sides {', '.join(arms) or 'none'}, and the dual-arm robot needs one "
            '"left" and one "right" arm (home:hasArm, each with home:armSide, home:x, home:y, home:z, '
            "home:reach and home:hasGripper; the bundled ones are in ontologies/world.ttl)",
        )
    for iri, what, pose in _starts(semantic_map):
        _check_floor(semantic_map, iri, what, pose)


def _check_counts(semantic_map: SemanticMap) -> None:
    robots = sorted(semantic_map.robots)
    needs = "a robot with home:hasPlatform, home:hasMarker, home:x, home:y, home:sizeX and home:sizeY"
    if not robots:
        raise HomeError(
            HOME + "MobileRobot",
            f"has no individual in the map, and the simulated home takes one: add {needs} to graph:map "
            "(the bundled home's are in ontologies/world.ttl)",
        )
    if len(robots) != 1:
        # Every run builds the whole map, so this stops every task, not only one about the second robot.
        raise HomeError(
            HOME + "MobileRobot",
            f"has {len(robots)} individuals in the map ({', '.join(robots)}): the simulated home takes one mobile "
            "robot; take the extra ones out of graph:map (a SPARQL update, or the map's files loaded into a fresh "
            "store), whatever task runs",
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
