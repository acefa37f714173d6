"""The simulated home: one pybullet client holding the rooms, the furniture, the people and the robots.

Everything is built from primitives except the two Panda arms (pybullet_data). Each world owns its
own physics client and passes its id on every call, so several worlds can live in one process. The
seed moves the cup, the pen, each person and the base's start a little; the same seed gives the same
world and, since stepping is deterministic, the same outcome for the same calls.
"""

from __future__ import annotations

import difflib
import hashlib
import logging
import math
from collections.abc import Callable, Hashable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import TracebackType

import numpy as np
import pybullet as p

from cbrs.kb.camera_view import default_image_size, image_up
from cbrs.kb.colour_windows import ColourWindow
from cbrs.kb.hands import PANDA_HAND
from cbrs.kb.home_check import NoMobileBaseError, check_home
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.person_choice import person_for
from cbrs.kb.semantic_map import Arm as ArmSpec
from cbrs.kb.semantic_map import Box, Dispenser, MapError, MapObject, MobileRobot, Person, SemanticMap, Thing, overlaps
from cbrs.sim import layout as L
from cbrs.sim.arms import PYBULLET_DATA, Arm, ArmDetail, ArmSide, Kinematics, panda_urdf
from cbrs.sim.base import MobileBase
from cbrs.sim.cameras import Camera
from cbrs.sim.errors import ImageSizeError, UnknownEntityError, WorldClosedError
from cbrs.sim.geometry import Pose2D, Pose3D, Quat, Region, Vec3, quat_from_yaw
from cbrs.sim.layout import CameraSpec
from cbrs.sim.perception import MarkerModel
from cbrs.sim.quiet import quiet_output
from cbrs.sim.scene import bundled_map

__all__ = [
    "GRAVITY",
    "SETTLE_NOTICE",
    "SOLVER_RESIDUAL",
    "TIME_STEP",
    "HomeWorld",
    "Perturbation",
    "Spread",
    "marker_model",
    "open_world",
]

log = logging.getLogger("cbrs.sim")
SETTLE_NOTICE = 0.005
"""An object that settling moves more than 5 mm across from where it was built (pushed by another it
was built in, after the seed moved them together) is said so in the log and in ``HomeWorld.settled``:
resting objects move less than 1 mm as they settle."""

GRAVITY = 9.81
"""m/s², downwards: what a load cell divides the force it measures by (``sim.load``)."""
TIME_STEP = 1.0 / 240.0
"""Physics step (s): pybullet's default, at which the Panda's controllers and contacts are stable."""
SOLVER_RESIDUAL = 1e-5
"""The constraint solver stops iterating within a step once the squares of an iteration's corrections of
its rows sum to less than this (Bullet's least-squares residual; at pybullet's default, 1e-7, the arms'
joint motors ran all 50 iterations of every step). See docs/simulation.md, "Speed"."""
FILL_RATE = 0.25
"""Fraction of the cup filled per second of open tap (a full cup takes 4 s)."""
TAP_OPEN_TRAVEL = 0.006
"""The tap runs while its lever is pushed in by more than 6 mm."""
LEVER_SPRING_FORCE = 4.0
"""N: the spring that closes the tap when the lever is let go."""
MARKER_LIFT = 0.002
"""The marker's patches lie on the platform: their top faces are 2 mm above it."""

_FLOOR = (0.78, 0.78, 0.76, 1.0)
_WALL = (0.92, 0.90, 0.84, 1.0)
_WOOD = (0.62, 0.50, 0.38, 1.0)
_WHITE = (0.93, 0.93, 0.95, 1.0)
_STEEL = (0.55, 0.56, 0.58, 1.0)
_DARK = (0.15, 0.15, 0.17, 1.0)
_TORSO = (0.45, 0.46, 0.50, 1.0)
_STATIC_GROUP, _NOT_STATIC = 2, -1 ^ 2
"""Bullet's collision filter group of static things, and a mask of every group but that one."""
WATER_CYAN = (0.05, 0.80, 0.80, 1.0)
HOME = PREFIXES["home"]


def _colours(semantic_map: SemanticMap) -> dict[str, ColourWindow]:
    """The colours some camera of the map tells apart, by name (the first camera's by IRI, where two name
    one differently): what a thing may be looked for by, and how a marker's patch of it is painted."""
    found: dict[str, ColourWindow] = {}
    for iri in sorted(semantic_map.cameras, reverse=True):
        found.update({window.name: window for window in semantic_map.cameras[iri].colours})
    return found


def _painted(colour: str, windows: dict[str, ColourWindow]) -> tuple[float, float, float, float]:
    """How a marker patch of ``colour`` is painted: its window's home:rgba (well inside the window)."""
    window = windows.get(colour)
    if window is None or window.rgba is None:
        known = ", ".join(name for name, w in windows.items() if w.rgba is not None)
        raise ValueError(f"no display colour (home:rgba of a colour window) for {colour!r}; known: {known}")
    return window.rgba


_CHASSIS = (0.28, 0.28, 0.30, 1.0)
_PLATFORM = (0.70, 0.70, 0.72, 1.0)
_SKIN = (0.85, 0.66, 0.52, 1.0)
_TROUSERS = (0.30, 0.30, 0.34, 1.0)

_IDENTITY: Quat = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Spread:
    """How far a seed moves things from the semantic map's start poses: each object up to ``object``
    metres in x and y (and, if it is not round, ``yaw`` radians), kept on its support; each person up to
    ``person`` metres; the base up to ``base`` metres and ``base_yaw`` radians. The default is the small
    jitter of a real home; the perturbation benchmark moves things much further."""

    object: float = 0.02
    yaw: float = 0.15
    person: float = 0.15
    base: float = 0.10
    base_yaw: float = 0.3


