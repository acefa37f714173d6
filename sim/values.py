"""Values between steps: one plain JSON shape per port type, named by the ontology class of the port.

A plan's data flow is what a component outside this process has to produce and consume, and the
rosbridge protocol carries JSON objects and nothing else. So every value a simulated component gives
or takes is a JSON object (dicts, lists, numbers, strings, null) with an ``"@type"`` holding the
IRI of the class its port declares (``home:RobotLocation``, ``home:Path``...). The Python objects the
skills work on (estimates, grids, paths, object models) live only inside a component: ``from_json``
/ ``decode`` at the start of its work, ``to_json`` at the end. A value that is not its type's shape is
refused with a ``MalformedValueError`` naming the key, what it held and what was expected.

The shapes, with examples, are in docs/values.md.
"""

from __future__ import annotations

import base64
import binascii
import functools
import itertools
import math
import weakref
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, NoReturn, TypeAlias, TypeVar

import numpy as np
from numpy.typing import NDArray

from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.kb.namespaces import HOME, expand
from cbrs.kb.semantic_map import MapObject, local_name
from cbrs.sim.errors import SimulationError
from cbrs.sim.geometry import Pose2D
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.mapping import OccupancyGrid, inflate
from cbrs.sim.perception import ObjectEstimate, PersonEstimate, RobotPoseEstimate
from cbrs.sim.planning import PlannedPath

__all__ = [
    "APPROACH_POSITION",
    "COLOUR_FEATURE",
    "GRASP_POSE",
    "GRID_MAP",
    "LOCATION",
    "MANIPULATION_PROPERTY",
    "OBJECT_FEATURE",
    "OBJECT_LOCATION",
    "OBJECT_POSITION_3D",
    "OCCUPANCY_GRID_MAP",
    "PATH",
    "PERSON_LOCATION",
    "PERSON_POSITION",
    "POSITION",
    "POSITION_2D",
    "ROBOT_LOCATION",
    "ROBOT_POSITION",
    "ColourFeature",
    "Designator",
    "GraspPlan",
    "IsA",
    "MalformedValueError",
    "Manipulation",
    "ObjectFeature",
    "Value",
    "bundled_taxonomy",
    "check",
    "concepts_of",
    "decode",
    "designator",
    "from_json",
    "taxonomy",
    "to_json",
]

DEFAULT_INFLATION_RADIUS = 0.30
"""A grid map value that does not say how far its obstacles were inflated is taken to be inflated by 30 cm
(the bundled base's footprint radius, rounded up)."""
ROBOT_LOCATION = HOME + "RobotLocation"
PERSON_POSITION = HOME + "PersonPosition"
PERSON_LOCATION = HOME + "PersonLocation"
POSITION = HOME + "Position"
POSITION_2D = HOME + "Position2D"
LOCATION = HOME + "Location"
APPROACH_POSITION = HOME + "ApproachPosition"
OBJECT_LOCATION = HOME + "ObjectLocation"
ROBOT_POSITION = HOME + "RobotPosition"
OBJECT_POSITION_3D = HOME + "ObjectPosition3D"
OCCUPANCY_GRID_MAP = HOME + "OccupancyGridMap"
GRID_MAP = HOME + "GridMap"
PATH = HOME + "Path"
MANIPULATION_PROPERTY = HOME + "ManipulationProperty"
GRASP_POSE = HOME + "GraspPose"
COLOUR_FEATURE = HOME + "ColourFeature"
OBJECT_FEATURE = HOME + "ObjectFeature"


# -- the Python side of the values that have no class of their own elsewhere -----------------------


@dataclass(frozen=True)
class Designator:
    """A thing of the world (a pen, a place, a person) as a value: its IRI and the class it was asked as."""

    iri: str
    concept: str


@dataclass(frozen=True)
class ColourFeature:
    """The colour a recogniser segments an object by (a name among the camera's colour windows, kb.colour_windows)."""

    colour: str


