"""What the robots believe of the world: where things are, from perception and proprioception only.

The executor verifies each step's effects against this belief, and the world graph is written from
it; the simulator's state is read only by the referee (:mod:`sim.referee`). The sources:

* the cameras of the map, rendered (pixels and depth, nothing else): an object is found by its colour
  near where it is believed to be (where the map put it, before it is first seen; anywhere, if its
  colour is its own and it is not there), a person by their shirt, a container's water by its colour;
* the arms: whether a gripper holds something is the gripper's own state; a held object is where the
  hand holds it, by the grasp it was taken with; an object let go is where the hand let it go, until
  a camera sees it again;
* the base: its pose is its odometry, and a load sensor in its platform says what rests on it;
* inference: an object that leaves the platform while the base is near a person was taken by them.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.person_choice import look_alikes
from cbrs.sim import predicates as pred
from cbrs.sim.arms import Arm, ArmSide
from cbrs.sim.cameras import Camera, Frame, project
from cbrs.sim.errors import SimulationError
from cbrs.sim.geometry import Pose2D, Region, Vec3
from cbrs.sim.layout import PERSON_HAND_HEIGHT
from cbrs.sim.perception import recognise_object, track_person
from cbrs.sim.relations import Judge
from cbrs.sim.world import HomeWorld

__all__ = ["PERCEIVED_RESTING", "SEARCH_RADIUS", "UNSEEN_AT_START", "PerceivedWorld", "Sighting"]

PERCEIVED_RESTING = 0.03
"""An object is believed to rest on a surface when its estimated bottom is within 3 cm of it: the
depth image puts a centre within about 1 cm, and a hand lets go of an object up to 2 cm above the
surface, where it then settles."""
SEARCH_RADIUS = 0.25
"""An object is looked for within 25 cm of where it is believed to be; a thing of the same colour
farther away is another thing."""
GRASP_MIN_WIDTH = 0.002
"""A gripper holds something when its fingers stopped at least 2 mm apart (closed on nothing, they meet)."""


@dataclass(frozen=True)
class Sighting:
    """Where a thing is believed to be (its centre), what said so, and when (simulated seconds)."""

    position: Vec3
    source: str
    time: float


class PerceivedWorld(Judge):
    """The robots' belief, updated by :meth:`look` (cameras) and :meth:`feel` (arms, base, platform)."""

    def __init__(self, world: HomeWorld) -> None:
        super().__init__(world)
        self.objects: dict[str, Sighting] = {}
        self.people: dict[str, Sighting] = {}
        self.holders: dict[str, str] = {}
        """Who is believed to hold an object after a hand-over: object name -> person name."""
        self.wet: set[str] = set()
        """The containers water was seen in."""
        self.loaded: set[str] = set()
        """What the platform's load sensor reported last."""
        self.frames = 0
        """How many images were taken for the belief (a measure of its cost)."""
        self._releases: dict[ArmSide, tuple[int, Vec3] | None] = {}
        water = world.map.appearance(PREFIXES["home"] + "Water")
        self.water_colour: str | None = water[0] if water is not None else None
        """The colour water is seen by (the semantic map's water), if the map says."""
        self.colour_owners: dict[str, frozenset[str]] = _colour_owners(world)
        """Who shows each colour, by the map (objects, markers' patches, shirts, water): an object is
        looked for anywhere only when nothing else is of its colour."""
        self.look_alikes: frozenset[str] = frozenset(iri for _, iris in look_alikes(world.map) for iri in iris)
        """The people who share their shirt colour with another (by IRI): the cameras, which find a person by
        the largest patch of that colour, cannot say which of them a patch is, so none of them is believed
        anywhere by sight (the map's place stands), and a task for one is refused by the plan's checks
        (``kb.person_choice.LookAlikePeopleError``) whatever the seed put where."""

    # -- updating the belief ---------------------------------------------------------------------

    def feel(self) -> None:
        """What the robots know of themselves: held objects, objects let go, the platform's load."""
        time = self.world.time
        arms = list(self.world.arms.values())
        # Where a hand let go first, then what the hands hold now: an object one arm let go of and the
        # other took on is where the taking hand holds it, whichever arm is felt first.
        for arm in arms:
            release = arm.released
            if release is not None and release != self._releases.get(arm.side):
                self._releases[arm.side] = release
                let_go = self._name(release[0])
                if let_go is not None:
                    self.objects[let_go] = Sighting(release[1], f"{arm.side.value} hand, let go", time)
        for arm in arms:
            name = self._name(arm.held)
            centre = arm.carried_centre()
            if name is not None and centre is not None:
                self.objects[name] = Sighting(centre, f"{arm.side.value} hand", time)
                self.holders.pop(name, None)
        if self.world.mobile is None:
            return  # a home with no mobile base (or several): no platform it drives, nothing loaded on it
        base = self.world.base_pose()
        loaded = set(pred.objects_on_platform(self.world))  # the platform's load sensor
        for name in loaded:
            height = self.world.objects[name].size[2]
            self.objects[name] = Sighting(
                (base.x, base.y, self.world.platform_height + height / 2), "platform load sensor", time
            )
        for name in sorted(self.loaded - loaded):
            if self._holding_arm(name) is None:
                self._handed_over(name, base, time)
        self.loaded = loaded

    def look(self, objects: Iterable[str] | None = None, people: bool = True) -> None:
        """Update the belief of ``objects`` (body names; all by default) and, with ``people``, of the
        people, from the working cameras that may see them.

        An object's belief comes from the preferred camera that finds it: the cameras are asked in
        reverse name order (Kinect01, CeilingCamera02, CeilingCamera01 in the bundled home) and the
        first that finds the object decides; a camera is rendered only when it is asked. A person's
        comes from the camera looking down that sees most of their shirt, so all those are rendered; a
        person whose shirt colour another wears is not looked for (:attr:`look_alikes`): one patch would
        place both, and at seeds where the other's patch was larger the resident was believed in the
        kitchen at the visitor's place, and the run answered "no plan" instead of the look-alike refusal.
        """
        self.feel()
        names = sorted(self.world.objects) if objects is None else sorted(set(objects))
        names = [name for name in names if self._holding_arm(name) is None]  # the hand knows better
        cameras = [self.world.cameras[name] for name in sorted(self.world.cameras)]
        frames: dict[str, Frame | None] = {}
        for name in names:
            for camera in reversed(cameras):
                if camera.failed or not self._may_see(camera, name):
                    continue
                frame = self._frame(camera, frames)
                if frame is not None and self._find(frame, name):
                    break
        if not people:
            return
        found_people: dict[str, tuple[int, Sighting]] = {}
        for camera in cameras:
            frame = self._frame(camera, frames) if not camera.failed and _looks_down(camera) else None
            if frame is None:
                continue
            for person in self.world.map.people.values():
                if person.iri in self.look_alikes:
                    continue
                try:
                    estimate = track_person(frame, person.colour)
                except SimulationError:
                    continue
                sighting = Sighting((estimate.x, estimate.y, 0.0), camera.spec.name, frame.time)
                if estimate.pixels > found_people.get(person.name, (0, sighting))[0]:
                    found_people[person.name] = (estimate.pixels, sighting)
        for name, (_, sighting) in found_people.items():
            self.people[name] = sighting

    def _frame(self, camera: Camera, frames: dict[str, Frame | None]) -> Frame | None:
        """The camera's image for this look, taken the first time it is asked for (None if it fails)."""
        if camera.name not in frames:
            try:
                frames[camera.name] = camera.capture()
                self.frames += 1
            except SimulationError:
                frames[camera.name] = None
        return frames[camera.name]

    def position(self, name: str) -> Vec3 | None:
        """Where an object is believed to be (its centre), if anywhere."""
        sighting = self.objects.get(name)
        return sighting.position if sighting is not None else None

    def _find(self, frame: Frame, name: str) -> bool:
        """Look for an object in a frame near where it is believed to be (anywhere, if its colour is its
        own and it is not there); whether it was found, and then the belief is what the frame shows.

        A colour is the object's own only when nothing else of the map shows it: not another object, a
        base's marker patch, a person's shirt or the water. Searched for anywhere, such a patch would be
        taken for the object (a magenta remote found on the base's rear patch)."""
        obj = self.world.objects[name]
        prior = self.objects.get(name)
        near = prior.position[:2] if prior is not None else (obj.start.x, obj.start.y)
        unique = self.colour_owners.get(obj.colour, frozenset()) <= {obj.iri}
        for where in (near, None) if unique else (near,):
            try:
                estimate = recognise_object(frame, obj.colour, near=where, radius=SEARCH_RADIUS)
            except SimulationError:
                continue
            self.objects[name] = Sighting(estimate.position, frame.camera, frame.time)
            if name in self.world.containers and self.water_colour is not None:
                self._see_water(frame, name, estimate.position)
            return True
        return False

    def _see_water(self, frame: Frame, name: str, centre: Vec3) -> None:
        assert self.water_colour is not None
        rim = max(self.world.objects[name].size[:2]) / 2.0
        try:
            recognise_object(frame, self.water_colour, near=(centre[0], centre[1]), radius=rim)
        except SimulationError:
            self.wet.discard(name)  # the container was seen, its water was not
            return
        self.wet.add(name)

    def _handed_over(self, name: str, base: Pose2D, time: float) -> None:
        for person, sighting in sorted(self.people.items()):
            x, y, _ = sighting.position
            if base.distance_to(x, y) <= pred.NEAR_PERSON_DISTANCE:
                self.holders[name] = person
                self.objects[name] = Sighting((x, y, PERSON_HAND_HEIGHT), f"taken by {person}", time)
                return

    def _may_see(self, camera: Camera, name: str) -> bool:
        """Whether where the object is believed to be is in the camera's image, within its range."""
        obj = self.world.objects[name]
        believed = self.position(name)
        if believed is None:
            support = self.world.map.things.get(obj.support or "")
            z = (support.box.max_z if support is not None else 0.0) + obj.size[2] / 2
            believed = (obj.start.x, obj.start.y, z)
        spec = camera.spec
        distance = math.dist(spec.eye, believed)
        if not spec.near <= distance <= spec.far:
            return False
        pixels = project(camera.intrinsics, camera.camera_to_world, np.array([believed]))
        u, v = float(pixels[0, 0]), float(pixels[0, 1])
        return 0.0 <= u < spec.width and 0.0 <= v < spec.height  # NaN (behind the camera) is not

    def _name(self, body: int | None) -> str | None:
        name = self.world.name_of(body) if body is not None else None
        return name if name in self.world.objects else None

    def _holding_arm(self, name: str) -> Arm | None:
        body = self.world.body(name)
        return next((arm for arm in self.world.arms.values() if arm.held == body), None)

    # -- the primitive questions, on the belief ----------------------------------------------------

    def gripper_near(self, side: ArmSide, name: str) -> bool:
        where = self.position(name)
        arm = self.world.arm(side)
        size = self.world.objects[name].size
        near = pred.gripper_near_distance(arm.hand)
        return where is not None and pred.distance_to_extent(arm.ee_pose().position, where, size) <= near

    def base_near_person(self, person: str) -> bool | None:
        sighting = self.people.get(person)
        if sighting is None or self.world.mobile is None:
            return None  # no camera saw them, or no base: nothing to go by
        x, y, _ = sighting.position
        return self.world.base_pose().distance_to(x, y) <= pred.NEAR_PERSON_DISTANCE

    def base_near(self, dock: Pose2D) -> bool:
        odometry = self.world.base_pose()
        near = odometry.distance_to(dock.x, dock.y) <= pred.BASE_NEAR_DISTANCE
        return near and odometry.heading_error(dock.theta) <= pred.BASE_NEAR_HEADING

    def grasped(self, name: str, side: ArmSide | None) -> bool:
        arm = self._holding_arm(name)
        if arm is None or (side is not None and arm.side is not ArmSide(side)):
            return False
        return arm.gripper_width() >= GRASP_MIN_WIDTH

    def with_person(self, name: str, person: str | None) -> bool:
        holder = self.holders.get(name)
        return holder is not None and (person is None or holder == person)

    def contains_water(self, name: str) -> bool | None:
        if self.water_colour is None:
            return None  # the map says nothing of how water looks
        return name in self.wet

    def on_platform(self, name: str) -> bool:
        return name in self.loaded

    def above(self, name: str, region: Region) -> bool | None:
        where = self.position(name)
        if where is None:
            return None
        gap = where[2] - self.world.objects[name].size[2] / 2 - region.zmin
        return region.contains_xy(where[0], where[1]) and pred.ABOVE_MIN - PERCEIVED_RESTING <= gap <= pred.ABOVE_MAX

    def located_in(self, name: str, region: Region, upright: bool) -> bool | None:
        where = self.position(name)
        if where is None:
            return None
        if self._holding_arm(name) is not None:
            return False
        bottom = where[2] - self.world.objects[name].size[2] / 2
        return region.contains_xy(where[0], where[1]) and abs(bottom - region.zmin) <= PERCEIVED_RESTING