@dataclass(frozen=True)
class Perturbation:
    """The seed's deterministic offsets from the semantic map's start poses (metres, radians).
    ``person`` is the seed's shared draw, the offset of a map's only person; ``people`` each person's
    offset by IRI."""

    objects: Mapping[str, tuple[float, float, float]]
    person: tuple[float, float]
    base: tuple[float, float, float]
    people: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    bases: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)
    """Each mobile base's offsets by IRI: a map's only base takes the shared draw (``base``); with several,
    each draws its own (:meth:`of_base`)."""

    @classmethod
    def from_seed(
        cls,
        seed: int,
        objects: Mapping[str, tuple[str, bool]] | None = None,
        spread: Spread = Spread(),
        people: Sequence[str] = (),
        bases: Sequence[str] = (),
    ) -> Perturbation:
        """``objects`` maps each object's name to its IRI and whether it is round (no yaw offset);
        ``people`` are the map's people's IRIs. A map's only person takes the seed's shared draw, as before
        people were counted, so a home of one person is where it was at every seed; with several, each
        draws their own (:meth:`of_person`), and adding or removing one moves nobody else."""
        rng = np.random.default_rng(seed)
        person = rng.uniform(-spread.person, spread.person, 2)
        base = rng.uniform([-spread.base, -spread.base, -spread.base_yaw], [spread.base, spread.base, spread.base_yaw])
        moved = {name: cls.of_object(seed, iri, round_, spread) for name, (iri, round_) in (objects or {}).items()}
        shared = (float(person[0]), float(person[1]))
        alone = len(people) == 1
        offsets = {iri: shared if alone else cls.of_person(seed, iri, spread) for iri in people}
        drawn = (float(base[0]), float(base[1]), float(base[2]))
        one = len(bases) == 1
        each = {iri: drawn if one else cls.of_base(seed, iri, spread) for iri in bases}
        return cls(moved, shared, drawn, offsets, each)

    @staticmethod
    def of_base(seed: int, iri: str, spread: Spread = Spread()) -> tuple[float, float, float]:
        """One base's offsets (dx, dy, dyaw) at ``seed`` in a home of several: drawn, as a person's are, from a
        generator seeded by the seed and the SHA-256 of its IRI."""
        words = np.frombuffer(hashlib.sha256(iri.encode("utf-8")).digest(), dtype="<u4")
        rng = np.random.default_rng([seed, *(int(word) for word in words)])
        limits = [spread.base, spread.base, spread.base_yaw]
        dx, dy, dyaw = rng.uniform([-v for v in limits], limits)
        return (float(dx), float(dy), float(dyaw))

    @staticmethod
    def of_person(seed: int, iri: str, spread: Spread = Spread()) -> tuple[float, float]:
        """One person's offsets (dx, dy) at ``seed`` in a home of several: drawn, as an object's are, from a
        generator seeded by the seed and the SHA-256 of their IRI."""
        words = np.frombuffer(hashlib.sha256(iri.encode("utf-8")).digest(), dtype="<u4")
        rng = np.random.default_rng([seed, *(int(word) for word in words)])
        dx, dy = rng.uniform(-spread.person, spread.person, 2)
        return (float(dx), float(dy))

    @staticmethod
    def of_object(seed: int, iri: str, round_: bool = False, spread: Spread = Spread()) -> tuple[float, float, float]:
        """One object's offsets (dx, dy, dyaw) at ``seed``: drawn from a generator of its own, seeded by the
        seed and the SHA-256 of its IRI, so that adding or removing another object moves nothing else.
        Drawn in the order of the names, an object added to the map moved every object whose name sorted
        after it (docs/simulation.md, "Determinism"). A round object draws its yaw too, and drops it."""
        words = np.frombuffer(hashlib.sha256(iri.encode("utf-8")).digest(), dtype="<u4")
        rng = np.random.default_rng([seed, *(int(word) for word in words)])
        limits = [spread.object, spread.object, spread.yaw]
        dx, dy, dyaw = rng.uniform([-v for v in limits], limits)
        return (float(dx), float(dy), 0.0 if round_ else float(dyaw))


@dataclass(frozen=True)
class _Part:
    """One box, cylinder or sphere of a multi-part body: shape, size, offset from the body origin, colour."""

    shape: int
    size: tuple[float, ...]
    offset: Vec3
    rgba: tuple[float, float, float, float]
    collide: bool = True
    orientation: Quat = _IDENTITY


def _box(half: Vec3, offset: Vec3, rgba: tuple[float, float, float, float], collide: bool = True) -> _Part:
    return _Part(p.GEOM_BOX, half, offset, rgba, collide)


def _cylinder(
    radius: float, length: float, offset: Vec3, rgba: tuple[float, float, float, float], collide: bool = True
) -> _Part:
    return _Part(p.GEOM_CYLINDER, (radius, length), offset, rgba, collide)


