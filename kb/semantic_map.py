"""The semantic map: the home's rooms, furniture, regions, objects, people and robot parts, as typed values.

The map lives in the store (``ontologies/world.ttl`` seeds the ``map`` graph; a user's Turtle may add
to it), KnowRob style; this module reads it with the named queries ``map_facts``, ``map_types`` and
``grasp_affordances`` into plain frozen dataclasses, so that the simulation can build its scene from
it and the executor can resolve a task's inputs against it (:func:`designate`). Nothing here knows a
particular cup or table: every value comes from the store.
"""

from __future__ import annotations

import math
from collections import defaultdict
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from enum import Enum
from typing import TYPE_CHECKING, overload

from pyoxigraph import Literal, NamedNode

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.shapes import nearest_term
from cbrs.kb.stated_quantities import StatedQuantities
from cbrs.kb.turned_fit import fits_at, fits_some_turn, fits_unturned, fitting_turns

if TYPE_CHECKING:
    from collections.abc import Callable, Collection, Sequence

    from cbrs.kb.colour_windows import ColourWindow
    from cbrs.kb.hands import Hand
    from cbrs.kb.knowledge_base import KnowledgeBase
    from cbrs.kb.store import Term

HOME = PREFIXES["home"]

__all__ = [
    "OVERLAP_TOLERANCE",
    "AmbiguousDesignatorError",
    "Arm",
    "Box",
    "Camera",
    "Dispenser",
    "MapError",
    "MapObject",
    "Marker",
    "MobileRobot",
    "NoExtentError",
    "NotGraspableError",
    "Person",
    "Pose",
    "Reading",
    "SemanticMap",
    "UnresolvedDesignatorError",
    "designate",
    "designate_each",
    "local_name",
    "overlaps",
]


_DECLARED: ContextVar[frozenset[str]] = ContextVar("declared_home_properties", default=frozenset())
"""The home properties the vocabulary declares, while :meth:`SemanticMap.read` reads a map."""


class MapError(KnowledgeBaseError):
    """The semantic map lacks or contradicts what is needed; names the thing and the property."""

    http_status = 422

    def __init__(self, thing: str, problem: str) -> None:
        self.thing = thing
        super().__init__(f"semantic map: {local_name(thing)} ({thing}) {problem}")


class NotGraspableError(MapError):
    """An object a task has an arm handle has no grasp knowledge: no class above it states how to grasp it.
    An object nothing handles may lack it (a bowl on a shelf): the map is read, and only a task that
    would take it is refused."""

    def __init__(self, thing: str, types: tuple[str, ...]) -> None:
        kinds = ", ".join(local_name(t) for t in types) or "thing of no class"
        super().__init__(
            thing,
            f"is a {kinds} and no class above it says how to grasp it: give one home:graspApproach and "
            "home:graspHeightRatio",
        )


class NoExtentError(MapError):
    """A piece of furniture or a place objects are kept (``home:Furniture``, ``home:ObjectPlace`` by the
    taxonomy) with no extent: the simulation builds such a thing as a box, stands things on its top and
    finds spots on it, so without ``home:minX`` .. ``home:maxZ`` no task can use it. Refused when the map is
    read (a load into graph:map, an update of it, ``cbrs home``, a run), naming what it lacks (``missing``);
    before, it was left out of the map's things but kept among its furniture, and a task about it failed
    mid-run. A region or a wall with none is refused alike, and so is a thing whose extent lacks a height the
    simulation reads (``why``): a table whose ``home:maxZ`` an update deleted stood its top at 0 m."""

    def __init__(
        self, thing: str, types: tuple[str, ...], missing: tuple[str, ...], hint: str = "", why: str = ""
    ) -> None:
        self.missing = missing
        kinds = ", ".join(local_name(t) for t in types) or "thing of no class"
        if why:
            super().__init__(
                thing,
                f"is a {kinds} whose extent lacks {', '.join(missing)}{hint}: {why}; give it "
                f"{', '.join(missing)} (the kitchen table's are in ontologies/world.ttl), or take it out of graph:map",
            )
            return
        super().__init__(
            thing,
            f"is a {kinds} with no extent ({', '.join(missing)} missing){hint}: the simulation builds furniture "
            "and the places objects are kept as boxes and stands things on their top (home:maxZ), so it cannot "
            "use this one; give it home:minX, home:maxX, home:minY, home:maxY and home:maxZ (home:minZ too for a "
            "top that is a slab; the kitchen table's are in ontologies/world.ttl), or take it out of graph:map",
        )


class UnresolvedDesignatorError(KnowledgeBaseError):
    """No thing of the world is of the class a task's input names."""

    http_status = 422

    def __init__(self, concept: str) -> None:
        self.concept = concept
        super().__init__(
            f"nothing in the world is a {local_name(concept)} ({concept}): add an individual of that class to the "
            "semantic map (see docs/tasks.md)"
        )


class AmbiguousDesignatorError(KnowledgeBaseError):
    """Several things of the world are of the class a task's input names, and nothing tells them apart.
    ``stated``: each of ``candidates`` is stated to be of that very class (True), none is (False), not
    asked (None: :attr:`Reading.ANY`)."""

    http_status = 422

    def __init__(
        self, concept: str, candidates: list[str], stated: bool | None = None, note: str = "", task: str = ""
    ) -> None:
        self.concept = concept
        self.candidates = candidates
        self.stated = stated
        self.note = note
        self.task = task
        names = ", ".join(local_name(c) for c in candidates)
        kind = local_name(concept)
        own_class = _own_namespace(task, concept, candidates[0]) + f"My{kind}"
        example = (
            f"{_turtle(candidates[0])} a {_turtle(own_class)} . {_turtle(own_class)} rdfs:subClassOf {_turtle(concept)}"
        )
        own = f"a class of its own in the map ({example})"
        task = "the task (its input's cbrs:parameterType and its goals)"
        if stated:
            advice = (
                f"are each stated to be a {kind}; give the one the task means {own} and name that class in {task}: "
                f"a thing stated to be of a narrower class is named by that class, not by {shorten(concept)}"
            )
        elif stated is None:
            advice = f"are all {kind}s; give the one the task means {own} and name that class in {task}"
        else:
            advice = (
                f"are all {kind}s, none stated to be a {kind} and of no narrower class; name in {task} the "
                f"narrower class of the one it means, or give the one the task means {own} and name that"
            )
        said = f"; {note}" if note else ""
        super().__init__(f"{kind} is ambiguous: {names} {advice}{said} (docs/tasks.md, Write a task)")

    def noting(self, note: str, task: str = "") -> AmbiguousDesignatorError:
        """The same refusal saying ``note`` too (what the task says of the class that does not tell them
        apart), its example class in the namespace of ``task`` (the requirement's IRI) where that is a lab's."""
        return AmbiguousDesignatorError(self.concept, self.candidates, self.stated, note, task or self.task)


