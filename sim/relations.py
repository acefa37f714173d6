"""The generic relations a statement's predicate maps to (the store's computables), for things at hand.

A statement of the knowledge base names classes: (Cup, isLocated, BelowOfTap). The environment grounds
each side in a thing at hand (a ``Grounded`` role and name: this object, that gripper, the base, the
person, a region of the map) and asks a ``Judge`` whether the predicate's computable test (``inside``,
``on``, ``near``, ``above``, ``grasped-by``, ``with``, ``contains``) holds between them. The dispatch
from test and roles to a primitive question is the same for every judge; two answer the primitives:
what the robots believe, from perception and proprioception (:mod:`sim.perceived`), and what is true
in the simulator (:mod:`sim.referee`), which only reports whether a task really succeeded.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

from cbrs.kb.semantic_map import Thing
from cbrs.sim.arms import ArmSide
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.world import HomeWorld

__all__ = ["Grounded", "Judge", "region_of"]


@dataclass(frozen=True)
class Grounded:
    """One side of a statement, grounded: ``role`` is what kind of thing it is (``thing``, ``object``,
    ``gripper``, ``platform``, ``base``, ``robot``, ``person``, ``region``, ``substance``) and ``name``
    which one (an IRI for a ``thing``, a body or arm-side name otherwise)."""

    role: str
    name: str


def region_of(thing: Thing, furniture: bool = False) -> Region:
    """Where an object is in or on ``thing``: its own box for a region or a room, whose bottom is where
    things rest; the top of a piece of ``furniture`` (a table's box reaches down to the floor, and
    nothing is put on the table's floor)."""
    box = thing.box
    floor = box.max_z if furniture else box.min_z
    return Region(thing.name, box.min_x, box.max_x, box.min_y, box.max_y, floor, box.max_z)


class Judge(ABC):
    """Decides a computable test between two grounded things; None when the test does not apply to them."""

    def __init__(self, world: HomeWorld) -> None:
        self.world = world

    def decide(
        self, test: str, subject: Grounded, obj: Grounded, arm: ArmSide | None, region: Region | None = None
    ) -> bool | None:
        """``arm`` is the arm at work (for a statement about "the gripper"; None: any arm, as the task's
        goals are checked after the last step), ``region`` where the carried object goes (for a statement
        about "the place")."""
        thing = self.object_name(subject)
        if test == "near":
            if subject.role == "gripper":
                target = self.object_name(obj)
                return target is not None and self.gripper_near(ArmSide(subject.name), target)
            if subject.role == "base" and obj.role == "person":
                return self.base_near_person(obj.name)
            if subject.role == "base":
                place = self.thing(obj)
                if place is None or place.dock is None:
                    return None
                return self.base_near(Pose2D(place.dock.x, place.dock.y, place.dock.yaw))
            return None
        if thing is None:
            return None
        if test == "grasped-by":
            return self.grasped(thing, arm if obj.role == "gripper" else None)
        if test == "with":
            return self.with_person(thing, obj.name if obj.role == "person" else None)
        if test == "contains":
            return self.contains_water(thing)
        if test == "on" and obj.role == "platform":
            return self.on_platform(thing)
        where = region if obj.role == "region" and region is not None else None
        if where is None:
            place = self.thing(obj)
            where = region_of(place, place.iri in self.world.map.furniture) if place is not None else None
        if where is None:
            return None
        if test == "above":
            return self.above(thing, where)
        if test in ("inside", "on"):
            return self.located_in(thing, where, upright=thing in self.world.containers)
        return None

    def object_name(self, grounded: Grounded) -> str | None:
        """The body name of a movable object, if the grounded thing is one."""
        if grounded.role == "object":
            return grounded.name
        if grounded.role == "thing" and grounded.name in self.world.map.objects:
            return self.world.map.objects[grounded.name].name
        return None

    def thing(self, grounded: Grounded) -> Thing | None:
        """The map's thing (with an extent) a grounded region or thing is."""
        if grounded.role == "thing":
            return self.world.map.things.get(grounded.name)
        if grounded.role == "region":
            return next((t for t in self.world.map.things.values() if t.name == grounded.name), None)
        return None

    # -- the primitive questions ---------------------------------------------------------------

    @abstractmethod
    def gripper_near(self, side: ArmSide, name: str) -> bool: ...

    @abstractmethod
    def base_near_person(self, person: str) -> bool | None: ...

    @abstractmethod
    def base_near(self, dock: Pose2D) -> bool:
        """At a docking pose, heading included."""

    @abstractmethod
    def grasped(self, name: str, side: ArmSide | None) -> bool: ...

    @abstractmethod
    def with_person(self, name: str, person: str | None) -> bool: ...

    @abstractmethod
    def contains_water(self, name: str) -> bool | None: ...

    @abstractmethod
    def on_platform(self, name: str) -> bool: ...

    @abstractmethod
    def above(self, name: str, region: Region) -> bool | None: ...

    @abstractmethod
    def located_in(self, name: str, region: Region, upright: bool) -> bool | None: ...