class HomeWorld:
    """The home of paper section 6.2: living room, kitchen with table and dispenser, bedroom.

    Use ``HomeWorld.create(seed)`` and close it (``with HomeWorld.create() as world:``).
    """

    def __init__(
        self,
        client: int,
        seed: int,
        gui: bool,
        time_step: float,
        semantic_map: SemanticMap | None = None,
        spread: Spread = Spread(),
        arm_detail: ArmDetail | str = ArmDetail.REDUCED,
        image_sizes: Mapping[str, tuple[int, int]] | None = None,
        solver_residual: float = SOLVER_RESIDUAL,
    ) -> None:
        self.client = client
        self.seed = seed
        self.gui = gui
        self.time_step = time_step
        self.solver_residual = solver_residual
        self.arm_detail = ArmDetail(arm_detail)
        """The arms' visual meshes, for every camera and recording of this world (``ArmDetail``)."""
        self.map = semantic_map if semantic_map is not None else bundled_map()
        self.colour_windows = _colours(self.map)
        """The colours some camera tells apart, by name (each camera's own: ``Camera.colours``)."""
        _check_colours(self.map, self.colour_windows)
        self.image_sizes = _image_sizes(self.map, image_sizes or {})
        """Each camera's image width and height in pixels (``kb.camera_view.DOWNWARD_IMAGE_SIZE`` and
        ``OTHER_IMAGE_SIZE`` unless ``image_sizes`` named the camera)."""
        self.objects: dict[str, MapObject] = {obj.name: obj for obj in self.map.objects.values()}
        """The movable objects by body name (the local name of their IRI)."""
        self.containers = {name for name, obj in self.objects.items() if obj.iri in self.map.containers}
        check_home(self.map)  # rooms, a base at most, an arm a side at most, starts on a room's floor (kb.home_check)
        self.mobiles: dict[str, MobileRobot] = {robot.name: robot for _, robot in sorted(self.map.robots.items())}
        """The map's mobile robots by body name, in IRI order: one, none or several, each built."""
        self.mobile: MobileRobot | None = next(iter(self.mobiles.values())) if len(self.mobiles) == 1 else None
        """The mobile robot the simulation drives: the map's only one; in a home of several, the one a run's
        plan works (:meth:`drive`), None until then; None in a home with none (docs/simulation.md, "A home
        with no mobile base"). While None, :attr:`robot`, :attr:`base` and what they give are a
        :class:`NoMobileBaseError`."""
        self.base_names: tuple[str, ...] = tuple(self.mobiles)
        """The body names of the mobile bases built."""
        self.people: dict[str, Person] = {person.name: person for _, person in sorted(self.map.people.items())}
        """The map's people by body name (the local name of their IRI), in IRI order: none, one or several."""
        self.spread = spread
        """How far the seed may move things from the map's start poses: the check before a run asks the
        person tracker's camera to see the person wherever it may put them (``sight.person_outline``)."""
        self.perturbation = Perturbation.from_seed(
            seed,
            {name: (obj.iri, obj.shape == "cylinder") for name, obj in self.objects.items()},
            spread,
            [person.iri for person in self.people.values()],
            [robot.iri for robot in self.mobiles.values()],
        )
        self._steps = 0
        self._watchers: list[tuple[int, Callable[[], None]]] = []
        self._closed = False
        self._bodies: dict[str, int] = {}
        self.water: dict[str, float] = dict.fromkeys(self.containers, 0.0)
        """Fraction of each container filled with water (0 to 1)."""
        self.water_spilled = 0.0
        """Seconds the tap ran with no container below it."""
        self._water_shown: set[str] = set()
        self.holders: dict[str, str] = {}
        """Who holds an object after a delivery: object name -> person name."""
        self.cameras: dict[str, Camera] = {}
        self.arms: dict[ArmSide, Arm] = {}
        self.arm_specs: dict[ArmSide, ArmSpec] = {}
        """What the semantic map says of each arm: its mount pose and reach."""
        self._kinematics: Kinematics | None = None
        self._taps: list[tuple[Dispenser, int]] = []
        self._joints: list[tuple[int, list[int]]] = []
        self._base: MobileBase | None = None
        self._bases: dict[str, MobileBase] = {}
        try:
            self._build()
            self._taps = [(d, self._bodies[d.name]) for d in self.dispensers]
            self._joints = self._moving_joints()
            self._bases = {name: MobileBase(client, self._bodies[name], self.step) for name in self.mobiles}
            if self.mobile is not None:
                self._base = self._bases[self.mobile.name]
            for a, b, depth in overlaps(self.map):
                log.warning(
                    "%s and %s overlap by %.1f cm where the semantic map puts them: settling pushes them apart",
                    a.name,
                    b.name,
                    depth * 100,
                )
            built = {name: self.pose(name).position for name in self.objects}
            self.step(0.3)  # let the objects settle on the table
            self.settled = self._settled(built)
        except BaseException:
            if self._kinematics is not None:
                self._kinematics.close()
            raise

    def _settled(self, built: Mapping[str, Vec3]) -> dict[str, tuple[Vec3, Vec3]]:
        """The objects settling moved across by more than ``SETTLE_NOTICE``: name -> (where built, where
        they came to rest), each said in the log."""
        moved = {}
        for name, start in sorted(built.items()):
            rest = self.pose(name).position
            shift = math.hypot(rest[0] - start[0], rest[1] - start[1])
            if shift > SETTLE_NOTICE:
                moved[name] = (start, rest)
                log.warning(
                    "%s was built at (%.3f, %.3f) and settling moved it %.1f cm to (%.3f, %.3f) (seed %d): it was "
                    "built in another object or off balance",
                    name,
                    start[0],
                    start[1],
                    shift * 100,
                    rest[0],
                    rest[1],
                    self.seed,
                )
        return moved

    # --- life cycle -----------------------------------------------------------------------------

    @classmethod
    def create(
        cls,
        seed: int = 0,
        gui: bool = False,
        time_step: float = TIME_STEP,
        semantic_map: SemanticMap | None = None,
        spread: Spread = Spread(),
        arm_detail: ArmDetail | str = ArmDetail.REDUCED,
        image_sizes: Mapping[str, tuple[int, int]] | None = None,
        solver_residual: float = SOLVER_RESIDUAL,
    ) -> HomeWorld:
        """Connect a new pybullet client (DIRECT unless ``gui``) and build the home of ``semantic_map`` in
        it (the bundled map by default). ``arm_detail`` picks the arms' visual meshes (``ArmDetail``:
        reduced, the default, or full); physics is the same with either. ``image_sizes`` gives cameras,
        by name, another image size (width, height) than the layout's default for their kind.
        ``solver_residual`` is when the constraint solver stops iterating (``SOLVER_RESIDUAL``; 1e-7,
        pybullet's own, steps as cbrs did before)."""
        if not (isinstance(solver_residual, int | float) and 0.0 < solver_residual < math.inf):
            raise ValueError(f"solver_residual must be a positive number, not {solver_residual!r}")
        if image_sizes:  # a bad size is refused before a client is connected
            _image_sizes(semantic_map if semantic_map is not None else bundled_map(), image_sizes)
        with quiet_output():
            client = p.connect(p.GUI if gui else p.DIRECT)
        try:
            return cls(client, seed, gui, time_step, semantic_map, spread, arm_detail, image_sizes, solver_residual)
        except BaseException:
            p.disconnect(physicsClientId=client)
            raise

    def close(self) -> None:
        """Disconnect the pybullet client; safe to call twice."""
        if not self._closed:
            self._closed = True
            if self._kinematics is not None:
                self._kinematics.close()
            p.disconnect(physicsClientId=self.client)

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> HomeWorld:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def _check(self) -> None:
        if self._closed:
            raise WorldClosedError(self.client)

    # --- time -----------------------------------------------------------------------------------

    @property
    def time(self) -> float:
        """Simulated seconds since the world was built (settling included)."""
        return self._steps * self.time_step

    @property
    def steps(self) -> int:
        return self._steps

    def step(self, seconds: float) -> None:
        """Advance the physics by ``seconds``, rounded to whole fixed steps (at least one)."""
        self._check()
        count = max(1, round(seconds / self.time_step))
        client = self.client
        # the hot loop of every run (a drive steps once per control tick): names bound once
        step_simulation, joint_state, taps = p.stepSimulation, p.getJointState, self._taps
        for _ in range(count):
            step_simulation(physicsClientId=client)
            self._steps += 1
            for dispenser, body in taps:  # each tap runs while its lever is pushed in (tap_open)
                if joint_state(body, 1, client)[0] > TAP_OPEN_TRAVEL:
                    self._pour(dispenser.outlet)
            if self._watchers:
                for every, callback in list(self._watchers):
                    if self._steps % every == 0:
                        callback()

    def on_steps(self, every: int, callback: Callable[[], None]) -> Callable[[], None]:
        """Call ``callback()`` after every ``every``-th physics step (a recorder's frames); returns the
        call that stops it."""
        entry = (max(1, every), callback)
        self._watchers.append(entry)
        return lambda: self._watchers.remove(entry) if entry in self._watchers else None

    # --- entities -------------------------------------------------------------------------------

    @property
    def bodies(self) -> Mapping[str, int]:
        """Entity name -> pybullet body id."""
        return dict(self._bodies)

    def body(self, name: str) -> int:
        try:
            return self._bodies[name]
        except KeyError:
            raise UnknownEntityError(name, sorted(self._bodies)) from None

    def name_of(self, body: int) -> str | None:
        for name, uid in self._bodies.items():
            if uid == body:
                return name
        return None

    def pose(self, name: str) -> Pose3D:
        """Ground-truth pose of an entity's base (for checks and tests, not for the robots)."""
        self._check()
        pos, orn = p.getBasePositionAndOrientation(self.body(name), physicsClientId=self.client)
        return Pose3D((pos[0], pos[1], pos[2]), (orn[0], orn[1], orn[2], orn[3]))

    @property
    def robot(self) -> MobileRobot:
        """The map's mobile robot (:class:`NoMobileBaseError` in a home with none: :attr:`mobile` is None)."""
        if self.mobile is None:
            raise NoMobileBaseError("the simulation's mobile robot", self._several())
        return self.mobile

    @property
    def base(self) -> MobileBase:
        """The mobile base's drive (:class:`NoMobileBaseError` in a home with none)."""
        if self._base is None:
            raise NoMobileBaseError("the mobile base's drive", self._several())
        return self._base

    def drive(self, name: str) -> None:
        """Make the base ``name`` (a body name) the one the simulation drives: :attr:`mobile`, :attr:`robot`,
        :attr:`base` and what they give are its from now on. In a home of several bases, a run's plan names
        it (``sim.run_checks.base_for``); the others stand where they are."""
        if name not in self._bases:
            raise UnknownEntityError(name, sorted(self._bases))
        self.mobile, self._base = self.mobiles[name], self._bases[name]

    def _several(self) -> tuple[str, ...]:
        return tuple(robot.iri for robot in self.mobiles.values()) if len(self.mobiles) > 1 else ()

    @property
    def grid_inflation(self) -> float:
        """How far the map server's grid grows obstacles: by the driven base's :attr:`base_radius`; in a home of
        several with none driven yet, by the largest's (any of them might drive along it); with none, by nothing."""
        if self.mobile is not None:
            return _radius(self.mobile)
        return max((_radius(robot) for robot in self.mobiles.values()), default=0.0)

    @property
    def base_name(self) -> str:
        """The mobile base's body name (:class:`NoMobileBaseError` in a home with none)."""
        return self.robot.name

    def base_pose(self) -> Pose2D:
        return self.base.pose()

    def arm(self, side: ArmSide | str) -> Arm:
        """The arm on that side; :class:`UnknownEntityError` when the robot has none there (a robot with one
        arm, docs/simulation.md "A robot with one arm")."""
        arm = self.arms.get(ArmSide(side))
        if arm is None:
            raise UnknownEntityError(f"{ArmSide(side).value} arm", [f"{s.value} arm" for s in self.arms])
        return arm

    def camera(self, name: str) -> Camera:
        try:
            return self.cameras[name]
        except KeyError:
            raise UnknownEntityError(name, sorted(self.cameras)) from None

    def fail_camera(self, name: str) -> None:
        """Switch a camera off: its captures raise ``CameraUnavailableError`` until repaired."""
        self.camera(name).failed = True

    def repair_camera(self, name: str) -> None:
        self.camera(name).failed = False

    def scene_key(self) -> Hashable:
        """What a camera's image depends on: the step, every body's pose, the moving joints' angles and
        the water shown. Equal keys, equal images: a camera asked twice with nothing changed between
        (the belief looking, then a goal check) renders once."""
        c = self.client
        poses = tuple(p.getBasePositionAndOrientation(body, physicsClientId=c) for body in self._bodies.values())
        joints = tuple(
            tuple(state[0] for state in p.getJointStates(body, indices, physicsClientId=c))
            for body, indices in self._joints
        )
        return (self._steps, poses, joints, frozenset(self._water_shown))

    def _moving_joints(self) -> list[tuple[int, list[int]]]:
        """Each body with joints that move (the arms, the taps' levers) and those joints."""
        found = []
        for body in self._bodies.values():
            count = p.getNumJoints(body, physicsClientId=self.client)
            kinds = [p.getJointInfo(body, j, physicsClientId=self.client)[2] for j in range(count)]
            moving = [j for j, kind in enumerate(kinds) if kind != p.JOINT_FIXED]
            if moving:
                found.append((body, moving))
        return found

    def snapshot(self) -> dict[str, Pose3D]:
        """Poses of everything that can move (objects, base, people), for comparing runs."""
        return {name: self.pose(name) for name in (*sorted(self.objects), *self.base_names, *self.people)}

    @property
    def person(self) -> Person:
        """The map's only person, for a caller that names none (a :class:`kb.person_choice.PersonError` when the
        map has none or several: which one a step means is the task's to say, ``person_for``)."""
        return person_for(self.map, "the simulation's default person")

    @property
    def person_name(self) -> str:
        """The body name of :attr:`person`."""
        return self.person.name

    def aabb(self, name: str) -> tuple[Vec3, Vec3]:
        """The axis-aligned bounds of a body (all its links), low and high corners."""
        self._check()
        low, high = p.getAABB(self.body(name), physicsClientId=self.client)
        for link in range(p.getNumJoints(self.body(name), physicsClientId=self.client)):
            l_low, l_high = p.getAABB(self.body(name), link, physicsClientId=self.client)
            low = tuple(min(a, b) for a, b in zip(low, l_low, strict=True))
            high = tuple(max(a, b) for a, b in zip(high, l_high, strict=True))
        return (float(low[0]), float(low[1]), float(low[2])), (float(high[0]), float(high[1]), float(high[2]))

    def place(self, name: str, x: float, y: float, yaw: float | None = None) -> None:
        """Put a body somewhere else on the floor or on what it stands on (the world changing by itself:
        the person walks away, someone moves the cup), at rest."""
        self._check()
        body = self.body(name)
        (_, _, z), orientation = p.getBasePositionAndOrientation(body, physicsClientId=self.client)
        turned = quat_from_yaw(yaw) if yaw is not None else orientation
        p.resetBasePositionAndOrientation(body, (x, y, z), turned, physicsClientId=self.client)
        p.resetBaseVelocity(body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=self.client)

    @property
    def water_rgba(self) -> tuple[float, float, float, float]:
        """How water is shown: the display colour of the semantic map's water (cyan when it says none)."""
        look = self.map.appearance(HOME + "Water")
        return look[1] if look is not None else WATER_CYAN

    def water_level(self, name: str) -> float:
        """Fraction of a container filled with water; 0 for anything that is not a container."""
        return self.water.get(name, 0.0)

    @property
    def dispensers(self) -> list[Dispenser]:
        """The semantic map's appliances with a tap, in IRI order."""
        return [self.map.dispensers[iri] for iri in sorted(self.map.dispensers)]

    def tap_travel(self, dispenser: str | None = None) -> float:
        """How far a dispenser's tap lever is pushed in (m); with no name, the most of any dispenser."""
        chosen = [d for d in self.dispensers if dispenser is None or d.name == dispenser]
        if dispenser is not None and not chosen:
            raise UnknownEntityError(dispenser, [d.name for d in self.dispensers])
        travels = [float(p.getJointState(self.body(d.name), 1, physicsClientId=self.client)[0]) for d in chosen]
        return max(travels, default=0.0)

    def tap_open(self, dispenser: str | None = None) -> bool:
        return self.tap_travel(dispenser) > TAP_OPEN_TRAVEL

    def catches_water(self, name: str, outlet: Vec3 | None = None) -> bool:
        """Physics of the stream: it falls from the outlet (the first dispenser's by default) into a
        container if the container is upright below it and the outlet's axis passes inside the rim."""
        if outlet is None:
            if not self.dispensers:
                return False
            outlet = self.dispensers[0].outlet
        obj = self.objects[name]
        pos, orn = p.getBasePositionAndOrientation(self.body(name), physicsClientId=self.client)
        up = p.getMatrixFromQuaternion(orn)[8]
        rim = min(obj.size[0], obj.size[1]) / 2.0
        inside = math.hypot(pos[0] - outlet[0], pos[1] - outlet[1]) < rim - 0.004
        below = pos[2] + obj.size[2] / 2.0 < outlet[2]
        return inside and below and up > 0.95

    def _pour(self, outlet: Vec3) -> None:
        catching = next((name for name in sorted(self.containers) if self.catches_water(name, outlet)), None)
        if catching is None:
            self.water_spilled += self.time_step
            return
        self.water[catching] = min(1.0, self.water[catching] + FILL_RATE * self.time_step)
        if catching not in self._water_shown and self.water[catching] >= 0.2:
            p.changeVisualShape(self.body(catching), 0, rgbaColor=self.water_rgba, physicsClientId=self.client)
            self._water_shown.add(catching)

    def give_to(self, name: str, person: str, hand: Vec3) -> None:
        """The person takes the object into their hand: it leaves the platform and stays with them."""
        thing = self.body(name)
        holder = self.body(person)
        p.resetBasePositionAndOrientation(thing, hand, quat_from_yaw(0.0), physicsClientId=self.client)
        p.resetBaseVelocity(thing, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=self.client)
        holder_pos, holder_orn = p.getBasePositionAndOrientation(holder, physicsClientId=self.client)
        inv_pos, inv_orn = p.invertTransform(holder_pos, holder_orn)
        rel_pos, rel_orn = p.multiplyTransforms(inv_pos, inv_orn, hand, quat_from_yaw(0.0))
        p.createConstraint(
            holder,
            -1,
            thing,
            -1,
            p.JOINT_FIXED,
            (0.0, 0.0, 0.0),
            rel_pos,
            (0.0, 0.0, 0.0),
            parentFrameOrientation=rel_orn,
            physicsClientId=self.client,
        )
        self.holders[name] = person

    # --- building -------------------------------------------------------------------------------

    def _multibody(
        self,
        name: str,
        parts: list[_Part],
        position: Vec3,
        orientation: Quat = _IDENTITY,
        mass: float = 0.0,
        joints: list[tuple[int, Vec3]] | None = None,
        link_mass: float = 0.001,
    ) -> int:
        """A body whose first part is the base and the others fixed (or given) joints' links."""
        c = self.client

        def shapes(part: _Part) -> tuple[int, int]:
            if part.shape == p.GEOM_BOX:
                col = p.createCollisionShape(p.GEOM_BOX, halfExtents=part.size, physicsClientId=c)
                vis = p.createVisualShape(p.GEOM_BOX, halfExtents=part.size, rgbaColor=part.rgba, physicsClientId=c)
            elif part.shape == p.GEOM_CYLINDER:
                radius, length = part.size
                col = p.createCollisionShape(p.GEOM_CYLINDER, radius=radius, height=length, physicsClientId=c)
                vis = p.createVisualShape(
                    p.GEOM_CYLINDER, radius=radius, length=length, rgbaColor=part.rgba, physicsClientId=c
                )
            else:
                col = p.createCollisionShape(p.GEOM_SPHERE, radius=part.size[0], physicsClientId=c)
                vis = p.createVisualShape(p.GEOM_SPHERE, radius=part.size[0], rgbaColor=part.rgba, physicsClientId=c)
            return (col if part.collide else -1), vis

        base_col, base_vis = shapes(parts[0])
        links = parts[1:]
        link_shapes = [shapes(part) for part in links]
        kinds = joints or [(p.JOINT_FIXED, (0.0, 0.0, 1.0))] * len(links)
        body = p.createMultiBody(
            baseMass=mass,
            baseCollisionShapeIndex=base_col,
            baseVisualShapeIndex=base_vis,
            basePosition=position,
            baseOrientation=orientation,
            baseInertialFramePosition=parts[0].offset,
            linkMasses=[link_mass] * len(links),
            linkCollisionShapeIndices=[s[0] for s in link_shapes],
            linkVisualShapeIndices=[s[1] for s in link_shapes],
            linkPositions=[part.offset for part in links],
            linkOrientations=[part.orientation for part in links],
            linkInertialFramePositions=[(0.0, 0.0, 0.0)] * len(links),
            linkInertialFrameOrientations=[_IDENTITY] * len(links),
            linkParentIndices=[0] * len(links),
            linkJointTypes=[k[0] for k in kinds],
            linkJointAxis=[k[1] for k in kinds],
            physicsClientId=c,
        )
        if parts[0].offset != (0.0, 0.0, 0.0):
            raise ValueError("the base part of a body must sit at its origin")
        if mass == 0.0 and joints is None:
            # A fixed body's fixed links are as static as its base, but pybullet files them as dynamic
            # (they have a mass): the table's legs stood on the floor as 16 contact points solved at
            # every step that could move nothing. Filed as static, they meet only what moves.
            for link in range(len(links)):
                p.setCollisionFilterGroupMask(body, link, _STATIC_GROUP, _NOT_STATIC, physicsClientId=c)
        self._bodies[name] = int(body)
        return int(body)

    def _build(self) -> None:
        c = self.client
        p.resetSimulation(physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=self.time_step,
            deterministicOverlappingPairs=1,
            solverResidualThreshold=self.solver_residual,
            physicsClientId=c,
        )
        p.setGravity(0.0, 0.0, -GRAVITY, physicsClientId=c)
        p.setAdditionalSearchPath(PYBULLET_DATA, physicsClientId=c)
        if self.gui:
            p.configureDebugVisualizer(p.COV_ENABLE_GUI, 0, physicsClientId=c)
            home = self.map.extent()  # the window looks at the whole home, whatever its size (was the bundled one's)
            middle = ((home.min_x + home.max_x) / 2, (home.min_y + home.max_y) / 2, 0.0)
            span = max(home.max_x - home.min_x, home.max_y - home.min_y)
            p.resetDebugVisualizerCamera(0.9 * span, 0.0, -60.0, middle, physicsClientId=c)
        render = p.COV_ENABLE_RENDERING
        if self.gui:
            p.configureDebugVisualizer(render, 0, physicsClientId=c)
        self._build_rooms()
        self._build_kitchen()
        self._build_robot()
        for robot in self.mobiles.values():  # none, one, or each of several
            self._build_base(robot)
        for person in self.people.values():
            self._build_person(person)
        self._draw_floor_last()
        for iri in sorted(self.map.cameras):
            cam = self.map.cameras[iri]
            direction = cam.direction
            target = tuple(e + d for e, d in zip(cam.position, direction, strict=True))
            up = image_up(cam)  # looking straight down, the top of the image faces the camera's yaw
            width, height = self.image_sizes[cam.name]
            spec = CameraSpec(
                cam.name,
                cam.position,
                (target[0], target[1], target[2]),
                up,
                width,
                height,
                fov_deg=cam.fov,
                near=cam.near,
                far=cam.far,
                max_hidden=cam.occlusion_tolerance,
            )
            colours = {window.name: window for window in cam.colours}
            self.cameras[spec.name] = Camera(c, spec, self, self.scene_key, colours)
        if self.gui:
            p.configureDebugVisualizer(render, 1, physicsClientId=c)

    def _build_rooms(self) -> None:
        h = self.extent
        self._multibody(
            "Floor",
            [_box(((h.xmax - h.xmin) / 2 + 0.5, (h.ymax - h.ymin) / 2 + 0.5, 0.05), (0, 0, 0), _FLOOR)],
            ((h.xmin + h.xmax) / 2, (h.ymin + h.ymax) / 2, -0.05),
        )
        for iri in sorted(self.map.walls):
            wall = self.map.things.get(iri)
            if wall is not None:
                self._solid(wall.name, wall.box, _WALL)

    def _draw_floor_last(self) -> None:
        """Draw the floor after everything that stands on it. The TINY renderer draws bodies in the
        order they were made and shades every pixel that passes the depth test so far: drawn first,
        the floor was shaded wherever the table, the robots and the walls then covered it (a quarter
        of a Kinect frame's time). A body with the floor's look and no collision shape, made last,
        draws it; the floor body keeps its collision shape and its colour, made invisible, so that
        physics and everything that reads the floor's colour are as they were."""
        c = self.client
        floor = self._bodies["Floor"]
        (_, _, _, size, _, _, _, rgba, *_), *_ = p.getVisualShapeData(floor, physicsClientId=c)
        position, orientation = p.getBasePositionAndOrientation(floor, physicsClientId=c)
        half = (size[0] / 2, size[1] / 2, size[2] / 2)
        look = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=c)
        p.createMultiBody(0.0, -1, look, position, orientation, physicsClientId=c)
        p.changeVisualShape(floor, -1, rgbaColor=(rgba[0], rgba[1], rgba[2], 0.0), physicsClientId=c)

    @property
    def extent(self) -> Region:
        """The home's floor: the box around its rooms."""
        box = self.map.extent()
        return Region("Home", box.min_x, box.max_x, box.min_y, box.max_y)

    def _solid(self, name: str, box: Box, rgba: tuple[float, float, float, float]) -> int:
        """A fixed box body filling ``box``."""
        half, centre = _half_and_centre(_region(name, box))
        return self._multibody(name, [_box(half, (0, 0, 0), rgba)], centre)

    @property
    def furniture(self) -> list[str]:
        """The body names of the semantic map's furniture (its tables), in the map's order."""
        return sorted(self.map.things[iri].name for iri in self.map.furniture if iri in self.map.things)

    def _build_furniture(self) -> None:
        """Each piece of furniture of the map as a table: a 4 cm top at its height on four legs."""
        top = 0.04
        for iri in sorted(self.map.furniture):
            thing = self.map.things.get(iri)
            if thing is None:
                continue
            box = thing.box
            cx, cy = (box.min_x + box.max_x) / 2, (box.min_y + box.max_y) / 2
            hx, hy = (box.max_x - box.min_x) / 2, (box.max_y - box.min_y) / 2
            leg_h = (box.max_z - top) / 2
            legs = [
                _box((0.025, 0.025, leg_h), (sx * (hx - 0.06), sy * (hy - 0.06), -top / 2 - leg_h), _WOOD)
                for sx in (-1, 1)
                for sy in (-1, 1)
            ]
            self._multibody(
                thing.name, [_box((hx, hy, top / 2), (0, 0, 0), _WOOD), *legs], (cx, cy, box.max_z - top / 2)
            )

    def _build_kitchen(self) -> None:
        self._build_furniture()
        for dispenser in self.dispensers:
            self._build_dispenser(dispenser)
        for obj in self.objects.values():
            self._build_object(obj)

    def _build_dispenser(self, dispenser: Dispenser) -> None:
        """The appliance's body with its spout and its tap's lever, which slides towards the body
        (pushed in, it opens the tap; a spring pushes it back)."""
        body = _region(dispenser.name, dispenser.body.box)
        body_half, centre = _half_and_centre(body)

        def local(thing: Thing) -> tuple[Vec3, Vec3]:
            half, mid = _half_and_centre(_region(thing.name, thing.box))
            return half, (mid[0] - centre[0], mid[1] - centre[1], mid[2] - centre[2])

        spout_half, spout_off = local(dispenser.spout)
        lever_half, lever_off = local(dispenser.lever)
        norm = math.hypot(lever_off[0], lever_off[1]) or 1.0
        push = (-lever_off[0] / norm, -lever_off[1] / norm, 0.0)
        uid = self._multibody(
            dispenser.name,
            [
                _box(body_half, (0, 0, 0), _WHITE),
                _box(spout_half, spout_off, _STEEL),
                _box(lever_half, lever_off, _DARK),
            ],
            centre,
            joints=[(p.JOINT_FIXED, (0.0, 0.0, 1.0)), (p.JOINT_PRISMATIC, push)],
            link_mass=0.05,
        )
        p.setJointMotorControl2(
            uid, 1, p.POSITION_CONTROL, targetPosition=0.0, force=LEVER_SPRING_FORCE, physicsClientId=self.client
        )

    def _build_object(self, obj: MapObject) -> None:
        """An object of the semantic map at its start pose (moved by the seed), resting on its support."""
        support = self.map.things.get(obj.support) if obj.support else None
        surface = support.box.max_z if support is not None else 0.0
        dx, dy, dyaw = self.perturbation.objects.get(obj.name, (0.0, 0.0, 0.0))
        length, width, height = obj.size
        x, y = obj.start.x + dx, obj.start.y + dy
        if support is not None:  # moved by the seed, it stays on what it stands on; where the map puts it, it is
            edge = max(length, width) / 2.0
            box = support.box
            x = min(max(x, min(box.min_x + edge, obj.start.x)), max(box.max_x - edge, obj.start.x))
            y = min(max(y, min(box.min_y + edge, obj.start.y)), max(box.max_y - edge, obj.start.y))
        if obj.shape == "cylinder":
            radius = min(length, width) / 2.0
            parts = [_cylinder(radius, height, (0, 0, 0), obj.rgba)]
            if obj.name in self.containers:  # the water's surface: invisible against the cup until it fills
                parts.append(_cylinder(radius - 0.004, 0.002, (0, 0, height / 2 + 0.0005), obj.rgba, collide=False))
        else:
            parts = [_box((length / 2, width / 2, height / 2), (0, 0, 0), obj.rgba)]
        body = self._multibody(
            obj.name,
            parts,
            (x, y, surface + height / 2 + 0.001),
            quat_from_yaw(obj.start.yaw + dyaw),
            mass=obj.mass,
        )
        p.changeDynamics(body, -1, lateralFriction=1.0, spinningFriction=0.001, physicsClientId=self.client)

    def _build_robot(self) -> None:
        obstacles: list[Region] = []
        for iri in sorted(self.map.bodies):  # a robot's own extent: the dual-arm robot's torso
            body = self.map.things.get(iri)
            if body is not None:
                self._solid(body.name, body.box, _TORSO)
                obstacles.append(_region(body.name, body.box))
        obstacles += self._build_camera_housings()
        # the arms the map has, one a side (kb.home_check), built left first as they always were
        by_side = {ArmSide(arm.side): arm for arm in self.map.arms.values()}
        arms = {side: by_side[side] for side in ArmSide if side in by_side}
        self.arm_specs = arms
        mounts = {side: (spec.mount, quat_from_yaw(spec.yaw)) for side, spec in arms.items()}
        tops = [
            Region(thing.name, b.min_x, b.max_x, b.min_y, b.max_y, b.max_z - 0.04, b.max_z)
            for iri in sorted(self.map.furniture)
            if (thing := self.map.things.get(iri)) is not None and (b := thing.box) is not None
        ]
        # the spout too: it sticks out over the worktop, where a hand coming down on an object below it
        # would meet it (the lever, which a hand pushes, is not one)
        appliances = [_region(t.name, t.box) for d in self.dispensers for t in (d.body, d.spout)]
        # what a carry keeps clear of, the levers too: a hand means to push a lever to fill a cup, never
        # to carry a thing into it (Arm.dry_run's clear_by)
        levers = [_region(d.lever.name, d.lever.box) for d in self.dispensers]
        self._kinematics = Kinematics(mounts, [*obstacles, *tops, *appliances], [*appliances, *levers])
        for side, (mount, orientation) in mounts.items():
            body = p.loadURDF(
                panda_urdf(self.arm_detail),
                mount,
                orientation,
                useFixedBase=True,
                flags=p.URDF_ENABLE_CACHED_GRAPHICS_SHAPES,
                physicsClientId=self.client,
            )
            self._bodies[f"{side.value.capitalize()}Arm"] = body
            for link in (9, 10):
                p.changeDynamics(body, link, lateralFriction=1.5, physicsClientId=self.client)
            hand = self.map.hands.get(arms[side].iri, PANDA_HAND)  # the store's, by kb.hands
            self.arms[side] = Arm(self.client, side, body, self._kinematics, self.step, hand)
        for arm in self.arms.values():
            arm.peers = self.arms

    def _build_camera_housings(self) -> list[Region]:
        """The housing of each camera the map gives a size, on a mast down to the top of what it is
        mounted on; returns their extents (obstacles for the arms)."""
        extents = []
        for iri in sorted(self.map.cameras):
            cam = self.map.cameras[iri]
            if cam.size is None:
                continue
            x, y, z = cam.position
            sx, sy, sz = cam.size
            housing = Region(cam.name, x - sx / 2, x + sx / 2, y - sy / 2, y + sy / 2, z - sz / 2, z + sz / 2)
            parts = [_box(_half_and_centre(housing)[0], (0, 0, 0), _DARK)]
            extents.append(housing)
            mount = self.map.things.get(cam.mount or "")
            if mount is not None and mount.box.max_z < housing.zmin:
                mast = Region(
                    cam.name + "Mast", x - 0.015, x + 0.015, y - 0.015, y + 0.015, mount.box.max_z, housing.zmin
                )
                half, mid = _half_and_centre(mast)
                parts.append(_box(half, (mid[0] - x, mid[1] - y, mid[2] - z), _STEEL))
                extents.append(mast)
            self._multibody(cam.name, parts, (x, y, z))
        return extents

    @property
    def platform_height(self) -> float:
        """Height of the mobile robot's platform top, where things are put (from the semantic map)."""
        if self.robot.platform_height is None:
            raise ValueError(f"the semantic map gives {self.robot.name} no platform (home:hasPlatform with home:maxZ)")
        return self.robot.platform_height

    @property
    def marker_model(self) -> MarkerModel:
        """The base's colour marker as perception knows it: colours, patch size, spacing and height."""
        return marker_model(self.robot)

    @property
    def base_radius(self) -> float:
        """The base's footprint's circumscribed radius, rounded up to 5 cm: the map's obstacle inflation."""
        return _radius(self.robot)

    def _build_base(self, robot: MobileRobot) -> None:
        bx, by, btheta = self.perturbation.bases[robot.iri]
        start = robot.start
        marker = marker_model(robot)
        half_length, half_width = robot.footprint[0] / 2, robot.footprint[1] / 2
        bottom = 0.02
        if robot.platform_height is None:  # marker_model said so already
            raise ValueError(f"the semantic map gives {robot.name} no platform (home:hasPlatform with home:maxZ)")
        height = robot.platform_height
        chassis_half = (half_length, half_width, (height - 0.02 - bottom) / 2)
        chassis_centre_z = bottom + chassis_half[2]
        platform_z = height - 0.01 - chassis_centre_z
        marker_z = marker.height - 0.001 - chassis_centre_z
        wheel = (math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))  # cylinder axis along y
        patch = (marker.patch[0] / 2, marker.patch[1] / 2, 0.001)
        offset = marker.separation / 2
        wheel_radius = min(0.095, chassis_centre_z)
        parts = [
            _box(chassis_half, (0, 0, 0), _CHASSIS),
            _box((half_length, half_width, 0.01), (0, 0, platform_z), _PLATFORM),
            _box(patch, (offset, 0, marker_z), _painted(marker.front, self.colour_windows), collide=False),
            _box(patch, (-offset, 0, marker_z), _painted(marker.rear, self.colour_windows), collide=False),
            *(
                _Part(
                    p.GEOM_CYLINDER,
                    (wheel_radius, 0.04),
                    (0.0, side * (half_width + 0.025), wheel_radius - chassis_centre_z),
                    _DARK,
                    False,
                    wheel,
                )
                for side in (1.0, -1.0)
            ),
        ]
        body = self._multibody(
            robot.name,
            parts,
            (start.x + bx, start.y + by, chassis_centre_z),
            quat_from_yaw(start.yaw + btheta),
            mass=20.0,
        )
        p.changeDynamics(body, 0, lateralFriction=1.0, physicsClientId=self.client)

    def _build_person(self, person: Person) -> None:
        dx, dy = self.perturbation.people[person.iri]
        legs = L.SHIRT_BOTTOM
        self._multibody(
            person.name,
            [
                _cylinder(L.PERSON_RADIUS, legs, (0, 0, 0), _TROUSERS),
                _cylinder(
                    L.SHIRT_RADIUS,
                    L.SHIRT_TOP - L.SHIRT_BOTTOM,
                    (0, 0, (L.SHIRT_TOP + legs) / 2 - legs / 2),
                    person.rgba,
                ),
                _Part(p.GEOM_SPHERE, (0.10,), (0.0, 0.0, L.SHIRT_TOP + 0.11 - legs / 2), _SKIN),
            ],
            (person.start.x + dx, person.start.y + dy, legs / 2),
        )