def _namespace(iri: str) -> str:
    cut = max(iri.rfind("#"), iri.rfind("/"))
    return iri[: cut + 1]


def _own_namespace(task: str, concept: str, candidate: str) -> str:
    """Where the example class of :class:`AmbiguousDesignatorError` is named: the first of the task's, the
    class's and the thing's namespaces that is a lab's own (no bundled prefix's), else the thing's."""
    bundled = set(PREFIXES.values())
    for iri in (task, concept, candidate):
        if iri and _namespace(iri) and _namespace(iri) not in bundled:
            return _namespace(iri)
    return _namespace(candidate)


def _turtle(iri: str) -> str:
    """``iri`` as any Turtle file may write it: by a bundled prefix, which the lab's files declare as the
    docs do (home:Cup, world:Cup1), else whole (``<https://example.org/lab11#MyFlask>``): a store's derived
    prefix (lab11:) is not one the lab's file is known to declare, and pasted undeclared fails to parse."""
    for prefix, namespace in sorted(PREFIXES.items(), key=lambda item: -len(item[1])):
        local = iri[len(namespace) :]
        if iri.startswith(namespace) and local and all(ch.isalnum() or ch in "_-" for ch in local):
            return f"{prefix}:{local}"
    return f"<{iri}>"


def local_name(iri: str) -> str:
    return iri.rsplit("#", 1)[-1].rsplit("/", 1)[-1]


@dataclass(frozen=True)
class Pose:
    x: float
    y: float
    yaw: float = 0.0


@dataclass(frozen=True)
class Box:
    """An axis-aligned extent; ``min_z``/``max_z`` default to the floor for rooms."""

    min_x: float
    max_x: float
    min_y: float
    max_y: float
    min_z: float = 0.0
    max_z: float = 0.0

    @property
    def centre(self) -> tuple[float, float, float]:
        return ((self.min_x + self.max_x) / 2, (self.min_y + self.max_y) / 2, (self.min_z + self.max_z) / 2)

    def contains_xy(self, x: float, y: float, margin: float = 0.0) -> bool:
        return self.min_x - margin <= x <= self.max_x + margin and self.min_y - margin <= y <= self.max_y + margin


@dataclass(frozen=True)
class Thing:
    """Anything in the map that has an extent: a room, a piece of furniture, a region, a tap lever."""

    iri: str
    types: tuple[str, ...]
    box: Box
    dock: Pose | None = None

    @property
    def name(self) -> str:
        return local_name(self.iri)


@dataclass(frozen=True)
class MapObject:
    """A movable object: its shape and size, mass, colour, start pose and how it is grasped."""

    iri: str
    types: tuple[str, ...]
    shape: str  # "box" or "cylinder"
    size: tuple[float, float, float]
    mass: float
    colour: str
    rgba: tuple[float, float, float, float]
    start: Pose
    support: str | None
    grasp_approaches: tuple[str, ...]
    """The approaches its class allows ("top", "side"), in the class's order of preference; none when no
    class above it states them (it cannot be taken: :class:`NotGraspableError` when a task would)."""
    grasp_height: float

    @property
    def name(self) -> str:
        return local_name(self.iri)

    @property
    def grasp_approach(self) -> str:
        """The approach its class prefers."""
        if not self.grasp_approaches:
            raise NotGraspableError(self.iri, self.types)
        return self.grasp_approaches[0]


@dataclass(frozen=True)
class Person:
    iri: str
    start: Pose
    colour: str
    rgba: tuple[float, float, float, float]

    @property
    def name(self) -> str:
        return local_name(self.iri)


@dataclass(frozen=True)
class Arm:
    iri: str
    robot: str
    side: str
    mount: tuple[float, float, float]
    yaw: float
    reach: float


@dataclass(frozen=True)
class Camera:
    """A camera: where its eye is, where it looks (``pitch`` -pi/2 is straight down, with the top of
    the image towards ``yaw``), its vertical field of view (degrees) and range, and for a camera on a
    robot its housing's size and what it is mounted on."""

    iri: str
    position: tuple[float, float, float]
    fov: float
    yaw: float = math.pi / 2
    pitch: float = -math.pi / 2
    near: float = 0.2
    far: float = 8.0
    size: tuple[float, float, float] | None = None
    mount: str | None = None
    occlusion_tolerance: float = 0.0
    """The largest fraction of the sight lines to a thing's outline that the map's solid boxes may cut for
    the camera still to see it whole (``home:occlusionTolerance``; ``kb.camera_view.hidden``)."""
    colours: tuple[ColourWindow, ...] = ()
    """The colours it tells apart (``home:hasColourWindow``, :func:`kb.colour_windows.read_colour_windows`)."""

    @property
    def looks_down(self) -> bool:
        return abs(math.cos(self.pitch)) < 1e-6

    @property
    def direction(self) -> tuple[float, float, float]:
        """The unit vector the camera looks along."""
        c = math.cos(self.pitch)
        return (c * math.cos(self.yaw), c * math.sin(self.yaw), math.sin(self.pitch))

    @property
    def name(self) -> str:
        return local_name(self.iri)


@dataclass(frozen=True)
class Marker:
    """A colour marker of two patches on a robot's platform: their colours, one patch's size (along and
    across the robot) and the distance between the patches' centres."""

    front: str
    rear: str
    patch: tuple[float, float]
    separation: float


@dataclass(frozen=True)
class MobileRobot:
    iri: str
    start: Pose
    platform: str | None
    platform_height: float | None
    marker_colours: tuple[str, str] | None  # front, rear
    footprint: tuple[float, float] = (0.45, 0.38)
    """Length along the heading and width (m)."""
    marker: Marker | None = None

    @property
    def name(self) -> str:
        return local_name(self.iri)


@dataclass(frozen=True)
class Dispenser:
    """An appliance with a tap: its body, the tap's lever (pushed towards the body, it opens the tap)
    and the spout, with the point where the water leaves it."""

    iri: str
    body: Thing
    lever: Thing
    spout: Thing
    outlet: tuple[float, float, float]

    @property
    def name(self) -> str:
        return local_name(self.iri)