@dataclass(frozen=True)
class ObjectFeature:
    """The perceptual description of an object; the simulation's objects are told apart by colour only."""

    colour: str


@dataclass(frozen=True)
class Manipulation:
    """A ManipulationProperty: what an arm must know to handle an object, and which object it is."""

    object: str
    """The object's IRI."""
    model: ObjectModel

    @classmethod
    def of(cls, obj: MapObject) -> Manipulation:
        return cls(obj.iri, ObjectModel.of(obj))


@dataclass(frozen=True)
class GraspPlan:
    """What ComputeGraspPose gives: how to grasp this object. The world pose of the grasp is fixed only
    when an arm approaches, against the object's perceived position and the arm's mount."""

    object: str
    """The object's IRI."""
    model: ObjectModel


Value: TypeAlias = (
    Designator
    | RobotPoseEstimate
    | PersonEstimate
    | Pose2D
    | ObjectEstimate
    | OccupancyGrid
    | PlannedPath
    | Manipulation
    | GraspPlan
    | ColourFeature
    | ObjectFeature
)
"""What ``from_json`` gives and ``to_json`` takes."""

V = TypeVar("V")


# -- errors -----------------------------------------------------------------------------------------


class _Missing:
    def __repr__(self) -> str:
        return "missing"


MISSING: Any = _Missing()
WHOLE = "(value)"
"""The ``key`` of a ``MalformedValueError`` about the value itself rather than one of its fields."""


class MalformedValueError(SimulationError, ValueError):
    """A value between steps that is not the JSON shape of its type. A component given one fails its
    step (a SimulationError); the message names the key so that a remote component's author can fix it."""

    def __init__(self, concept: str | None, key: str, value: object, expected: str) -> None:
        self.concept = concept
        self.key = key
        self.value = value
        self.expected = expected
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        what = f"home:{local_name(concept)}" if concept and concept.startswith(HOME) else (concept or "value")
        if key == WHOLE:  # not a field: the value itself has the wrong shape (a bare 21.5, a list)
            where = f"the whole value is {shown}"
        else:
            where = f"{key!r} is {shown}" if value is not MISSING else f"{key!r} is missing"
        super().__init__(f"malformed {what}: {where}, expected {expected}")


# -- reading fields ---------------------------------------------------------------------------------


class _Fields:
    """The keys of one JSON object, read with the checks and error messages every type shares."""

    def __init__(self, concept: str, data: Mapping[str, Any]) -> None:
        self.concept = concept
        self.data = data

    def fail(self, key: str, value: object, expected: str) -> NoReturn:
        raise MalformedValueError(self.concept, key, value, expected)

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str) -> Any:
        if key not in self.data:
            self.fail(key, MISSING, "a value")
        return self.data[key]

    def number(self, key: str, default: float | None = None) -> float:
        """A finite number; ``default`` (if not None) when the key is absent."""
        if key not in self.data and default is not None:
            return default
        value = self.data.get(key, MISSING)
        if not _is_number(value):
            self.fail(key, value, "a finite number")
        return float(value)

    def optional_number(self, key: str) -> float | None:
        """A finite number, or None when the key is absent or null."""
        value = self.data.get(key)
        if value is None:
            return None
        if not _is_number(value):
            self.fail(key, value, "a finite number or null")
        return float(value)

    def integer(self, key: str, default: int | None = None) -> int:
        if key not in self.data and default is not None:
            return default
        value = self.data.get(key, MISSING)
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, value, "an integer")
        return value

    def text(self, key: str, default: str | None = None) -> str:
        if key not in self.data and default is not None:
            return default
        value = self.data.get(key, MISSING)
        if not isinstance(value, str):
            self.fail(key, value, "a string")
        return value

    def numbers(self, key: str, count: int, default: tuple[float, ...] | None = None) -> tuple[float, ...]:
        """A list of ``count`` finite numbers (a point, a size)."""
        if key not in self.data and default is not None:
            return default
        value = self.data.get(key, MISSING)
        if not (isinstance(value, list) and len(value) == count and all(_is_number(x) for x in value)):
            self.fail(key, value, f"a list of {count} finite numbers")
        return tuple(float(x) for x in value)

    def points(self, key: str) -> tuple[tuple[float, float], ...]:
        """A non-empty list of [x, y] pairs."""
        value = self.data.get(key, MISSING)
        ok = isinstance(value, list) and value and all(isinstance(p, list) and len(p) == 2 for p in value)
        if not ok or not all(_is_number(x) for p in value for x in p):
            self.fail(key, value, "a non-empty list of [x, y] pairs of finite numbers")
        return tuple((float(p[0]), float(p[1])) for p in value)


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _finite(concept: str, key: str, value: float) -> float:
    """A number fit for JSON: rosbridge (and JSON) have no NaN or infinity, so they are refused here."""
    number = float(value)
    if not math.isfinite(number):
        raise MalformedValueError(concept, key, number, "a finite number")
    return number