UNSEEN_AT_START = ("with", "grasped-by")
"""The tests (``home:computedBy``) that never find their relation holding in a world just built: a person
holds only what the base handed them (:attr:`PerceivedWorld.holders`), a hand only what it took. A task
whose goal they decide is planned for before the world is built as if it did not hold
(``actions.runner.refusal_before_world``'s ``unseen``)."""

_COLOUR_PROPERTIES = tuple(PREFIXES["home"] + name for name in ("colourName", "frontColourName", "rearColourName"))


def _colour_owners(world: HomeWorld) -> dict[str, frozenset[str]]:
    """Each colour the map gives anything (objects, people, robots' markers, any individual with a colour
    name) and the IRIs of what shows it."""
    owners: dict[str, set[str]] = {}
    shown = [(obj.iri, obj.colour) for obj in world.map.objects.values()]
    shown += [(person.iri, person.colour) for person in world.map.people.values()]
    for robot in world.map.robots.values():
        shown += [(robot.iri, colour) for colour in robot.marker_colours or ()]
    for iri, values in world.map.facts.items():
        shown += [(iri, colour) for name in _COLOUR_PROPERTIES for colour in values.get(name, [])]
    for iri, colour in shown:
        if colour:
            owners.setdefault(colour, set()).add(iri)
    return {colour: frozenset(iris) for colour, iris in owners.items()}


def _looks_down(camera: Camera) -> bool:
    """A camera that looks down from above (a ceiling camera) sees where people are."""
    spec = camera.spec
    return spec.eye[2] - spec.target[2] > 0.9 * math.dist(spec.eye, spec.target)