@dataclass(frozen=True)
class SemanticMap:
    """What the store says the home holds, by IRI."""

    things: dict[str, Thing] = field(default_factory=dict)
    objects: dict[str, MapObject] = field(default_factory=dict)
    people: dict[str, Person] = field(default_factory=dict)
    arms: dict[str, Arm] = field(default_factory=dict)
    robots: dict[str, MobileRobot] = field(default_factory=dict)
    cameras: dict[str, Camera] = field(default_factory=dict)
    types: dict[str, tuple[str, ...]] = field(default_factory=dict)
    facts: dict[str, dict[str, list[str]]] = field(default_factory=dict)
    containers: frozenset[str] = frozenset()
    """The things that are a home:Container by the taxonomy: what a tap can fill."""
    furniture: frozenset[str] = frozenset()
    """The things that are home:Furniture by the taxonomy: what the simulation builds as tables."""
    rooms: frozenset[str] = frozenset()
    regions: frozenset[str] = frozenset()
    """The things that are a home:Region (below the tap, the table's top): where objects can be put."""
    walls: frozenset[str] = frozenset()
    bodies: frozenset[str] = frozenset()
    """Robots with an extent of their own (a torso standing on the floor), by the taxonomy (home:Robot)."""
    dispensers: dict[str, Dispenser] = field(default_factory=dict)
    hands: dict[str, Hand] = field(default_factory=dict)
    """Each arm's hand, by the arm's IRI (:func:`kb.hands.read_hands`)."""

    def extent(self) -> Box:
        """The box around every room: the home's floor."""
        boxes = [self.things[iri].box for iri in self.rooms if iri in self.things]
        if not boxes:
            raise MapError(HOME + "Room", "has no individual with an extent: the home has no rooms")
        return Box(
            min(b.min_x for b in boxes),
            max(b.max_x for b in boxes),
            min(b.min_y for b in boxes),
            max(b.max_y for b in boxes),
        )

    def of_type(self, concept: str) -> list[str]:
        """The things whose asserted classes include ``concept`` (no subclass reasoning: see :func:`designate`)."""
        return sorted(iri for iri, types in self.types.items() if concept in types)

    def appearance(self, concept: str) -> tuple[str, tuple[float, float, float, float]] | None:
        """How the things asserted to be a ``concept`` look (the first by IRI with a colour name): how
        perception finds them and how the simulation shows them; None when none says."""
        for iri in self.of_type(concept):
            values = self.facts.get(iri, {})
            name = _text(values, "colourName", iri)
            if name:
                return name, _rgba(iri, values)
        return None

    def marker_colours(self, iri: str) -> tuple[str, str] | None:
        """The front and rear colours of a marker-colours individual (or a robot's marker)."""
        values = self.facts.get(iri, {})
        if HOME + "frontColourName" in values and HOME + "rearColourName" in values:
            return values[HOME + "frontColourName"][0], values[HOME + "rearColourName"][0]
        robot = self.robots.get(iri)
        return robot.marker_colours if robot else None

    @classmethod
    def read(cls, kb: KnowledgeBase) -> SemanticMap:
        declared = frozenset(row["property"].value for row in kb.select("declared_properties", {"namespace": HOME}))
        said = _DECLARED.set(declared)  # a missing property's hint proposes no declared one as its slip
        try:
            return cls._read(kb, declared)
        finally:
            _DECLARED.reset(said)

    @classmethod
    def _read(cls, kb: KnowledgeBase, declared: frozenset[str]) -> SemanticMap:
        facts: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
        quoted: set[tuple[str, str]] = set()  # (thing, property) given a literal: text where a thing may belong
        for row in kb.select("map_facts"):
            facts[row["thing"].value][row["property"].value].append(row["value"].value)
            if isinstance(row["value"], Literal):
                quoted.add((row["thing"].value, row["property"].value))
        types: dict[str, list[str]] = defaultdict(list)
        for row in kb.select("map_types"):
            types[row["thing"].value].append(row["type"].value)
        affordances: dict[str, list[tuple[str, str, str]]] = {}
        nearest: dict[str, int] = {}
        for row in kb.select("grasp_affordances"):  # nearest ancestor first
            concept, distance = row["class"].value, int(row["distance"].value)
            if nearest.setdefault(concept, distance) == distance:  # a farther ancestor's is overridden
                stated = (row["approach"].value, row["ratio"].value, row["ancestor"].value)
                affordances.setdefault(concept, []).append(stated)

        designated: dict[str, set[str]] = defaultdict(set)  # one query for every class, not one per class
        for row in kb.queries.select_every(kb.store, "designate"):
            designated[row["class"].value].add(row["thing"].value)

        def things_of(concept: str) -> frozenset[str]:
            return frozenset(designated.get(HOME + concept, ()))

        from cbrs.kb.hands import read_hands  # kb.hands builds on this module's MapError

        people = things_of("Person")
        built = cls(
            hands=read_hands(kb),
            types={k: tuple(v) for k, v in types.items()},
            facts={k: dict(v) for k, v in facts.items()},
            containers=things_of("Container"),
            furniture=things_of("Furniture"),
            rooms=things_of("Room"),
            regions=things_of("Region"),
            walls=things_of("Wall"),
            bodies=things_of("Robot"),
        )
        for iri, values in facts.items():
            _classify(built, iri, values, tuple(types.get(iri, ())), affordances, facts, iri in people)
        from cbrs.kb.colour_windows import read_colour_windows  # it builds on this module's MapError

        windows = read_colour_windows(kb) if built.cameras else {}
        for iri, camera in built.cameras.items():
            built.cameras[iri] = replace(camera, colours=windows.get(iri, ()))
        for iri, values in facts.items():
            for tap in values.get(HOME + "hasTap", []):
                built.dispensers[iri] = _dispenser(built, iri, tap, facts)
        _check_extents(built, things_of("ObjectPlace"))
        _check_supports(built, quoted)
        _check_heights(built)
        _check_masses(built)
        _check_overlaps(built)
        _check_properties(declared, facts)
        return built


def _check_properties(declared: frozenset[str], facts: dict[str, dict[str, list[str]]]) -> None:
    """Every property of the home namespace the map's statements use is one the vocabulary declares: a
    misspelt optional property (home:yaww for home:yaw) is declared nowhere, so the load took it and the
    reader ignored it, the thing keeping its default. Checked after the required properties, whose own
    checks say what is missing. A store without the home vocabulary has nothing to check against."""
    if not declared:
        return
    for thing in sorted(facts):
        for prop in sorted(facts[thing]):
            if prop.startswith(HOME) and prop not in declared:
                near = nearest_term(prop, declared)
                hint = f" (did you mean home:{local_name(near)}?)" if near else ""
                raise MapError(
                    thing,
                    f"has home:{local_name(prop)} {facts[thing][prop][0]!r}, a property the home vocabulary does "
                    f"not declare, which would be ignored{hint}",
                )


def _number(values: dict[str, list[str]], name: str, iri: str, default: float | None = None) -> float:
    raw = values.get(HOME + name)
    if not raw:
        if default is None:
            raise _missing(values, name, iri)
        return default
    numbers = set()
    for text in raw:
        try:
            numbers.add(float(text))
        except ValueError:
            raise MapError(iri, f"has home:{name} {text!r}, not a number") from None
    if len(numbers) > 1:
        raise _two_values(iri, name, raw)
    return numbers.pop()