def _check_colours(semantic_map: SemanticMap, known: dict[str, ColourWindow]) -> None:
    """Every colour name of the map's objects, people, markers and water is one some camera tells apart
    (``known``, the cameras' colour windows): one none can was found only as the task looked for the
    thing, after the base had driven off. A ``MapError`` names the thing, the property and the value."""
    named: list[tuple[str, str, str]] = [(obj.iri, "colourName", obj.colour) for obj in semantic_map.objects.values()]
    named += [(person.iri, "colourName", person.colour) for person in semantic_map.people.values()]
    for iri, values in semantic_map.facts.items():
        if HOME + "hueCentre" in values:
            continue  # a colour window of the map's, which no camera need have
        for name in ("colourName", "frontColourName", "rearColourName"):
            named += [(iri, name, colour) for colour in values.get(HOME + name, [])]
    for iri, name, colour in sorted(set(named)):
        if colour and colour not in known:  # none at all: the thing is not looked for
            near = difflib.get_close_matches(colour.lower(), list(known), n=1, cutoff=0.6)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise MapError(
                iri,
                f"has home:{name} {colour!r}, a colour perception cannot find{hint}; known: {', '.join(known)} "
                "(the colour windows of the map's cameras, docs/simulation.md)",
            )


def marker_model(robot: MobileRobot) -> MarkerModel:
    """A mobile robot's colour marker as perception knows it from the semantic map: colours, one patch's
    size, the patches' spacing, and the height of their top faces (lying on the platform)."""
    marker = robot.marker
    if marker is None or robot.platform_height is None:
        raise ValueError(
            f"the semantic map gives {robot.name} no marker on a platform (home:hasPlatform with home:maxZ; "
            "home:hasMarker, with home:sizeX, home:sizeY, home:markerSeparation and a node of "
            "home:frontColourName and home:rearColourName): the ceiling cameras could not find it"
        )
    return MarkerModel(marker.front, marker.rear, marker.patch, marker.separation, robot.platform_height + MARKER_LIFT)