def _pair(concept: str, key: str, point: tuple[float, float]) -> list[float]:
    return [_finite(concept, key, point[0]), _finite(concept, key, point[1])]


# -- one codec per Python kind ----------------------------------------------------------------------


@dataclass(frozen=True)
class _Codec:
    kind: type
    concepts: tuple[str, ...]
    """The classes whose values have this shape; ``to_json`` writes the first unless told another."""
    encode: Callable[[Any, str], dict[str, Any]]
    decode: Callable[[_Fields], Any]


def _seen_by(value: RobotPoseEstimate | PersonEstimate | ObjectEstimate, concept: str) -> dict[str, Any]:
    """Who measured an estimate and when: optional for a remote producer, kept so a round trip is exact."""
    return {"camera": value.camera, "time": _finite(concept, "time", value.time), "pixels": int(value.pixels)}


def _encode_robot(value: RobotPoseEstimate, concept: str) -> dict[str, Any]:
    xyt = {k: _finite(concept, k, getattr(value, k)) for k in ("x", "y", "theta")}
    return {**xyt, **_seen_by(value, concept)}


def _decode_robot(f: _Fields) -> RobotPoseEstimate:
    x, y, theta = f.number("x"), f.number("y"), f.number("theta")
    return RobotPoseEstimate(x, y, theta, f.text("camera", ""), f.number("time", 0.0), f.integer("pixels", 0))


def _encode_person(value: PersonEstimate, concept: str) -> dict[str, Any]:
    return {"x": _finite(concept, "x", value.x), "y": _finite(concept, "y", value.y), **_seen_by(value, concept)}


def _decode_person(f: _Fields) -> PersonEstimate:
    x, y = f.number("x"), f.number("y")
    return PersonEstimate(x, y, f.text("camera", ""), f.number("time", 0.0), f.integer("pixels", 0))


def _encode_pose(value: Pose2D, concept: str) -> dict[str, Any]:
    return {k: _finite(concept, k, getattr(value, k)) for k in ("x", "y", "theta")}


def _decode_pose(f: _Fields) -> Pose2D:
    return Pose2D(f.number("x"), f.number("y"), f.number("theta"))


def _encode_object(value: ObjectEstimate, concept: str) -> dict[str, Any]:
    found: dict[str, Any] = {k: _finite(concept, k, getattr(value, k)) for k in ("x", "y", "z")}
    found["theta"] = None if value.yaw is None else _finite(concept, "theta", value.yaw)
    found["size"] = [_finite(concept, "size", s) for s in value.size]
    found["colour"] = value.colour
    return {**found, **_seen_by(value, concept)}