def _missing(values: dict[str, list[str]], name: str, iri: str, why: str = "") -> MapError:
    """A required property the thing lacks, with the property of its own it may be a slip of (home:colorName
    for home:colourName): a misspelt property is declared nowhere, so the load took it silently, and a
    declared one (home:sizeZ beside a missing home:sizeX) is no slip."""
    declared = _DECLARED.get()
    slip = nearest_term(HOME + name, [prop for prop in values if prop != HOME + name and prop not in declared])
    hint = f" (did you mean home:{name} for its home:{local_name(slip)} {values[slip][0]!r}?)" if slip else ""
    return MapError(iri, f"has no home:{name}{why}{hint}")


def _text(values: dict[str, list[str]], name: str, iri: str) -> str | None:
    raw = values.get(HOME + name)
    if raw and len(set(raw)) > 1:
        raise _two_values(iri, name, raw)
    return raw[0] if raw else None


def _colour(values: dict[str, list[str]], iri: str, why: str) -> str:
    """The thing's home:colourName; "" when it has none and no property of its own reads as a slip of it
    (home:colorName), which is refused (``why`` it is needed). A thing with no colour at all is taken
    as before: the simulation builds it, and perception says it cannot look for it when asked to."""
    colour = _text(values, "colourName", iri)
    if not colour and nearest_term(HOME + "colourName", [prop for prop in values if prop != HOME + "colourName"]):
        raise _missing(values, "colourName", iri, f": {why}")
    return colour or ""


def _two_values(iri: str, name: str, raw: list[str]) -> MapError:
    """A thing has one pose, size or colour: two values are a contradiction, not a choice to make
    quietly (a load adds statements, so moving a thing by loading its new place leaves the old one)."""
    shown = " and ".join(repr(text) for text in sorted(set(raw)))
    return MapError(
        iri,
        f"has home:{name} {shown}: one value is needed; remove the old one (a load only adds: "
        "update the map with DELETE/INSERT, docs/tasks.md)",
    )


UNPAINTED = (0.5, 0.5, 0.5, 1.0)
"""How a thing the map gives no home:rgba is painted: a mid grey, no colour a camera tells."""


def _rgba(iri: str, values: dict[str, list[str]]) -> tuple[float, float, float, float]:
    text = _text(values, "rgba", iri)
    if not text:
        return UNPAINTED
    try:
        parts = [float(part) for part in text.split()]
    except ValueError:
        raise MapError(iri, f"has home:rgba {text!r}; write four numbers in 0..1") from None
    if len(parts) == 3:
        parts.append(1.0)
    if len(parts) != 4 or not all(0.0 <= part <= 1.0 for part in parts):
        raise MapError(iri, f"has home:rgba {text!r}; write four numbers in 0..1")
    return (parts[0], parts[1], parts[2], parts[3])


def _classify(
    built: SemanticMap,
    iri: str,
    values: dict[str, list[str]],
    types: tuple[str, ...],
    affordances: dict[str, list[tuple[str, str, str]]],
    facts: dict[str, dict[str, list[str]]],
    person: bool,
) -> None:
    if HOME + "fieldOfView" in values:
        position = (_number(values, "x", iri), _number(values, "y", iri), _number(values, "z", iri))
        size = None
        if HOME + "sizeX" in values:
            size = (_number(values, "sizeX", iri), _number(values, "sizeY", iri), _number(values, "sizeZ", iri))
        camera = Camera(
            iri,
            position,
            _number(values, "fieldOfView", iri),
            yaw=_number(values, "yaw", iri, math.pi / 2),
            pitch=_number(values, "pitch", iri, -math.pi / 2),
            near=_number(values, "minRange", iri, 0.2),
            far=_number(values, "maxRange", iri, 8.0),
            size=size,
            mount=_named(facts, iri, "mountedOn", values.get(HOME + "mountedOn", [None])[0]),
            occlusion_tolerance=_number(values, "occlusionTolerance", iri, Camera.occlusion_tolerance),
        )
        if not 0.0 < camera.near < camera.far:
            raise MapError(iri, f"has a range of {camera.near}..{camera.far} m; need 0 < home:minRange < home:maxRange")
        if not 0.0 < camera.fov < 180.0:
            raise MapError(iri, f"has a field of view of {camera.fov} degrees; it must be between 0 and 180")
        if not 0.0 <= camera.occlusion_tolerance < 1.0:
            raise MapError(
                iri,
                f"has a home:occlusionTolerance of {camera.occlusion_tolerance}; it is a fraction of sight lines, "
                "from 0 up to (not including) 1",
            )
        built.cameras[iri] = camera
        return
    if HOME + "armSide" in values:
        robots = [robot for robot, props in facts.items() if iri in props.get(HOME + "hasArm", [])]
        built.arms[iri] = Arm(
            iri,
            robots[0] if robots else "",
            _text(values, "armSide", iri) or "",
            (_number(values, "x", iri), _number(values, "y", iri), _number(values, "z", iri)),
            _number(values, "yaw", iri, 0.0),
            _number(values, "reach", iri),
        )
        return
    if HOME + "shapeKind" in values:
        shape = _text(values, "shapeKind", iri) or ""
        if shape not in ("box", "cylinder"):
            raise MapError(iri, f'has home:shapeKind {shape!r}; use "box" or "cylinder"')
        concept = next((t for t in types if t in affordances), None)  # None: it cannot be taken (a decoration)
        size = (_number(values, "sizeX", iri), _number(values, "sizeY", iri), _number(values, "sizeZ", iri))
        if min(size) <= 0:
            raise MapError(iri, f"has a size of {size}; every size must be positive")
        support = values.get(HOME + "isLocatedOn", [None])[0]
        built.objects[iri] = MapObject(
            iri,
            types,
            shape,
            size,
            _number(values, "massKg", iri),
            _colour(values, iri, "perception finds an object by its colour"),
            _rgba(iri, values),
            Pose(_number(values, "x", iri), _number(values, "y", iri), _number(values, "yaw", iri, 0.0)),
            support,
            *(_grasp(concept, affordances[concept], size[2]) if concept is not None else ((), 0.0)),
        )
        return
    if person:  # a home:Person by the taxonomy
        built.people[iri] = Person(
            iri,
            Pose(_number(values, "x", iri), _number(values, "y", iri), _number(values, "yaw", iri, 0.0)),
            _colour(values, iri, "the cameras find a person by the colour of their shirt"),
            _rgba(iri, values),
        )
        return
    if HOME + "hasPlatform" in values or HOME + "hasMarker" in values:
        platform = _named(facts, iri, "hasPlatform", values.get(HOME + "hasPlatform", [None])[0])
        height = None
        if platform is not None:
            height = _number(facts.get(platform, {}), "maxZ", platform)
        marker = _named(facts, iri, "hasMarker", values.get(HOME + "hasMarker", [None])[0])
        colours = None
        geometry = None
        if marker is not None:
            marker_values = facts.get(marker, {})
            colour_node = _named(facts, marker, "hasColour", marker_values.get(HOME + "hasColour", [marker])[0])
            node = facts.get(colour_node, {})
            front, rear = _text(node, "frontColourName", colour_node), _text(node, "rearColourName", colour_node)
            colours = (front, rear) if front and rear else None
            if colours is not None:
                patch = (_number(marker_values, "sizeX", marker), _number(marker_values, "sizeY", marker))
                geometry = Marker(colours[0], colours[1], patch, _number(marker_values, "markerSeparation", marker))
        footprint = (_number(values, "sizeX", iri), _number(values, "sizeY", iri))
        if min(footprint) <= 0:
            raise MapError(iri, f"has a footprint of {footprint}; home:sizeX and home:sizeY must be positive")
        built.robots[iri] = MobileRobot(
            iri,
            Pose(_number(values, "x", iri), _number(values, "y", iri), _number(values, "yaw", iri, 0.0)),
            platform,
            height,
            colours,
            footprint,
            geometry,
        )
        return
    if HOME + "minX" in values:  # the floor's 0 m and a top's own height only where _check_heights_given allows
        top = _number(values, "maxZ", iri, 0.0)
        box = Box(
            _number(values, "minX", iri),
            _number(values, "maxX", iri),
            _number(values, "minY", iri),
            _number(values, "maxY", iri),
            _number(values, "minZ", iri, top),
            top,
        )
        dock_iri = _named(facts, iri, "dockingPose", values.get(HOME + "dockingPose", [None])[0])
        dock = None
        if dock_iri is not None:
            node = facts.get(dock_iri, {})
            dock = Pose(_number(node, "x", dock_iri), _number(node, "y", dock_iri), _number(node, "yaw", dock_iri, 0.0))
        built.things[iri] = Thing(iri, types, box, dock)


