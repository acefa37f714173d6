"""Which person a step tracks, drives to or hands something to, and what the tracker may take for them.

A home holds any number of people (:mod:`kb.home_check`), so which one a step means is asked per run
(:func:`person_for`): the one the task designates, else the only one. None, several with nothing saying
which, one whose shirt another shares (the tracker finds a person by its colour alone), or one in the
colour of a patch of the mobile robot's marker (the tracker takes the patch for the person when their
shirt is out of view) is a :class:`PersonError` naming the step, before anything moves: refused rather
than guessed, since the robot would otherwise serve whoever the camera happened to see first. An object of
the shirt's colour that a camera sees with the person is only said (:func:`shirt_clashes`).
:func:`people_check` gives each person's verdict, which ``cbrs home`` and the browser's ``/home`` show.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from cbrs.kb.camera_view import floor_view
from cbrs.kb.home_check import HomeError
from cbrs.kb.semantic_map import HOME, Person, SemanticMap, local_name

__all__ = [
    "AmbiguousPersonError",
    "LookAlikeMarkerError",
    "LookAlikePeopleError",
    "NoPersonError",
    "PersonCheck",
    "PersonError",
    "ShirtClash",
    "look_alikes",
    "people_check",
    "person_for",
    "shirt_clashes",
]


_ADD_PERSON = "a home:Person with home:x, home:y and the home:colourName of their shirt"


class PersonError(HomeError):
    """A step needs a person the map cannot give it. ``step`` is what needs them (a component's IRI or a
    statement's class), ``people`` the people the choice was among (IRIs)."""

    def __init__(self, thing: str, step: str, people: list[str], problem: str) -> None:
        self.step = step
        self.people = tuple(people)
        super().__init__(thing, problem)


class NoPersonError(PersonError):
    """The map has no ``home:Person`` and a step tracks, drives to or hands something to one."""

    def __init__(self, step: str) -> None:
        super().__init__(
            HOME + "Person",
            step,
            [],
            f"has no individual in the map, and {local_name(step)} needs one (it tracks, goes to or hands "
            f"something to a person): add {_ADD_PERSON} to graph:map, or run a task that needs no person",
        )


class AmbiguousPersonError(PersonError):
    """Several people, and nothing in the task says which one a step means."""

    def __init__(self, step: str, people: list[str]) -> None:
        names = ", ".join(local_name(iri) for iri in people)
        super().__init__(
            HOME + "Person",
            step,
            people,
            f"is ambiguous for {local_name(step)}: the map has {len(people)} people ({names}) and the task "
            "designates none of them; give the task an input of the class of the one it means (a class "
            "designates the one person stated to be of it and of no narrower class, so give each a class "
            "of their own, e.g. home:Caregiver or a lab's subclass of home:Person)",
        )


class LookAlikePeopleError(PersonError):
    """The person a step means wears the shirt colour of another: the tracker, which finds a person by that
    colour alone, could follow either."""

    def __init__(self, step: str, person: Person, twins: list[str]) -> None:
        self.colour = person.colour
        names = ", ".join(local_name(iri) for iri in twins)
        super().__init__(
            person.iri,
            step,
            [person.iri, *twins],
            f"wears a {person.colour} shirt, as {names} does, and {local_name(step)} finds a person by the colour "
            "of their shirt alone: give each person a home:colourName of their own (and home:rgba to match), "
            "or take the other out of graph:map",
        )


class LookAlikeMarkerError(PersonError):
    """The person a step means wears the colour of a patch of the mobile robot's marker. The tracker takes
    the largest patch of the shirt's colour in its camera's image for the person, and the marker's patch
    passes for one: while the shirt is in view it outweighs the patch, but with the person out of view
    (walked off, hidden) the tracker reports the robot's own marker instead of failing over to another
    camera. ``other`` is the marker (or the robot when the map names no marker individual), ``patch``
    "front" or "rear"."""

    def __init__(self, step: str, person: Person, clash: ShirtClash) -> None:
        self.colour = person.colour
        self.other = clash.other
        self.patch = clash.patch
        super().__init__(
            person.iri,
            step,
            [person.iri],
            f"wears a {person.colour} shirt, the colour of {clash.what}, and {local_name(step)} finds a person by the "
            "largest patch of their shirt's colour: with the person out of its camera's view it would take the "
            "marker for them; give the person a home:colourName (and home:rgba) the marker does not have, or the "
            "marker other colours (home:frontColourName, home:rearColourName)",
        )


@dataclass(frozen=True)
class ShirtClash:
    """Something other than a person in that person's shirt colour, which the tracker may take for them.
    ``kind`` is "marker" (a patch of the mobile robot's marker: a task that tracks the person is refused,
    :class:`LookAlikeMarkerError`) or "object" (an object a ceiling camera sees with the person: said, not
    refused); ``cameras`` the cameras that see both (for the marker, none: it goes where the base goes)."""

    person: str
    colour: str
    kind: str
    other: str
    patch: str = ""
    cameras: tuple[str, ...] = ()

    @property
    def what(self) -> str:
        """The other thing in words: "P3DX01Marker's rear patch", "Cup"."""
        return f"{local_name(self.other)}'s {self.patch} patch" if self.kind == "marker" else local_name(self.other)

    @property
    def said(self) -> str:
        """The clash in one clause, for ``cbrs home`` and the browser."""
        name = local_name(self.person)
        if self.kind == "marker":
            return (
                f"{name} wears {self.colour}, the colour of {self.what}: a task that tracks them is refused (the "
                "tracker would take the marker for them with them out of view)"
            )
        seen = " and ".join(local_name(c) for c in self.cameras)
        return (
            f"{name} wears {self.colour}, as {self.what} is, in the view of {seen}: the tracker takes the largest "
            "patch of the colour, so it could take the object for them with them out of view (said, not refused)"
        )

    def to_dict(self) -> dict[str, object]:
        return {
            "person": self.person,
            "colour": self.colour,
            "kind": self.kind,
            "other": self.other,
            "patch": self.patch or None,
            "cameras": list(self.cameras),
            "said": self.said,
        }


def shirt_clashes(semantic_map: SemanticMap, person: Person | None = None) -> list[ShirtClash]:
    """What besides a person wears their shirt colour (of ``person``, else of each of the map's people):
    a patch of a mobile robot's marker, wherever the base is (it drives to the person, and the cameras that
    track them locate it), and each object that a ceiling camera sees with the person's start (its floor
    view holds both). Colours are compared by name, as the tracker looks for one (home:colourName)."""
    people = [person] if person is not None else [semantic_map.people[iri] for iri in sorted(semantic_map.people)]
    views = _ceiling_views(semantic_map)
    found: list[ShirtClash] = []
    for one in people:
        colour = one.colour.lower()
        if not colour:
            continue
        found.extend(_marker_clashes(semantic_map, one))
        for iri in sorted(semantic_map.objects):
            obj = semantic_map.objects[iri]
            if obj.colour.lower() != colour:
                continue
            cameras = tuple(
                camera
                for camera, corners in views
                if _inside(corners, one.start.x, one.start.y) and _inside(corners, obj.start.x, obj.start.y)
            )
            if cameras:
                found.append(ShirtClash(one.iri, one.colour, "object", iri, cameras=cameras))
    return found


@dataclass(frozen=True)
class PersonCheck:
    """One person of the map: whether a task that tracks, goes to or hands something to them (and names
    them) runs or is refused, and what else wears their colour (:func:`people_check`)."""

    person: Person
    refusal: PersonError | None
    clashes: tuple[ShirtClash, ...]

    def to_dict(self) -> dict[str, object]:
        refused = self.refusal
        return {
            "iri": self.person.iri,
            "name": self.person.name,
            "colour": self.person.colour or None,
            "task": "refused" if refused is not None else "runs",
            "refusal": None if refused is None else {"kind": type(refused).__name__, "message": str(refused)},
            "clashes": [clash.to_dict() for clash in self.clashes],
        }


def people_check(semantic_map: SemanticMap) -> list[PersonCheck]:
    """Each of the map's people, by IRI, with the refusal :func:`person_for` gives a task that names them
    (None: it runs) and the things in their shirt colour: what ``cbrs home`` and ``/home`` say of them."""
    checked = []
    for iri in sorted(semantic_map.people):
        person = semantic_map.people[iri]
        try:
            person_for(semantic_map, "a task that tracks them", [iri])
            refusal = None
        except PersonError as error:
            refusal = error
        checked.append(PersonCheck(person, refusal, tuple(shirt_clashes(semantic_map, person))))
    return checked


def _marker_clashes(semantic_map: SemanticMap, person: Person) -> list[ShirtClash]:
    """The patches of the map's mobile robots' markers in ``person``'s shirt colour."""
    found = []
    for iri in sorted(semantic_map.robots):
        colours = semantic_map.robots[iri].marker_colours or ()
        marker = semantic_map.facts.get(iri, {}).get(HOME + "hasMarker", [iri])[0]
        for patch, worn in zip(("front", "rear"), colours, strict=False):
            if person.colour and worn.lower() == person.colour.lower():
                found.append(ShirtClash(person.iri, person.colour, "marker", marker, patch))
    return found


def _ceiling_views(semantic_map: SemanticMap) -> list[tuple[str, list[tuple[float, float]]]]:
    """The floor each camera that looks straight down sees (the cameras a person is tracked with)."""
    views = []
    for iri in sorted(semantic_map.cameras):
        camera = semantic_map.cameras[iri]
        corners = floor_view(camera) if camera.looks_down else None
        if corners is not None:
            views.append((iri, corners))
    return views


def _inside(corners: list[tuple[float, float]], x: float, y: float) -> bool:
    """Whether (x, y) is in the convex polygon ``corners`` (either winding)."""
    sides = []
    for (ax, ay), (bx, by) in zip(corners, corners[1:] + corners[:1], strict=True):
        sides.append((bx - ax) * (y - ay) - (by - ay) * (x - ax))
    return all(s >= 0 for s in sides) or all(s <= 0 for s in sides)


def person_for(semantic_map: SemanticMap, step: str, designated: Iterable[str] = ()) -> Person:
    """The person ``step`` tracks, drives to or hands something to: the one of the map's people among
    ``designated`` (the things the task's inputs name), else the map's only person. A :class:`PersonError`
    when the map has none, or several and the task names not exactly one, or that person's shirt colour
    is another's or a patch of the mobile robot's marker's: refused rather than guessed, since the robot
    would otherwise serve whoever (or whatever) the camera happened to see first."""
    people = semantic_map.people
    if not people:
        raise NoPersonError(step)
    named = sorted({iri for iri in designated if iri in people})
    if len(named) == 1:
        chosen = people[named[0]]
    elif not named and len(people) == 1:
        chosen = next(iter(people.values()))
    else:
        raise AmbiguousPersonError(step, named or sorted(people))
    twins = sorted(iri for iri, other in people.items() if iri != chosen.iri and _same_shirt(chosen, other))
    if twins:
        raise LookAlikePeopleError(step, chosen, twins)
    markers = _marker_clashes(semantic_map, chosen)
    if markers:
        raise LookAlikeMarkerError(step, chosen, markers[0])
    return chosen


def look_alikes(semantic_map: SemanticMap) -> list[tuple[str, list[str]]]:
    """Each shirt colour worn by more than one of the map's people, with their IRIs: the tracker cannot
    tell them apart, so a task for one of them is refused (:class:`LookAlikePeopleError`)."""
    worn: dict[str, list[str]] = {}
    for iri in sorted(semantic_map.people):
        colour = semantic_map.people[iri].colour
        if colour:
            worn.setdefault(colour.lower(), []).append(iri)
    return [(colour, iris) for colour, iris in sorted(worn.items()) if len(iris) > 1]


def _same_shirt(one: Person, other: Person) -> bool:
    return bool(one.colour) and one.colour.lower() == other.colour.lower()