def _decode_object(f: _Fields) -> ObjectEstimate:
    size = f.numbers("size", 3, (0.0, 0.0, 0.0))
    return ObjectEstimate(
        f.number("x"),
        f.number("y"),
        f.number("z"),
        f.optional_number("theta"),
        (size[0], size[1], size[2]),
        f.text("colour", ""),
        f.text("camera", ""),
        f.number("time", 0.0),
        f.integer("pixels", 0),
    )


GridKey = tuple[float, tuple[float, ...], int, int, str, float]

_grids: weakref.WeakValueDictionary[GridKey, OccupancyGrid] = weakref.WeakValueDictionary()
"""Grids encoded here and still alive, by their JSON content. Decoding the same JSON gives the grid
back instead of a copy, so a run's planners share the grid the map server keeps, and with it the search
graph sim.planning caches per grid (0.3 s to build); a grid from elsewhere is decoded afresh."""


def _encode_grid(grid: OccupancyGrid, concept: str) -> dict[str, Any]:
    rows, cols = grid.shape
    packed = np.packbits(np.asarray(grid.occupied, dtype=np.bool_).ravel())
    resolution = _finite(concept, "resolution", grid.resolution)
    origin = _pair(concept, "origin", grid.origin)
    cells = base64.b64encode(packed.tobytes()).decode("ascii")
    radius = _finite(concept, "inflationRadius", grid.inflation_radius)
    _grids[(resolution, tuple(origin), cols, rows, cells, radius)] = grid
    return {
        "resolution": resolution,
        "origin": origin,
        "width": cols,
        "height": rows,
        "cells": cells,
        "inflationRadius": radius,
    }


def _decode_grid(f: _Fields) -> OccupancyGrid:
    resolution = f.number("resolution")
    if resolution <= 0.0:
        f.fail("resolution", resolution, "a positive number of metres per cell")
    origin = f.numbers("origin", 2)
    width, height = f.integer("width"), f.integer("height")
    for name, size in (("width", width), ("height", height)):
        if size < 1:
            f.fail(name, size, "a positive number of cells")
    cells = f.text("cells")
    radius = f.number("inflationRadius", DEFAULT_INFLATION_RADIUS)
    if not 0.0 <= radius <= max(width, height) * resolution:
        f.fail("inflationRadius", radius, "a number of metres from 0 to the map's size")  # bounds the work
    cached = _grids.get((resolution, origin, width, height, cells, radius))
    if cached is not None:
        return cached
    try:
        packed = base64.b64decode(cells, validate=True)
    except (binascii.Error, ValueError):
        f.fail("cells", cells, "base64 text")
    if len(packed) != (width * height + 7) // 8:
        f.fail("cells", cells, f"base64 of {(width * height + 7) // 8} bytes ({width} x {height} bits, packed)")
    bits = np.unpackbits(np.frombuffer(packed, dtype=np.uint8), count=width * height)
    occupied = bits.astype(np.bool_).reshape(height, width)
    inflated = _inflate(occupied, (radius + resolution / 2.0) / resolution)
    return OccupancyGrid(resolution, (origin[0], origin[1]), occupied, inflated, radius)


def _inflate(occupied: NDArray[np.bool_], radius_cells: float) -> NDArray[np.bool_]:
    """``sim.mapping.inflate`` on a frame of free cells as wide as the reach, cut off again: the same
    cells, also for a grid from elsewhere that is narrower than the reach (which ``inflate`` mis-slices)."""
    reach = math.ceil(radius_cells)
    grown = inflate(np.pad(occupied, reach), radius_cells)
    return grown[reach : reach + occupied.shape[0], reach : reach + occupied.shape[1]]


def _encode_path(path: PlannedPath, concept: str) -> dict[str, Any]:
    return {
        "waypoints": [_pair(concept, "waypoints", p) for p in path.waypoints],
        "start": _pair(concept, "start", path.start),
        "goal": _pair(concept, "goal", path.goal),
        "length": _finite(concept, "length", path.length),
        "cells": int(path.cells),
        "algorithm": path.algorithm,
    }