@overload
def _named(facts: dict[str, dict[str, list[str]]], iri: str, prop: str, target: str) -> str: ...
@overload
def _named(facts: dict[str, dict[str, list[str]]], iri: str, prop: str, target: str | None) -> str | None: ...
def _named(facts: dict[str, dict[str, list[str]]], iri: str, prop: str, target: str | None) -> str | None:
    """``target``, what ``iri``'s ``home:{prop}`` names, when graph:map says something of it (None: it names
    nothing). One the map says nothing of is refused, with the thing it may mean: a misspelt platform was
    said to have no home:maxZ, a misspelt marker left the robot without colours, and a camera mounted on a
    misspelt thing was taken as mounted, its mast never built, without a word."""
    if target is None or target in facts:
        return target
    near = nearest_term(target, facts)
    hint = f" (did you mean {local_name(near)}?)" if near else ""
    raise MapError(iri, f"has home:{prop} {local_name(target)} ({target}), of which graph:map says nothing{hint}")


GRASP_APPROACHES = ("top", "side")
"""The approaches the arms' grasp planner computes (:class:`sim.grasping.GraspKind`)."""


def _grasp(concept: str, stated: list[tuple[str, str, str]], height: float) -> tuple[tuple[str, ...], float]:
    """The approaches (in order of preference) and the grasp height of an object of ``concept``, from
    ``concept`` or its nearest superclass that states them (``stated``: approach, ratio, the class that
    states them). A class writes its approaches as one list, best first ("side top"): two statements of
    either property give no order (nor one height), so they are refused, naming the class (or classes,
    as near) that stated them and both values, as two values of any one property are."""
    approaches = sorted({approach for approach, _, _ in stated})
    ratios = sorted({ratio for _, ratio, _ in stated})
    for name, values, index in (("graspApproach", approaches, 0), ("graspHeightRatio", ratios, 1)):
        if len(values) > 1:
            raise _stated_twice(concept, name, stated, index)
    kinds = tuple(approaches[0].split())
    unknown = [kind for kind in kinds if kind not in GRASP_APPROACHES]
    if not kinds or unknown or len(set(kinds)) != len(kinds):
        raise MapError(
            concept,
            f"has home:graspApproach {approaches[0]!r}; write approaches from "
            + ", ".join(repr(a) for a in GRASP_APPROACHES)
            + ', each once, best first ("side top")',
        )
    try:
        ratio = float(ratios[0])
    except ValueError:
        raise MapError(concept, f"has home:graspHeightRatio {ratios[0]!r}, not a number") from None
    return kinds, ratio * height


def _stated_twice(concept: str, name: str, stated: list[tuple[str, str, str]], index: int) -> MapError:
    """Two values of a grasp property for ``concept``'s objects, named by the class that stated them
    (an object's class inherits them): the map author fixes that class, not the object's."""
    said: dict[str, set[str]] = {}
    for row in stated:
        said.setdefault(row[2], set()).add(row[index])
    owner = sorted(said)[0]
    inherited = "" if owner == concept else f" (the nearest class above {local_name(concept)} that says)"
    order = ' they give no order of preference; write one list, best first ("side top")'
    how = order if index == 0 else " one value is needed"
    if len(said) == 1:
        shown = " and ".join(repr(value) for value in sorted(said[owner]))
        return MapError(owner, f"has home:{name} {shown}{inherited}:{how}")
    each = "; ".join(
        f"{local_name(cls)} has {' and '.join(repr(v) for v in sorted(values))}" for cls, values in sorted(said.items())
    )
    return MapError(
        owner,
        f"and {', '.join(local_name(cls) for cls in sorted(said)[1:])} are as near above {local_name(concept)} and "
        f"give home:{name} ({each}):{how}, on one class",
    )


_EXTENT = ("minX", "maxX", "minY", "maxY", "maxZ")
"""The properties of an extent a piece of furniture needs (``home:minZ`` defaults to its top)."""


def _check_extents(built: SemanticMap, places: frozenset[str]) -> None:
    """Every piece of furniture, object place, region and wall the map describes is built: a box of its
    own (a thing), or an object with a size. One with neither was read as nothing, yet listed as furniture,
    so the home check passed it and a task putting something on it failed mid-run (the lab4 bench); a wall
    or a region was left out of the home without a word. Then :func:`_check_heights_given`."""
    for iri in sorted((built.furniture | places | built.regions | built.walls) & built.types.keys()):
        if iri in built.things or iri in built.objects:
            continue
        values = built.facts.get(iri, {})
        missing = tuple(f"home:{name}" for name in _EXTENT if HOME + name not in values)
        raise NoExtentError(iri, built.types[iri], missing, _slip(values, missing))
    for iri, values in sorted(built.facts.items()):  # a room or a device whose home:minX an update deleted
        given = [name for name in ("maxX", "minY", "maxY") if HOME + name in values]
        if given and iri not in built.things and HOME + "minX" not in values:
            why = (
                f"it gives home:{', home:'.join(given)} of an extent, and a thing without home:minX is read as one "
                "with no extent at all (left out of the home: a room's floor, what rooms a device is in)"
            )
            missing = ("home:minX",)
            raise NoExtentError(iri, built.types.get(iri, ()), missing, _slip(values, missing), why)
    _check_heights_given(built, places)