def _radius(robot: MobileRobot) -> float:
    """A base's footprint's circumscribed radius, rounded up to 5 cm: the map's obstacle inflation."""
    length, width = robot.footprint
    return math.ceil(math.hypot(length / 2, width / 2) / 0.05 - 1e-9) * 0.05


def _region(name: str, box: Box) -> Region:
    return Region(name, box.min_x, box.max_x, box.min_y, box.max_y, box.min_z, box.max_z)


def _half_and_centre(region: Region) -> tuple[Vec3, Vec3]:
    half = ((region.xmax - region.xmin) / 2, (region.ymax - region.ymin) / 2, (region.zmax - region.zmin) / 2)
    centre = ((region.xmin + region.xmax) / 2, (region.ymin + region.ymax) / 2, (region.zmin + region.zmax) / 2)
    return half, centre


def _image_sizes(semantic_map: SemanticMap, given: Mapping[str, tuple[int, int]]) -> dict[str, tuple[int, int]]:
    """Every camera's image size: ``given`` for the cameras it names, else the layout's default for a
    camera looking straight down or for any other."""
    cameras = {cam.name: cam for cam in semantic_map.cameras.values()}
    for name, size in given.items():
        if name not in cameras:
            raise UnknownEntityError(name, sorted(cameras))
        if (
            not isinstance(size, tuple | list)
            or len(size) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in size)
        ):
            raise ImageSizeError(name, size)
    sizes = {}
    for name, cam in cameras.items():
        width, height = given.get(name, default_image_size(cam))
        sizes[name] = (int(width), int(height))
    return sizes


@contextmanager
def open_world(
    seed: int = 0,
    gui: bool = False,
    semantic_map: SemanticMap | None = None,
    spread: Spread = Spread(),
    arm_detail: ArmDetail | str = ArmDetail.REDUCED,
    image_sizes: Mapping[str, tuple[int, int]] | None = None,
    solver_residual: float = SOLVER_RESIDUAL,
) -> Iterator[HomeWorld]:
    """``with open_world(seed) as world:`` builds a world and always disconnects it."""
    world = HomeWorld.create(
        seed,
        gui,
        semantic_map=semantic_map,
        spread=spread,
        arm_detail=arm_detail,
        image_sizes=image_sizes,
        solver_residual=solver_residual,
    )
    try:
        yield world
    finally:
        world.close()