def _decode_path(f: _Fields) -> PlannedPath:
    waypoints = f.points("waypoints")
    start = f.numbers("start", 2, waypoints[0])
    goal = f.numbers("goal", 2, waypoints[-1])
    length = f.number("length", sum(math.dist(a, b) for a, b in itertools.pairwise(waypoints)))
    return PlannedPath(
        f.text("algorithm", ""), (start[0], start[1]), (goal[0], goal[1]), waypoints, length, f.integer("cells", 0)
    )


def _encode_handling(value: Manipulation | GraspPlan, concept: str) -> dict[str, Any]:
    model = value.model
    return {
        "object": value.object,
        "name": model.name,
        "colour": model.colour,
        "height": _finite(concept, "height", model.height),
        "width": _finite(concept, "width", model.width),
        "approach": model.grasp.value,
        "graspHeight": _finite(concept, "graspHeight", model.grasp_height),
    }


def _decode_model(f: _Fields) -> tuple[str, ObjectModel]:
    iri = f.text("object")
    if not iri:
        f.fail("object", iri, "the object's IRI")
    approach = f.text("approach")
    kinds = [kind.value for kind in GraspKind]
    if approach not in kinds:
        f.fail("approach", approach, "one of " + ", ".join(repr(k) for k in kinds))
    model = ObjectModel(
        f.text("name", local_name(iri)),
        f.text("colour", ""),
        f.number("height"),
        f.number("width"),
        GraspKind(approach),
        f.number("graspHeight"),
    )
    return iri, model


def _decode_manipulation(f: _Fields) -> Manipulation:
    return Manipulation(*_decode_model(f))


def _decode_grasp(f: _Fields) -> GraspPlan:
    return GraspPlan(*_decode_model(f))


def _encode_colour(value: ColourFeature, concept: str) -> dict[str, Any]:
    return {"colour": value.colour}


def _decode_colour(f: _Fields) -> ColourFeature:
    colour = f.text("colour")
    if not colour:
        f.fail("colour", colour, "a colour name")
    return ColourFeature(colour)


def _encode_feature(value: ObjectFeature, concept: str) -> dict[str, Any]:
    return {"colourFeature": to_json(ColourFeature(value.colour))}


def _decode_feature(f: _Fields) -> ObjectFeature:
    return ObjectFeature(decode(f.raw("colourFeature"), ColourFeature).colour)


_CODECS = (
    _Codec(RobotPoseEstimate, (ROBOT_LOCATION,), _encode_robot, _decode_robot),
    _Codec(PersonEstimate, (PERSON_POSITION, PERSON_LOCATION), _encode_person, _decode_person),
    _Codec(
        Pose2D,
        (POSITION_2D, APPROACH_POSITION, OBJECT_LOCATION, POSITION, LOCATION, ROBOT_POSITION),
        _encode_pose,
        _decode_pose,
    ),
    _Codec(ObjectEstimate, (OBJECT_POSITION_3D,), _encode_object, _decode_object),
    _Codec(OccupancyGrid, (OCCUPANCY_GRID_MAP, GRID_MAP), _encode_grid, _decode_grid),
    _Codec(PlannedPath, (PATH,), _encode_path, _decode_path),
    _Codec(Manipulation, (MANIPULATION_PROPERTY,), _encode_handling, _decode_manipulation),
    _Codec(GraspPlan, (GRASP_POSE,), _encode_handling, _decode_grasp),
    _Codec(ColourFeature, (COLOUR_FEATURE,), _encode_colour, _decode_colour),
    _Codec(ObjectFeature, (OBJECT_FEATURE,), _encode_feature, _decode_feature),
)
_BY_KIND: dict[type, _Codec] = {codec.kind: codec for codec in _CODECS}
_BY_CONCEPT: dict[str, _Codec] = {concept: codec for codec in _CODECS for concept in codec.concepts}