def _check_heights_given(built: SemanticMap, places: frozenset[str]) -> None:
    """Every thing built as a box has the heights the simulation reads of it; none stands in as 0 m.

    A room is a floor area (``home:minX`` .. ``home:maxY``; its height is the floor's, 0 m), and so is any
    other thing with a footprint alone (a device the map places by its area, which only says what rooms it
    is in). A piece of furniture needs its top (``home:maxZ``, where things stand; it is built as a top on
    legs, and its ``home:minZ`` is its top unless given). Everything else the simulation builds or rests
    things in (a region, an object place, a wall, an appliance and its tap and spout, a robot's body), or
    any thing that gives one of its heights, needs both ``home:minZ`` and ``home:maxZ``: deleting the
    kitchen table's ``home:maxZ`` by an update left its top at 0 m, and a region's missing ``home:minZ`` read
    as its top."""
    parts = {
        part.iri
        for dispenser in built.dispensers.values()
        for part in (dispenser.body, dispenser.lever, dispenser.spout)
    }
    solid = built.furniture | places | built.regions | built.walls | built.bodies | parts
    for iri in sorted(built.things):
        if iri in built.rooms:
            continue
        values = built.facts.get(iri, {})
        if iri not in solid and HOME + "minZ" not in values and HOME + "maxZ" not in values:
            continue
        table = iri in built.furniture and iri not in built.regions and iri not in places
        wanted = ("maxZ",) if table else ("minZ", "maxZ")
        missing = tuple(f"home:{name}" for name in wanted if HOME + name not in values)
        if not missing:
            continue
        why = (
            "things stand on its top (home:maxZ), which no default may stand in for (it read as 0 m, the floor)"
            if table
            else "the simulation builds it, or rests things in it, from home:minZ up to home:maxZ, and no default "
            "may stand in for either (a missing home:maxZ read as 0 m, a missing home:minZ as its top)"
        )
        raise NoExtentError(iri, built.types.get(iri, ()), missing, _slip(values, missing), why)


def _slip(values: dict[str, list[str]], missing: tuple[str, ...]) -> str:
    """A hint at a property of the thing's own that may be a slip of a missing one (home:maxz for home:maxZ)."""
    declared = _DECLARED.get()
    wanted = [HOME + name.removeprefix("home:") for name in missing]
    slips = [  # a misspelt property is declared nowhere: the load took it
        f"home:{local_name(near)} for its home:{local_name(prop)}"
        for prop in sorted(values)
        if prop not in declared and (near := nearest_term(prop, wanted)) is not None
    ]
    return f" (did you mean {'; '.join(slips)}?)" if slips else ""


def _check_supports(built: SemanticMap, quoted: set[tuple[str, str]] = set()) -> None:  # noqa: B006 (read only)
    """Each object's support (home:isLocatedOn) is a thing of the map with an extent, and the object's
    centre is over it: the simulation stands the object on the support's top, and an unknown support
    (a misspelt IRI) stood it on the floor, an object beyond its support's edge was moved onto it.
    ``quoted``: the (thing, property) pairs the map gives a literal, said as such (``home:isLocatedOn
    "KitchenTable"`` was called a support that is nothing in the map, as a misspelt IRI is)."""
    for iri, obj in sorted(built.objects.items()):
        if obj.support is None:
            continue
        support = built.things.get(obj.support)
        base = next((robot for robot in built.robots.values() if robot.platform == obj.support), None)
        if base is not None:  # said so with an extent or without: "add an extent" led to a plan that cannot reach it
            raise MapError(iri, _on_a_platform(obj.support, base))
        if support is None and obj.support in built.objects:
            raise MapError(iri, _on_an_object(obj.support, built.objects[obj.support], built))
        if support is None and (iri, HOME + "isLocatedOn") in quoted:
            named = sorted(t for t in built.things if local_name(t) == obj.support)
            near = named[0] if named else nearest_term(obj.support, built.things)
            meant = f" (did you mean {shorten(near)}, {near}?)" if near else ""
            raise MapError(
                iri,
                f'has home:isLocatedOn "{obj.support}", a literal (text in quotes), where the thing it stands on '
                f"belongs: name that thing by its IRI, without quotes{meant}",
            )
        if support is None:
            known = obj.support in built.facts or obj.support in built.types
            what = "has no extent (home:minX .. home:maxZ) to stand on" if known else "is nothing in the map"
            near = nearest_term(obj.support, built.things)
            hint = f" (did you mean {local_name(near)}, {near}?)" if near else ""
            raise MapError(iri, f"has home:isLocatedOn {obj.support}, which {what}{hint}")
        box = support.box
        _check_fits(obj, support)
        if not box.contains_xy(obj.start.x, obj.start.y):
            raise MapError(
                iri,
                f"has home:x {obj.start.x:g}, home:y {obj.start.y:g}, not over its support {support.name} "
                f"(home:isLocatedOn; x {box.min_x:g} .. {box.max_x:g}, y {box.min_y:g} .. {box.max_y:g}): "
                "move it onto the support or name the support it is on",
            )


def _check_heights(built: SemanticMap) -> None:
    """No piece of furniture, place or wall has its top above the ceiling, where the map's ceiling cameras
    (those looking straight down) hang: it is most often a height written in centimetres (home:maxZ 75 for a
    table 75 cm high), which the map read without a word and a run refused only as a thing "75 m up" out of
    every arm's reach. A map without a ceiling camera says nothing of its ceiling, and is not checked."""
    ceiling = max((camera for camera in built.cameras.values() if camera.looks_down), key=_height, default=None)
    if ceiling is None:
        return
    for iri, thing in sorted(built.things.items()):
        top = thing.box.max_z
        if top <= _height(ceiling):
            continue
        metres = f": heights are in metres, {top:g} cm is {top / 100:g}" if top / 100 <= _height(ceiling) else ""
        raise MapError(
            iri,
            f"has its top at {top:g} m (home:maxZ {top:g}), above the ceiling, where {ceiling.name} hangs at "
            f"{_height(ceiling):g} m{metres}",
        )


def _height(camera: Camera) -> float:
    return camera.position[2]


DENSEST = 22_590.0
"""kg/m³: osmium's density, the densest element at room conditions. No object of a home is denser than it
over the shape and size the map gives it (a hollow cup is less dense over its outline than its walls)."""