def concepts_of(kind: type) -> tuple[str, ...]:
    """The classes whose JSON values decode to ``kind`` (the first is what ``to_json`` writes)."""
    codec = _BY_KIND.get(kind)
    return codec.concepts if codec is not None else ()


# -- the interface ----------------------------------------------------------------------------------


def designator(iri: str, concept: str) -> dict[str, str]:
    """A thing of the world as a value between steps: its IRI and the class it was asked as."""
    return {"@id": iri, "@type": concept}


def to_json(value: Value, concept: str | None = None) -> dict[str, Any]:
    """The JSON value of ``value`` as an instance of ``concept`` (by default its kind's usual class).

    ``TypeError`` for a kind with no JSON shape, ``ValueError`` for a class the kind cannot stand for,
    ``MalformedValueError`` for a number JSON cannot carry (NaN, infinity).
    """
    if isinstance(value, Designator):
        return designator(value.iri, concept or value.concept)
    codec = _BY_KIND.get(type(value))
    if codec is None:
        raise TypeError(f"no JSON shape for a {type(value).__name__}")
    wanted = concept or codec.concepts[0]
    if wanted not in codec.concepts:
        names = ", ".join(local_name(c) for c in codec.concepts)
        raise ValueError(f"a {type(value).__name__} is a value of {names}, not of {local_name(wanted)}")
    return {"@type": wanted, **codec.encode(value, wanted)}


def from_json(data: object) -> Value:
    """The value a JSON object stands for, by its ``"@type"`` (a designator when it has an ``"@id"``)."""
    if not isinstance(data, dict):
        raise MalformedValueError(None, WHOLE, data, "a JSON object with an '@type'")
    concept = data.get("@type", MISSING)
    if not isinstance(concept, str) or not concept:
        raise MalformedValueError(None, "@type", concept, "the IRI of the value's class")
    if "@id" in data:
        iri = data["@id"]
        if not isinstance(iri, str) or not iri:
            raise MalformedValueError(concept, "@id", iri, "the IRI of a thing")
        return Designator(iri, concept)
    codec = _BY_CONCEPT.get(concept)
    if codec is None:
        known = ", ".join(local_name(c) for c in _BY_CONCEPT)
        raise MalformedValueError(None, "@type", concept, f"one of the classes with a JSON shape ({known})")
    value: Value = codec.decode(_Fields(concept, data))
    return value


def decode(data: object, kind: type[V]) -> V:
    """``from_json``, checked to be the kind a component works on: a step given a value of another
    type fails with the classes it would have taken."""
    value = from_json(data)
    if not isinstance(value, kind):
        concepts = concepts_of(kind) or ("a designator (@id)",)
        expected = "one of " + ", ".join(local_name(c) for c in concepts)
        assert isinstance(data, dict)
        raise MalformedValueError(None, "@type", data.get("@type"), expected)
    return value


IsA = Callable[[str, str], bool]
"""``is_a(class, superclass)``: whether the first class is the second or a subclass of it (a taxonomy)."""

RDFS_SUBCLASS_OF = "http://www.w3.org/2000/01/rdf-schema#subClassOf"


def taxonomy(pairs: Iterable[tuple[str, str]]) -> IsA:
    """The ``is_a`` of a taxonomy given as (class, superclass) pairs, closed here under transitivity
    (the store's ``subclasses`` query gives the closure already; a file's axioms do not)."""
    parents: dict[str, set[str]] = {}
    for sub, sup in pairs:
        parents.setdefault(sub, set()).add(sup)
    closure: dict[str, frozenset[str]] = {}

    def ancestors(concept: str) -> frozenset[str]:
        found = closure.get(concept)
        if found is None:
            seen: set[str] = set()
            todo = [concept]
            while todo:
                for sup in parents.get(todo.pop(), ()):
                    if sup not in seen:
                        seen.add(sup)
                        todo.append(sup)
            found = closure[concept] = frozenset(seen)
        return found

    return lambda concept, superclass: concept == superclass or superclass in ancestors(concept)


@functools.cache
def bundled_taxonomy() -> IsA:
    """The home ontology's taxonomy (``ontologies/home.ttl``, read once): what :func:`check` uses when
    it is given no store's. A run checks remote answers against its store's, which also knows the
    classes a lab registered."""
    import pyoxigraph as ox

    from cbrs.kb.resources import ontology_dir

    quads = ox.parse(path=str(ontology_dir() / "home.ttl"), format=ox.RdfFormat.TURTLE)
    return taxonomy(
        (q.subject.value, q.object.value)
        for q in quads
        if q.predicate.value == RDFS_SUBCLASS_OF
        and isinstance(q.subject, ox.NamedNode)
        and isinstance(q.object, ox.NamedNode)
    )


def check(concept: str, data: object, is_a: IsA | None = None) -> dict[str, Any]:
    """A value another process sent for a port of type ``concept``, checked against docs/values.md:
    a JSON object whose ``"@type"`` (a prefixed name is expanded) is the port's class or a subclass of
    it by ``is_a`` (default: :func:`bundled_taxonomy`).

    - A port whose class has a JSON shape here takes a value of that shape: one of the classes of the
      port's row, or a subclass of the port's class with no shape of its own (read as the port's shape
      and passed on as the port's class, so that its consumer can decode it). A designator (``"@id"``)
      is refused: a position or a map is data, not a thing of the world.
    - A port of any other class (a thing, a status, a thermometer's reading) takes any JSON object of
      its class or a subclass (``home:Opened`` for ``home:DoorStatus``), a designator of one included.

    ``concept`` may be a prefixed name (``home:ObjectPosition3D``), as ``@type`` may: given so, it was no
    class with a shape, and a good value was refused as of another class.

    Returns the value with its ``@type`` written in full; ``MalformedValueError`` (a ``ValueError``)
    names the port's class, what was given and what was expected."""
    concept = expand(concept)
    named = local_name(concept)
    if not isinstance(data, dict):
        raise MalformedValueError(concept, WHOLE, data, f"a JSON object with '@type' {named}")
    written = data.get("@type", MISSING)
    if not isinstance(written, str) or not written:
        raise MalformedValueError(concept, "@type", written, f"the class of the value ({named})")
    try:
        full = expand(written)
    except UnknownPrefixError as error:  # its did-you-mean: hom:Door for home:Door
        raise MalformedValueError(concept, "@type", written, f"an IRI or a prefixed name ({error.reason})") from None
    except ValueError:
        raise MalformedValueError(concept, "@type", written, "an IRI or a prefixed name") from None
    is_a = is_a if is_a is not None else bundled_taxonomy()
    value = {**data, "@type": full}
    codec = _BY_CONCEPT.get(concept)
    if "@id" in value:
        if codec is not None:
            raise MalformedValueError(
                concept, WHOLE, data, f"the JSON shape of {named} (docs/values.md), not a designator (@id)"
            )
        if not is_a(full, concept):
            raise MalformedValueError(concept, "@type", written, f"a designator of {named} or a subclass of it")
        from_json(value)  # a designator: an IRI and a class
        return value
    if codec is None:
        if not is_a(full, concept):
            raise MalformedValueError(concept, "@type", written, f"{named} or a subclass of it")
        return value
    expected = "one of " + ", ".join(local_name(c) for c in codec.concepts) + " or a subclass of " + named
    if full not in _BY_CONCEPT:
        if not is_a(full, concept):
            raise MalformedValueError(concept, "@type", written, expected)
        codec.decode(_Fields(concept, data))  # a subclass with no shape of its own: the port's shape
        return {**data, "@type": concept}
    decoded = from_json(value)
    if not isinstance(decoded, codec.kind):
        raise MalformedValueError(concept, "@type", written, expected)
    return value