def _check_masses(built: SemanticMap) -> None:
    """No object is denser than any solid over its shape and size: it is most often a mass written in grams
    (home:massKg 300 for a 300 g mug), which the map read without a word and a run found only as an arm that
    stopped short lifting it, after two re-plans (docs/tasks.md, "A tenth round")."""
    for iri, obj in sorted(built.objects.items()):
        across = obj.size[0] * obj.size[1] * (math.pi / 4 if obj.shape == "cylinder" else 1.0)
        volume = across * obj.size[2]
        if volume <= 0 or obj.mass <= DENSEST * volume:
            continue
        grams = (
            f": masses are in kilograms, {obj.mass:g} g is {obj.mass / 1000:g}"
            if obj.mass <= DENSEST * volume * 1000
            else ""
        )
        raise MapError(
            iri,
            f"weighs {obj.mass:g} kg (home:massKg {obj.mass:g}) in a {obj.shape} of {volume * 1e6:.3g} cm³: "
            f"{obj.mass / volume / 1000:.3g} t/m³, denser than any solid (osmium, {DENSEST / 1000:.3g} t/m³){grams}",
        )


def _on_a_platform(platform: str, base: MobileRobot) -> str:
    """Why a thing cannot start on ``platform``, ``base``'s (home:hasPlatform), and how it gets there. Said as
    "no extent", a lab gave the platform one: the map loaded, the parcel stood where the base starts, and
    no plan could reach it (the twentieth round)."""
    return (
        f"has home:isLocatedOn {platform}, which is the platform of a mobile base ({base.name}, home:hasPlatform), "
        "which moves: a thing starts on furniture or a region with an extent; a thing is put on the platform by "
        "HandOverOntoPlatform (the arms' component whose effect is (home:PhysicalObject, home:isLocatedOn, "
        "home:RobotPlatform)): start it on furniture, and a task with that effect has it loaded"
    )


def _on_an_object(iri: str, below: MapObject, built: SemanticMap) -> str:
    """Why a thing cannot stand on ``below``, an object of the map, and what to write instead. The map's
    objects are what moves (a shape, a size, a pose the seed varies, a body the arms take); what things
    stand on is a piece of furniture or place, built as a fixed box whose top is their height. Said as "no
    extent", a lab that gave the object an extent as well was told the same again."""
    under = built.things.get(below.support or "")
    top = f"home:maxZ {under.box.max_z + below.size[2]:.3g}" if under is not None else "home:maxZ"
    return (
        f"has home:isLocatedOn {iri}, which is an object of the map (home:shapeKind {below.shape!r} and a size: a "
        "thing that moves), and nothing stands on an object: a thing stands on a piece of furniture or a place, "
        f"with an extent (home:minX .. home:maxZ) and no home:shapeKind. To stack it, describe {below.name} as "
        f"furniture (its class under home:Furniture, its extent home:minX .. {top}, its top), as "
        "docs/examples/spice_rack.ttl does for a rack on the table; or stand the thing on "
        f"what {below.name} stands on"
    )


def _check_fits(obj: MapObject, support: Thing) -> None:
    """An object's footprint fits its support's top at some turn (:mod:`kb.turned_fit`): one that does not
    stands on nothing, and it is most often a size written in centimetres (home:sizeX 7 for a 7 cm apple),
    which the overlap check then reported as another object inside it, by hundreds of centimetres, never
    naming the size (docs/tasks.md, "An eighth round"). One that fits either way round passes, as before;
    one that fits only turned (a 40 cm ruler across a 35 x 30 cm stool) passes where its home:yaw is such
    a turn, since the simulation stands it as home:yaw says and never turns it to fit; elsewhere it is
    refused, naming the turns that fit."""
    box = support.box
    sides = (box.max_x - box.min_x, box.max_y - box.min_y)
    length, width = obj.size[0], obj.size[1]
    if fits_unturned(length, width, sides):
        return
    sizes = f"home:sizeX {obj.size[0]:g}, home:sizeY {obj.size[1]:g}, home:sizeZ {obj.size[2]:g}"
    said = f"is {obj.size[0]:g} x {obj.size[1]:g} m ({sizes})"
    where = f"its support {support.name} (home:isLocatedOn; {sides[0]:.2f} x {sides[1]:.2f} m)"
    if fits_some_turn(length, width, sides):
        if fits_at(length, width, obj.start.yaw, sides):
            return
        turns = " or ".join(f"{low:.2f} to {high:.2f}" for low, high in fitting_turns(length, width, sides))
        raise MapError(
            obj.iri,
            f"{said}, longer than the top of {where} and fits it only turned, at home:yaw {turns} rad (or the "
            f"negative, or a half turn from these); its home:yaw is {obj.start.yaw:g}, and the simulation "
            "stands it as home:yaw says and does not turn it to fit: give a home:yaw that fits",
        )
    metres = (
        f"; sizes are in metres: {obj.size[0]:g} cm is {obj.size[0] / 100:g}"
        if max(obj.size) >= 1.0 and fits_some_turn(length / 100, width / 100, sides)
        else ""
    )
    raise MapError(obj.iri, f"{said}, wider than the top of {where}{metres or ', however turned'}")


def _footprint(obj: MapObject) -> list[tuple[float, float]]:
    """The corners of an object's footprint on its support (a cylinder's: the square around its circle,
    turned by its yaw)."""
    c, s = math.cos(obj.start.yaw), math.sin(obj.start.yaw)
    hx, hy = obj.size[0] / 2, obj.size[1] / 2
    return [
        (obj.start.x + c * u - s * v, obj.start.y + s * u + c * v)
        for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))
    ]


def _overlap(a: MapObject, b: MapObject) -> float:
    """How far two objects' footprints overlap (m; 0 or less: apart). Two cylinders by their circles,
    anything else by separating axes of the turned rectangles."""
    if a.shape == b.shape == "cylinder":
        gap = math.hypot(a.start.x - b.start.x, a.start.y - b.start.y)
        return min(a.size[:2]) / 2 + min(b.size[:2]) / 2 - gap
    corners = (_footprint(a), _footprint(b))
    depth = math.inf
    for shape in corners:
        for i in range(4):
            (x0, y0), (x1, y1) = shape[i], shape[(i + 1) % 4]
            axis = (y0 - y1, x1 - x0)
            norm = math.hypot(*axis) or 1.0
            spans = [[(x * axis[0] + y * axis[1]) / norm for x, y in points] for points in corners]
            depth = min(depth, min(max(spans[0]), max(spans[1])) - max(min(spans[0]), min(spans[1])))
    return depth


OVERLAP_TOLERANCE = 0.002
"""Two objects on one support whose footprints overlap by more than 2 mm touch where the map puts them:
pybullet pushes them apart as the world settles (the simulation says so, ``sim.world``)."""


def _inside(point: tuple[float, float], obj: MapObject) -> bool:
    """Whether a point of the floor plan is within an object's footprint."""
    dx, dy = point[0] - obj.start.x, point[1] - obj.start.y
    if obj.shape == "cylinder":
        return math.hypot(dx, dy) < min(obj.size[:2]) / 2
    c, s = math.cos(obj.start.yaw), math.sin(obj.start.yaw)
    return abs(c * dx + s * dy) < obj.size[0] / 2 and abs(-s * dx + c * dy) < obj.size[1] / 2


def overlaps(built: SemanticMap) -> list[tuple[MapObject, MapObject, float]]:
    """The pairs of objects on one support whose footprints overlap where the map puts them, and by how
    much (m), by IRI."""
    objects = sorted(built.objects.values(), key=lambda obj: obj.iri)
    found = []
    for i, a in enumerate(objects):
        for b in objects[i + 1 :]:
            if a.support is not None and a.support == b.support and (depth := _overlap(a, b)) > OVERLAP_TOLERANCE:
                found.append((a, b, depth))
    return found


def _check_overlaps(built: SemanticMap) -> None:
    """No object's centre is in another's footprint: such objects are one in the other, and settling
    would throw them apart anywhere. A lesser overlap (a pencil's end against a cup) is left to the
    simulation, which says what settling moved."""
    for a, b, depth in overlaps(built):
        if _inside((a.start.x, a.start.y), b) or _inside((b.start.x, b.start.y), a):
            raise MapError(
                a.iri,
                f"at home:x {a.start.x:g}, home:y {a.start.y:g} is in {b.name} ({b.iri}) at home:x "
                f"{b.start.x:g}, home:y {b.start.y:g} on {local_name(a.support or '')} (their footprints overlap by "
                f"{depth * 100:.1f} cm): move one of them",
            )


def _dispenser(built: SemanticMap, iri: str, tap: str, facts: dict[str, dict[str, list[str]]]) -> Dispenser:
    spout = facts.get(tap, {}).get(HOME + "hasSpout", [None])[0]
    if spout is None:
        raise MapError(tap, "is a tap with no home:hasSpout: the water would come from nowhere")
    parts = {"the appliance": iri, "its tap": tap, "its spout": spout}
    for what, part in parts.items():
        if part not in built.things:
            raise MapError(part, f"({what}) has no extent: give home:minX .. home:maxZ")
    values = facts.get(spout, {})
    outlet = (_number(values, "x", spout), _number(values, "y", spout), _number(values, "z", spout))
    return Dispenser(iri, built.things[iri], built.things[tap], built.things[spout], outlet)


class Reading(Enum):
    """How :func:`designate` reads a class that several things of the world are of.

    ``DIRECT_FIRST`` (the default): a class means, of those things, the ones *stated* to be of it and of
    none of its narrower classes (its direct instances, as an OWL reasoner's ``direct`` instances); a
    thing stated only of a narrower class (a lab's ``lab:GreenCup``) is named by that class. ``ANY``:
    every thing of the class or below counts alike, and two are always ambiguous."""

    DIRECT_FIRST = "direct-first"
    ANY = "any"


def designate(
    kb: KnowledgeBase,
    concept: str,
    prefer: str | None = None,
    reading: Reading = Reading.DIRECT_FIRST,
    guarantees: Collection[str] = (),
) -> str:
    """The one thing of the world that is a ``concept`` (a task input's class), by the ``designate`` query.

    With several candidates, those of which the map's stated quantities decide a status of ``guarantees``
    false are left out (what the task's preconditions guarantee of the thing it means: the full flask of
    two, by the weight each states; :mod:`kb.stated_quantities`), unless that leaves none; then those that
    are parts of ``prefer`` (the requesting robot, through any one or two links) win; then, by ``reading``,
    the one stated to be a ``concept`` and of no narrower class (docs/tasks.md, "Write a task"); still
    several is :class:`AmbiguousDesignatorError`, none is :class:`UnresolvedDesignatorError`.
    """
    return designate_each(kb, [(concept, prefer)], reading, [guarantees])[0]


def designate_each(
    kb: KnowledgeBase,
    wanted: Sequence[tuple[str, str | None]],
    reading: Reading = Reading.DIRECT_FIRST,
    guarantees: Sequence[Collection[str]] | None = None,
) -> list[str]:
    """:func:`designate` of each (concept, prefer) of ``wanted``, with the statuses ``guarantees`` gives
    for it (in the same order; None: none), their ``designate`` queries asked at once: one request to a
    remote store instead of one per input of a task."""
    asked = kb.queries.select_each(kb.store, [("designate", {"class": concept}) for concept, _ in wanted])
    statuses = list(guarantees) if guarantees is not None else [() for _ in wanted]
    pairs = zip(wanted, asked, statuses, strict=True)
    stated: list[StatedQuantities] = []  # read once, and only where several things are candidates

    def quantities() -> StatedQuantities:
        if not stated:
            stated.append(StatedQuantities.read(kb))
        return stated[0]

    return [_designated(kb, concept, prefer, reading, rows, its, quantities) for (concept, prefer), rows, its in pairs]


def _designated(
    kb: KnowledgeBase,
    concept: str,
    prefer: str | None,
    reading: Reading,
    rows: list[dict[str, Term]],
    guarantees: Collection[str] = (),
    quantities: Callable[[], StatedQuantities] | None = None,
) -> str:
    types: dict[str, set[str]] = defaultdict(set)
    for row in rows:
        types[row["thing"].value].add(row["type"].value)
    candidates = sorted(types)
    if not candidates:
        raise UnresolvedDesignatorError(concept)
    if len(candidates) > 1 and guarantees and quantities is not None:
        meant = quantities().meeting(candidates, guarantees)
        if meant and len(meant) < len(candidates):  # none left: the run's check of its preconditions refuses
            types = {thing: kinds for thing, kinds in types.items() if thing in meant}
            candidates = meant
    if len(candidates) > 1 and prefer is not None:
        owned = [c for c in candidates if _linked(kb, prefer, c)]
        if len(owned) == 1:
            return owned[0]
    if len(candidates) > 1 and reading is Reading.DIRECT_FIRST:
        direct = _direct(kb, concept, types)
        if len(direct) == 1:
            return direct[0]
        raise AmbiguousDesignatorError(concept, direct or candidates, stated=bool(direct))
    if len(candidates) > 1:
        raise AmbiguousDesignatorError(concept, candidates)
    return candidates[0]


def _direct(kb: KnowledgeBase, concept: str, types: dict[str, set[str]]) -> list[str]:
    """The things whose every stated class at or below ``concept`` (``types``, by thing) is ``concept``
    or one the taxonomy makes the same (a subclass cycle): its direct instances among them."""
    same = {concept}
    if any(kinds - same for kinds in types.values()):
        same |= {row["superclass"].value for row in kb.select("subclasses", {"class": concept})}
    return sorted(thing for thing, kinds in types.items() if kinds <= same)


def _linked(kb: KnowledgeBase, owner: str, thing: str) -> bool:
    """Whether ``thing`` is one of ``owner``'s things, one or two links away. Only things are followed:
    a fact's literal value (a robot's ``home:y 1.5``) is no thing to look up."""

    def linked(subject: str) -> set[str]:
        rows = kb.select("map_facts", {"thing": subject})
        return {row["value"].value for row in rows if isinstance(row["value"], NamedNode)}

    first = linked(owner)
    return thing in first or any(thing in linked(hop) for hop in first)
