"""A picture of the home drawn from the store, before anything runs: the semantic map seen from above.

The only top-down picture of a home was drawn after a simulated run (``cbrs run --record``), which needs
pybullet; a lab building its own home (``cbrs load --graph map --replace``) wants to see what it wrote
first. :func:`draw_home` draws a :class:`SemanticMap` as SVG text by hand (no matplotlib, no pybullet):
rooms, walls, furniture with its top's height, appliances, objects by shape, size, yaw and colour, the
mobile base with its heading and marker, the dual-arm robot with each arm's reach, the people (none, one
or several), each camera and the floor a ceiling camera sees (:mod:`kb.camera_view`, the simulation's
camera model), and docking poses. Where the world graph believes a thing is elsewhere than its start
(after a run), the believed place is drawn too, with an arrow from the start. Each thing is a link to
its page in the browser with a tooltip. :func:`survey` reads the map and checks it as the simulation
would (:func:`kb.home_check.check_home`), so the browser's ``/home`` and ``cbrs home`` say what is wrong
with a home instead of failing. docs/web.md, "The home".
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from html import escape
from urllib.parse import quote

from cbrs.home_canvas import (
    APPLIANCE,
    BASE,
    BELIEF,
    CAMERA_INKS,
    CHAR,
    DOCK,
    FONT,
    FURNITURE,
    INK,
    MARGIN,
    MUTED,
    PERSON_PX,
    ROBOT,
    ROOM_FILLS,
    THING,
    Canvas,
    arrow,
    circle,
    dot,
    grid,
    legend,
    overlap,
    scale_bar,
    svg_attributes,
)
from cbrs.home_things import Kind, others, position, read_kinds
from cbrs.kb.camera_view import floor_view
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.home_check import check_home, undocked_supports
from cbrs.kb.knowledge_base import KnowledgeBase
from cbrs.kb.namespaces import RDFS, shorten
from cbrs.kb.person_choice import look_alikes, shirt_clashes
from cbrs.kb.semantic_map import HOME, Box, MapObject, SemanticMap, Thing, local_name

__all__ = [
    "DEFAULT_WIDTH",
    "MOVED",
    "NO_BASE",
    "NO_ROOMS",
    "SEVERAL_BASES",
    "Entry",
    "HomePicture",
    "HomeSurvey",
    "draw_home",
    "kind_of",
    "resource_link",
    "survey",
]

DEFAULT_WIDTH = 960
"""Pixels across the picture; the height follows the home's shape."""
MOVED = 0.05
"""How far (m) the world graph must believe a thing to be from its start in the map for the picture to
draw it at both places: less is the simulation's settling and a seed's scatter, not a move."""

NO_ROOMS = (
    "The map has no rooms (no home:Room with home:minX, home:maxX, home:minY and home:maxY): there is no "
    "floor to draw, and the simulation cannot build a home from it. Load a home's rooms into graph:map "
    "(docs/tasks.md, 'A home of your own')."
)
"""What the picture of a map without rooms says, above what else the map places (or alone)."""

_PAD = 0.3  # m of floor shown around the outermost thing
_MIN_SPAN = 2.0  # m across and up the picture shows at least: one thing alone is not drawn a metre wide
_NOTICE_LINE = 17  # px between the lines of the picture's notice


def resource_link(iri: str) -> str:
    """The browser's page of ``iri`` (``/resource?iri=``), relative to the server's root."""
    return "/resource?iri=" + quote(iri, safe="")


@dataclass(frozen=True)
class Entry:
    """One thing of the picture, as the table under it lists it."""

    iri: str
    name: str
    kind: str
    classes: tuple[str, ...]
    where: str
    room: str | None = None
    believed: tuple[float, float] | None = None

    def to_dict(self) -> dict[str, object]:
        return {
            "iri": self.iri,
            "name": self.name,
            "kind": self.kind,
            "classes": list(self.classes),
            "where": self.where,
            "room": self.room,
            "believed": list(self.believed) if self.believed else None,
        }


@dataclass(frozen=True)
class HomePicture:
    svg: str
    width: int
    height: int
    entries: tuple[Entry, ...]
    notice: str | None = None
    """What the picture says above the plan instead of drawing it right (:data:`NO_ROOMS`), or None."""


@dataclass(frozen=True)
class HomeSurvey:
    """What the store says of the home: the map (None when it cannot be read), the problem that stops
    the simulation building it (unreadable, or refused by the home check), and the world graph's
    believed positions (x, y) by IRI."""

    semantic_map: SemanticMap | None
    problem: KnowledgeBaseError | None
    believed: dict[str, tuple[float, float]] = field(default_factory=dict)
    kinds: dict[str, Kind] = field(default_factory=dict)
    """What each physical thing of the map outside the reader's groups is, and each water dispenser's kind
    (:func:`cbrs.home_things.read_kinds`): the things the picture draws as they are, grouped by kind."""

    def picture(self, width: int = DEFAULT_WIDTH, link: Callable[[str], str] | None = None) -> HomePicture:
        """:func:`draw_home` of this survey's map, with where things are believed to be and their kinds."""
        if self.semantic_map is None:
            raise ValueError("the map could not be read: there is nothing to draw")
        return draw_home(self.semantic_map, self.believed, width, link or resource_link, kinds=self.kinds)

    @property
    def verdict(self) -> str:
        if self.semantic_map is None:
            return "unreadable"
        return "refused" if self.problem is not None else "ok"

    def counts(self) -> dict[str, int]:
        smap = self.semantic_map
        if smap is None:
            return {}
        return {
            "rooms": len(smap.rooms & smap.things.keys()),
            "walls": len(smap.walls & smap.things.keys()),
            "furniture": len(smap.furniture & smap.things.keys()),
            "objects": len(smap.objects),
            "mobile robots": len(smap.robots),
            "stationary robots": len(_bodies(smap)),  # a torso on the floor, whatever its arms
            "arms": len(smap.arms),
            "people": len(smap.people),
            "cameras": len(smap.cameras),
            "docking poses": sum(1 for thing in smap.things.values() if thing.dock is not None),
        } | {plural: len(iris) for plural, (_, iris) in self._kind_groups().items()}

    def _kind_groups(self) -> dict[str, tuple[str, list[str]]]:
        """The things of :attr:`kinds` by kind, as (singular, things) by plural, sorted by name."""
        groups: dict[str, tuple[str, list[str]]] = {}
        for iri in sorted(self.kinds):
            kind = self.kinds[iri]
            groups.setdefault(kind.plural, (kind.name, []))[1].append(iri)
        return dict(sorted(groups.items(), key=lambda item: item[1][0]))

    def counted(self) -> list[str]:
        """:meth:`counts` in words: "3 rooms", "1 piece of furniture", "1 person"."""
        singular = {plural: name for plural, (name, _) in self._kind_groups().items()}
        return [_counted(n, name, singular.get(name)) for name, n in self.counts().items()]

    def warnings(self) -> list[str]:
        """What the home check lets through but a task may trip on, in words: furniture that holds objects
        and has no docking pose (kb.home_check.undocked_supports)."""
        if self.semantic_map is None:
            return []
        return [undocked.said for undocked in undocked_supports(self.semantic_map)]

    def people(self) -> str | None:
        """Who lives in the home and what that allows, in words (None when the map cannot be read): a home
        of nobody runs only the tasks that need no person, a home of several needs the task to name its
        person, and people in one shirt colour cannot be told apart by the tracker, nor a shirt from the
        marker's patch of its colour (kb.home_check)."""
        smap = self.semantic_map
        if smap is None:
            return None
        people = [smap.people[iri] for iri in sorted(smap.people)]
        if not people:
            return "none: a task that tracks, goes to or hands something to a person is refused; the others run"
        said = ", ".join(f"{person.name} ({person.colour or 'no'} shirt)" for person in people)
        if len(people) > 1:
            said += "; a task for one names them (an input of a class of theirs), else it is refused as ambiguous"
        for colour, iris in look_alikes(smap):
            names = " and ".join(local_name(iri) for iri in iris)
            said += f"; {names} wear {colour}: the tracker cannot tell them apart, so a task for either is refused"
        for clash in shirt_clashes(smap):  # the marker's colours, objects in a camera's view with them
            said += f"; {clash.said}"
        return said

    def bases(self) -> str | None:
        """The home's mobile bases and what that allows, in words (None when the map cannot be read): a home
        with none runs the tasks of the arms, the cameras and the sensors, and refuses before the world is
        built a task that drives a base, loads its platform or finds its marker (``sim.run_checks.without_base``);
        one of several drives the base its plan works (``sim.run_checks.base_for``; docs/simulation.md, "A home
        with no mobile base")."""
        smap = self.semantic_map
        if smap is None:
            return None
        if not smap.robots:
            return NO_BASE
        said = ", ".join(local_name(iri) for iri in sorted(smap.robots))
        if len(smap.robots) > 1:
            said += f"; {SEVERAL_BASES}"
        return said


NO_BASE = (
    "none: a task that drives the base, loads its platform or finds its marker is refused before the world is "
    "built; the others run (the arms', the cameras', the sensors')"
)
"""What ``cbrs home`` says of a home with no mobile base."""
SEVERAL_BASES = (
    "a run drives the base its plan works (the device of its drive, the marker colours a locator is given); "
    "a plan that works two, or names none, is refused before anything moves"
)
"""What ``cbrs home`` says of a home with several mobile bases, after their names."""

_ONE = {"people": "person", "furniture": "piece of furniture"}
_MANY = {"furniture": "pieces of furniture"}


def _counted(count: int, name: str, one: str | None = None) -> str:
    if count == 1:
        return f"1 {one or _ONE.get(name, name.removesuffix('s'))}"
    return f"{count} {_MANY.get(name, name)}"


def survey(kb: KnowledgeBase) -> HomeSurvey:
    """Read the map and check it as the simulation builds the home; a map that cannot be read or built
    is reported, not raised, so that its picture or its message can be shown."""
    try:
        smap = SemanticMap.read(kb)
    except KnowledgeBaseError as error:
        return HomeSurvey(None, error)
    believed = {
        row["thing"].value: (float(row["x"].value), float(row["y"].value)) for row in kb.select("world_positions")
    }
    kinds = read_kinds(kb, smap, [*others(smap), *smap.dispensers])
    try:
        check_home(smap)
    except KnowledgeBaseError as error:
        return HomeSurvey(smap, error, believed, kinds)
    return HomeSurvey(smap, None, believed, kinds)


def kind_of(kinds: Mapping[str, Kind], iri: str, default: str) -> str:
    """The name of ``iri``'s kind, ``default`` when the store gives none."""
    kind = kinds.get(iri)
    return kind.name if kind is not None else default


# -- the drawing ------------------------------------------------------------------------------------


def _linked(href: str, title: str, body: list[str], kind: str) -> str:
    """A thing of the picture: its shapes inside a link to its page, its tooltip the link's title."""
    return (
        f'<a href="{escape(href)}" class="home-{kind}"><title>{escape(title, quote=False)}</title>'
        + "".join(body)
        + "</a>"
    )


def draw_home(
    semantic_map: SemanticMap,
    believed: dict[str, tuple[float, float]] | None = None,
    width: int = DEFAULT_WIDTH,
    link: Callable[[str], str] = resource_link,
    moved: float = MOVED,
    kinds: Mapping[str, Kind] | None = None,
) -> HomePicture:
    """The home from above as SVG text, ``width`` pixels across, and the things drawn; ``believed``
    gives where the world graph believes things are (x, y by IRI), drawn where they are ``moved`` or
    more from their start; ``link`` gives each thing's address; ``kinds`` what the physical things outside
    the reader's groups are (:attr:`HomeSurvey.kinds`), each drawn by its extent or at its position. The
    entries come grouped by kind, in the order each kind is first drawn."""
    smap, believed, kinds = semantic_map, believed or {}, kinds or {}
    placed = {iri: position(smap, iri) for iri in kinds if iri not in smap.things and iri not in smap.dispensers}
    extent = _extent(smap, believed, [(p[0], p[1]) for p in placed.values() if p is not None])
    notice = None if smap.rooms & smap.things.keys() else NO_ROOMS
    if extent is None:  # nothing placed at all: the notice alone, not an empty grid
        return _notice_only(notice or NO_ROOMS, width)
    lines = _wrapped(notice, width)
    scale = (width - 2 * MARGIN) / (extent.max_x - extent.min_x)
    canvas = Canvas(extent, scale, top=16.0 + len(lines) * _NOTICE_LINE + (12 if lines else 0))
    plan_height = (extent.max_y - extent.min_y) * scale
    entries: list[Entry] = []
    solid = smap.furniture | {d.iri for d in smap.dispensers.values()} | {t.iri for t in _bodies(smap)}
    solid |= {iri for iri in kinds if iri in smap.things}
    for iri in sorted(solid & smap.things.keys()):  # labels keep off them, the rooms' too
        canvas.block_box(smap.things[iri].box)
    layers: list[Iterator[str]] = [
        grid(canvas),
        _rooms(canvas, smap, link, entries),
        _walls(canvas, smap, link, entries),
        _cameras_views(canvas, smap, link),
        _furniture(canvas, smap, link, entries, kinds),
        _other_things(canvas, smap, link, entries, kinds, placed),
        _robot_bodies(canvas, smap, link, entries),
        _docks(canvas, smap, link, entries),
        _objects(canvas, smap, link, entries, believed, moved),
        _mobile_robots(canvas, smap, link, entries, believed, moved),
        _people(canvas, smap, link, entries, believed, moved),
        _cameras(canvas, smap, link, entries),
    ]
    body = [part for layer in layers for part in layer]
    legend_top = canvas.top + plan_height + 84
    key, legend_height = legend(canvas, legend_top, width, things=any(e.iri in kinds for e in entries))
    height = int(legend_top + legend_height + 8)
    rooms = ", ".join(_name(smap, iri) for iri in sorted(smap.rooms) if iri in smap.things)
    svg = "".join(
        [
            f'<svg xmlns="http://www.w3.org/2000/svg" class="home-plan" width="{width}" height="{height}" '
            f'viewBox="0 0 {width} {height}" font-family="{FONT}" aria-labelledby="home-plan-title home-plan-desc">',
            '<title id="home-plan-title">The home from above, from the semantic map</title>',
            f'<desc id="home-plan-desc">{escape(_description(smap, rooms), quote=False)}</desc>',
            _defs(canvas),
            f'<rect width="{width}" height="{height}" fill="#ffffff"/>',
            *_notice(canvas, lines),
            *body,
            *scale_bar(canvas, canvas.top + plan_height + 44),
            *key,
            "</svg>",
        ]
    )
    return HomePicture(svg, width, height, _grouped(entries), notice)


def _grouped(entries: list[Entry]) -> tuple[Entry, ...]:
    """``entries`` by kind, each kind where it is first drawn, in drawing order within it: a lab's lamp
    beside the water dispenser, both appliances."""
    order: dict[str, int] = {}
    for entry in entries:
        order.setdefault(entry.kind, len(order))
    return tuple(sorted(entries, key=lambda entry: order[entry.kind]))


def _wrapped(notice: str | None, width: int) -> list[str]:
    """The notice in lines that fit the picture's width (SVG text does not wrap)."""
    if notice is None:
        return []
    return textwrap.wrap(notice, max(20, int((width - 2 * MARGIN) / (CHAR * 13))))


def _notice(canvas: Canvas, lines: list[str]) -> Iterator[str]:
    for index, line in enumerate(lines):
        y = 16.0 + (index + 1) * _NOTICE_LINE
        yield canvas.text(canvas.left, y, line, 13, fill=BELIEF, **{"class": "home-notice"})


def _notice_only(notice: str, width: int) -> HomePicture:
    """The picture of a map that places nothing: its notice, and no plan."""
    lines = _wrapped(notice, width)
    height = int(16 + (len(lines) + 1) * _NOTICE_LINE + 8)
    canvas = Canvas(Box(0.0, 1.0, 0.0, 1.0), 1.0)
    svg = "".join(
        [
            f'<svg xmlns="http://www.w3.org/2000/svg" class="home-plan" width="{width}" height="{height}" '
            f'viewBox="0 0 {width} {height}" font-family="{FONT}" aria-labelledby="home-plan-title home-plan-desc">',
            '<title id="home-plan-title">The home from above, from the semantic map</title>',
            f'<desc id="home-plan-desc">{escape(notice, quote=False)}</desc>',
            f'<rect width="{width}" height="{height}" fill="#ffffff"/>',
            *_notice(canvas, lines),
            "</svg>",
        ]
    )
    return HomePicture(svg, width, height, (), notice)


def _description(smap: SemanticMap, rooms: str) -> str:
    return (
        f"{len(smap.rooms)} rooms ({rooms}), {len(smap.furniture)} pieces of furniture, {len(smap.objects)} objects, "
        f"{len(smap.robots) + len(_bodies(smap))} robots, {len(smap.people)} people and {len(smap.cameras)} cameras; "
        "x to the east (right), y to the north (up), in metres."
    )


def _defs(canvas: Canvas) -> str:
    e = canvas.extent
    return (
        "<defs>"
        f'<clipPath id="home-plan-floor">{canvas.rect(e)}</clipPath>'
        '<marker id="home-plan-arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" '
        f'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="{BELIEF}"/></marker>'
        "</defs>"
    )


def _extent(
    smap: SemanticMap, believed: dict[str, tuple[float, float]], placed: list[tuple[float, float]]
) -> Box | None:
    """The box around every thing drawn (not around the cameras' views), with some floor around it, and
    at least :data:`_MIN_SPAN` across and up; None when the map places nothing. ``placed``: the positions
    of the things drawn by their position alone (:func:`_other_things`)."""
    xs: list[float] = []
    ys: list[float] = []
    for thing in smap.things.values():
        xs += [thing.box.min_x, thing.box.max_x]
        ys += [thing.box.min_y, thing.box.max_y]
    points = [(o.start.x, o.start.y) for o in smap.objects.values()]
    points += [(r.start.x, r.start.y) for r in smap.robots.values()]
    points += [(p.start.x, p.start.y) for p in smap.people.values()]
    points += [(c.position[0], c.position[1]) for c in smap.cameras.values()]
    points += [(a.mount[0], a.mount[1]) for a in smap.arms.values()]
    points += [(t.dock.x, t.dock.y) for t in smap.things.values() if t.dock is not None]
    points += placed
    points += [where for iri, where in believed.items() if _drawn_at(smap, iri) is not None]
    xs += [x for x, _ in points]
    ys += [y for _, y in points]
    if not xs:
        return None
    x0, x1 = _spanned(min(xs) - _PAD, max(xs) + _PAD)
    y0, y1 = _spanned(min(ys) - _PAD, max(ys) + _PAD)
    return Box(x0, x1, y0, y1)


def _spanned(low: float, high: float) -> tuple[float, float]:
    """``low`` to ``high`` widened about its middle to :data:`_MIN_SPAN` when it is narrower."""
    grow = max(0.0, _MIN_SPAN - (high - low)) / 2
    return low - grow, high + grow


def _drawn_at(smap: SemanticMap, iri: str) -> tuple[float, float] | None:
    """The start of a thing that moves (an object, a mobile robot, a person), None for any other."""
    for group in (smap.objects, smap.robots, smap.people):
        if iri in group:
            start = group[iri].start
            return start.x, start.y
    return None


def _name(smap: SemanticMap, iri: str) -> str:
    return local_name(iri)


def _label(smap: SemanticMap, iri: str) -> str:
    """The thing's name, with its rdfs:label where the map gives one."""
    labels = smap.facts.get(iri, {}).get(RDFS + "label", [])
    return f"{local_name(iri)} ({labels[0]})" if labels else local_name(iri)


def _classes(smap: SemanticMap, iri: str) -> tuple[str, ...]:
    return tuple(shorten(t) for t in smap.types.get(iri, ()))


def _room_of(smap: SemanticMap, x: float, y: float) -> str | None:
    for iri in sorted(smap.rooms):
        thing = smap.things.get(iri)
        if thing is not None and thing.box.contains_xy(x, y):
            return local_name(iri)
    return None


def _span(box: Box) -> str:
    return f"x {box.min_x:g} to {box.max_x:g}, y {box.min_y:g} to {box.max_y:g}"


def _bodies(smap: SemanticMap) -> list[Thing]:
    """The robots with a body of their own on the floor (the dual-arm robot's torso)."""
    return [smap.things[iri] for iri in sorted(smap.bodies) if iri in smap.things and iri not in smap.robots]


def _rooms(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry]) -> Iterator[str]:
    for index, iri in enumerate(sorted(iri for iri in smap.rooms if iri in smap.things)):
        box = smap.things[iri].box
        classes = _classes(smap, iri)
        kind = ", ".join(classes) or "room"
        x, y, anchor = _room_corner(canvas, box, max(CHAR * 14 * len(local_name(iri)), CHAR * 11 * len(kind)))
        body = [
            canvas.rect(box, fill=ROOM_FILLS[index % len(ROOM_FILLS)], stroke="#9aa7b8", stroke_width=1),
            canvas.text(x, y, local_name(iri), 14, font_weight="bold", text_anchor=anchor),
            canvas.text(x, y + 15, kind, 11, fill=MUTED, text_anchor=anchor),
        ]
        yield _linked(link(iri), f"{_label(smap, iri)}: {kind}, {_span(box)}", body, "room")
        entries.append(Entry(iri, local_name(iri), "room", classes, _span(box)))


def _room_corner(canvas: Canvas, box: Box, width: float) -> tuple[float, float, str]:
    """Where a room's name and class go: the first corner of the room, from its north-west one, where
    they cover no furniture or robot (the north-west one when every corner is taken)."""
    left, right = canvas.x(box.min_x) + 8, canvas.x(box.max_x) - 8
    top, bottom = canvas.y(box.max_y) + 20, canvas.y(box.min_y) - 23
    spots = ((left, top, "start"), (right, top, "end"), (left, bottom, "start"), (right, bottom, "end"))
    for x, y, anchor in spots:
        x0 = x if anchor == "start" else x - width
        if not any(overlap((x0, y - 14, x0 + width, y + 18), taken) for taken in canvas.taken):
            canvas.block(x0, y - 14, x0 + width, y + 18)
            return x, y, anchor
    return spots[0]


def _walls(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry]) -> Iterator[str]:
    for iri in sorted(iri for iri in smap.walls if iri in smap.things):
        box = smap.things[iri].box
        where = f"{_span(box)}, {box.max_z - box.min_z:g} m high"
        yield _linked(link(iri), f"{_label(smap, iri)}: wall, {where}", [canvas.rect(box, fill="#4b5563")], "wall")
        entries.append(Entry(iri, local_name(iri), "wall", _classes(smap, iri), where))


def _furniture(
    canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry], kinds: Mapping[str, Kind]
) -> Iterator[str]:
    appliances = {d.iri for d in smap.dispensers.values()}
    drawn = sorted(
        (smap.furniture | appliances) & smap.things.keys(), key=lambda iri: (smap.things[iri].box.max_z, iri)
    )
    for iri in drawn:  # lowest first: what stands on a piece of furniture is drawn over it
        thing = smap.things[iri]
        box = thing.box
        appliance = iri in appliances and iri not in smap.furniture
        fill, stroke = APPLIANCE if appliance else FURNITURE
        where = f"{_span(box)}, top at {box.max_z:g} m"
        body = [canvas.rect(box, fill=fill, stroke=stroke, stroke_width=1.2)]
        if appliance:
            outlet = smap.dispensers[iri].outlet
            body.append(dot(canvas, outlet[0], outlet[1], 2.5, "#0e7490"))
            where += f", water leaves at ({outlet[0]:g}, {outlet[1]:g}, {outlet[2]:g})"
        else:
            cx = canvas.x((box.min_x + box.max_x) / 2)
            top = canvas.y(box.max_y)
            body.append(canvas.text(cx, top + 14, local_name(iri), 11, text_anchor="middle", font_weight="bold"))
            body.append(canvas.text(cx, top + 27, f"top {box.max_z:g} m", 10, fill=MUTED, text_anchor="middle"))
        style = "appliance" if appliance else "furniture"
        kind = kind_of(kinds, iri, style) if appliance else style
        support = smap.facts.get(iri, {}).get(HOME + "isLocatedOn", [])
        if support:
            where += f", on {local_name(support[0])}"
        yield _linked(link(iri), f"{_label(smap, iri)}: {kind}, {where}", body, style)
        centre = box.centre
        entries.append(Entry(iri, local_name(iri), kind, _classes(smap, iri), where, _room_of(smap, *centre[:2])))


def _other_things(
    canvas: Canvas,
    smap: SemanticMap,
    link: Callable[[str], str],
    entries: list[Entry],
    kinds: Mapping[str, Kind],
    placed: Mapping[str, tuple[float, float, float | None] | None],
) -> Iterator[str]:
    """The physical things of the map outside the reader's groups (:mod:`cbrs.home_things`): a box by its
    extent, lowest first, else a diamond at its position, each with its name (its kind in its tooltip); a
    part of a water dispenser (its lever, its spout) unnamed, its tooltip saying whose part it is. A thing
    with neither a box nor a single number for x and y is listed, not drawn."""
    parts = {part: d.iri for d in smap.dispensers.values() for part in (d.lever.iri, d.spout.iri)}
    boxed = sorted(
        (iri for iri in kinds if iri in smap.things and iri not in smap.dispensers),
        key=lambda iri: (smap.things[iri].box.max_z, iri),
    )
    for iri in boxed:
        box = smap.things[iri].box
        kind = kinds[iri].name
        where = f"{_span(box)}, top at {box.max_z:g} m"
        least = 3.0 / canvas.scale  # a tap lever 2 cm across stays visible
        shown = Box(box.min_x, max(box.max_x, box.min_x + least), box.min_y, max(box.max_y, box.min_y + least))
        whole = parts.get(iri)
        fill = "none" if whole is not None else THING[0]  # a spout's outline, the outlet's dot seen through it
        body = [canvas.rect(shown, fill=fill, stroke=THING[1], stroke_width=1)]
        if whole is not None:
            where += f", part of {local_name(whole)}"
        else:
            cx, cy = canvas.x(box.centre[0]), canvas.y(box.centre[1])
            half = (box.max_y - box.min_y) / 2 * canvas.scale
            body.append(canvas.label(cx, cy, half + 1, local_name(iri), 10, font_weight="bold", fill=THING[1]))
        yield _linked(link(iri), f"{_label(smap, iri)}: {kind}, {where}", body, "thing")
        entries.append(Entry(iri, local_name(iri), kind, _classes(smap, iri), where, _room_of(smap, *box.centre[:2])))
    for iri in sorted(placed):
        kind, at = kinds[iri].name, placed[iri]
        if at is None:
            entries.append(Entry(iri, local_name(iri), kind, _classes(smap, iri), "no single home:x and home:y"))
            continue
        x, y, z = at
        px, py = canvas.x(x), canvas.y(y)
        where = f"at ({x:g}, {y:g}" + (f", {z:g})" if z is not None else ")")
        body = [
            canvas.polygon(
                [
                    (x + 6 / canvas.scale, y),
                    (x, y + 6 / canvas.scale),
                    (x - 6 / canvas.scale, y),
                    (x, y - 6 / canvas.scale),
                ],
                fill=THING[0],
                stroke=THING[1],
                stroke_width=1.5,
            ),
            canvas.label(px, py, 7, local_name(iri), 10, font_weight="bold", fill=THING[1]),
        ]
        canvas.block(px - 6, py - 6, px + 6, py + 6)
        yield _linked(link(iri), f"{_label(smap, iri)}: {kind}, {where}", body, "thing")
        entries.append(Entry(iri, local_name(iri), kind, _classes(smap, iri), where, _room_of(smap, x, y)))


def _robot_bodies(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry]) -> Iterator[str]:
    arms_of: dict[str, list[str]] = {}
    for arm in smap.arms.values():
        arms_of.setdefault(arm.robot, []).append(arm.iri)
    for thing in _bodies(smap):
        box = thing.box
        cx, cy = canvas.x(box.centre[0]), canvas.y(box.centre[1])
        half = (box.max_y - box.min_y) / 2 * canvas.scale
        body = [
            canvas.rect(box, fill=ROBOT[0], stroke=ROBOT[1], stroke_width=1.5),
            canvas.label(cx, cy, half + 1, thing.name, 11, font_weight="bold", fill=ROBOT[1]),
        ]
        where = f"{_span(box)}, {box.max_z:g} m high"
        yield _linked(link(thing.iri), f"{_label(smap, thing.iri)}: robot, {where}", body, "robot")
        entries.append(
            Entry(thing.iri, thing.name, "robot", _classes(smap, thing.iri), where, _room_of(smap, *box.centre[:2]))
        )
    for iri in sorted(smap.arms):
        arm = smap.arms[iri]
        mx, my, mz = arm.mount
        r = arm.reach * canvas.scale
        tip = (mx + 0.12 * math.cos(arm.yaw), my + 0.12 * math.sin(arm.yaw))
        body = [
            f'<circle cx="{canvas.x(mx):.1f}" cy="{canvas.y(my):.1f}" r="{r:.1f}" fill="{ROBOT[1]}" '
            f'fill-opacity="0.05" stroke="{ROBOT[1]}" stroke-width="1" stroke-dasharray="5 4"/>',
            f'<line x1="{canvas.x(mx):.1f}" y1="{canvas.y(my):.1f}" x2="{canvas.x(tip[0]):.1f}" '
            f'y2="{canvas.y(tip[1]):.1f}" stroke="{ROBOT[1]}" stroke-width="2"/>',
            dot(canvas, mx, my, 4, ROBOT[1]),
            canvas.text(
                canvas.x(mx - 0.1 * math.cos(arm.yaw)),
                canvas.y(my - 0.1 * math.sin(arm.yaw)) + 3.5,
                arm.side[:1].upper(),
                9,
                text_anchor="middle",
                fill=ROBOT[1],
                font_weight="bold",
            ),
        ]
        where = f"mounted at ({mx:g}, {my:g}, {mz:g}), reaches {arm.reach:g} m"
        title = f"{_label(smap, iri)}: {arm.side} arm of {local_name(arm.robot)}, {where}"
        yield _linked(link(iri), title, body, "arm")
        entries.append(Entry(iri, local_name(iri), "arm", _classes(smap, iri), where, _room_of(smap, mx, my)))


def _docks(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry]) -> Iterator[str]:
    for iri in sorted(smap.things):
        dock = smap.things[iri].dock
        if dock is None:
            continue
        dock_iri = smap.facts.get(iri, {}).get(HOME + "dockingPose", [iri])[0]
        body = [arrow(canvas, dock.x, dock.y, dock.yaw, 0.32, DOCK)]
        where = f"({dock.x:g}, {dock.y:g}), heading {math.degrees(dock.yaw):.0f}°"
        title = f"{_label(smap, dock_iri)}: where the mobile base parks at {local_name(iri)}, {where}"
        yield _linked(link(dock_iri), title, body, "dock")
        entries.append(
            Entry(
                dock_iri,
                local_name(dock_iri),
                "docking pose",
                _classes(smap, dock_iri),
                where,
                _room_of(smap, dock.x, dock.y),
            )
        )


def _objects(
    canvas: Canvas,
    smap: SemanticMap,
    link: Callable[[str], str],
    entries: list[Entry],
    believed: dict[str, tuple[float, float]],
    moved: float,
) -> Iterator[str]:
    for iri in sorted(smap.objects):
        obj = smap.objects[iri]
        x, y = obj.start.x, obj.start.y
        fill, opacity = _colour(obj.rgba)
        body = [
            _object_shape(
                canvas, obj, x, y, {"fill": fill, "fill_opacity": opacity, "stroke": INK, "stroke_width": 0.8}
            )
        ]
        body.append(canvas.label(canvas.x(x), canvas.y(y), max(obj.size[:2]) / 2 * canvas.scale + 2, obj.name, 10))
        size = " x ".join(f"{s * 100:g}" for s in obj.size)
        where = f"({x:g}, {y:g})" + (f" on {local_name(obj.support)}" if obj.support else "")
        kinds = ", ".join(_classes(smap, iri))
        title = f"{_label(smap, iri)}: {kinds}, {obj.shape} {size} cm, {obj.colour or 'no colour'}, {where}"
        there = _elsewhere(believed, iri, x, y, moved)
        if there is not None:
            ghost = _object_shape(canvas, obj, there[0], there[1], _GHOST)
            body += _belief(canvas, (x, y), there, [ghost], max(obj.size[:2]) / 2 * canvas.scale)
            title += f"; believed at ({there[0]:.2f}, {there[1]:.2f})"
        yield _linked(link(iri), title, body, "object")
        entries.append(Entry(iri, obj.name, "object", _classes(smap, iri), where, _room_of(smap, x, y), there))


_GHOST: dict[str, object] = {"fill": "none", "stroke": BELIEF, "stroke_width": 1.5, "stroke_dasharray": "3 2"}


def _object_shape(canvas: Canvas, obj: MapObject, x: float, y: float, attributes: dict[str, object]) -> str:
    """An object's footprint at (``x``, ``y``): a cylinder's circle, a box's rectangle turned by its yaw;
    at least 3 px across, so that a pen stays visible."""
    if obj.shape == "cylinder":
        r = max(obj.size[0] / 2 * canvas.scale, 2.0)
        return f'<circle cx="{canvas.x(x):.1f}" cy="{canvas.y(y):.1f}" r="{r:.1f}"{svg_attributes(attributes)}/>'
    least = 3.0 / canvas.scale
    length, width = max(obj.size[0], least), max(obj.size[1], least)
    return canvas.polygon(_turned(x, y, obj.start.yaw, length, width), **attributes)


def _turned(x: float, y: float, yaw: float, length: float, width: float) -> list[tuple[float, float]]:
    c, s = math.cos(yaw), math.sin(yaw)
    half = ((length / 2, width / 2), (-length / 2, width / 2), (-length / 2, -width / 2), (length / 2, -width / 2))
    return [(x + c * u - s * v, y + s * u + c * v) for u, v in half]


def _mobile_robots(
    canvas: Canvas,
    smap: SemanticMap,
    link: Callable[[str], str],
    entries: list[Entry],
    believed: dict[str, tuple[float, float]],
    moved: float,
) -> Iterator[str]:
    for iri in sorted(smap.robots):
        robot = smap.robots[iri]
        x, y, yaw = robot.start.x, robot.start.y, robot.start.yaw
        length, width = robot.footprint
        body = [canvas.polygon(_turned(x, y, yaw, length, width), fill=BASE[0], stroke=BASE[1], stroke_width=1.5)]
        if robot.marker is not None:
            for sign, colour in ((1, robot.marker.front), (-1, robot.marker.rear)):
                cx = x + sign * robot.marker.separation / 2 * math.cos(yaw)
                cy = y + sign * robot.marker.separation / 2 * math.sin(yaw)
                patch = _turned(cx, cy, yaw, *robot.marker.patch)
                body.append(canvas.polygon(patch, fill=_css_colour(colour), stroke=BASE[1], stroke_width=0.5))
        body.append(arrow(canvas, x, y, yaw, length * 0.9, "#ffffff", stroke_width=2.5))
        reach = math.hypot(length, width) / 2 * canvas.scale
        body.append(canvas.label(canvas.x(x), canvas.y(y), reach + 2, robot.name, 11, font_weight="bold"))
        canvas.block(canvas.x(x) - reach, canvas.y(y) - reach, canvas.x(x) + reach, canvas.y(y) + reach)
        where = f"starts at ({x:g}, {y:g}), heading {math.degrees(yaw):.0f}°, {length:g} x {width:g} m"
        if robot.platform_height is not None:
            where += f", platform at {robot.platform_height:g} m"
        title = f"{_label(smap, iri)}: mobile robot, {where}"
        there = _elsewhere(believed, iri, x, y, moved)
        if there is not None:
            ghost = circle(canvas.x(there[0]), canvas.y(there[1]), reach, **_GHOST)  # the world graph gives no heading
            body += _belief(canvas, (x, y), there, [ghost], reach)
            title += f"; believed at ({there[0]:.2f}, {there[1]:.2f})"
        yield _linked(link(iri), title, body, "base")
        entries.append(Entry(iri, robot.name, "mobile robot", _classes(smap, iri), where, _room_of(smap, x, y), there))


def _people(
    canvas: Canvas,
    smap: SemanticMap,
    link: Callable[[str], str],
    entries: list[Entry],
    believed: dict[str, tuple[float, float]],
    moved: float,
) -> Iterator[str]:
    for iri in sorted(smap.people):
        person = smap.people[iri]
        x, y, yaw = person.start.x, person.start.y, person.start.yaw
        fill, _ = _colour(person.rgba)
        nose = (canvas.x(x) + 1.6 * PERSON_PX * math.cos(yaw), canvas.y(y) - 1.6 * PERSON_PX * math.sin(yaw))
        body = [
            f'<line x1="{canvas.x(x):.1f}" y1="{canvas.y(y):.1f}" x2="{nose[0]:.1f}" y2="{nose[1]:.1f}" '
            f'stroke="{INK}" stroke-width="2"/>',
            circle(canvas.x(x), canvas.y(y), PERSON_PX, fill=fill, stroke=INK, stroke_width=1.5),
            circle(canvas.x(x), canvas.y(y), PERSON_PX / 2.4, fill="#f2d2b6", stroke=INK, stroke_width=1),
            canvas.label(canvas.x(x), canvas.y(y), PERSON_PX + 2, person.name, 11, font_weight="bold"),
        ]
        canvas.block(canvas.x(x) - PERSON_PX, canvas.y(y) - PERSON_PX, canvas.x(x) + PERSON_PX, canvas.y(y) + PERSON_PX)
        where = f"starts at ({x:g}, {y:g}), facing {math.degrees(yaw):.0f}°, {person.colour or 'no'} shirt"
        twins = [local_name(other) for _, iris in look_alikes(smap) if iri in iris for other in iris if other != iri]
        if twins:
            where += f" as {' and '.join(twins)}'s (the tracker cannot tell them apart)"
        title = f"{_label(smap, iri)}: person, {where}"
        there = _elsewhere(believed, iri, x, y, moved)
        if there is not None:
            ghost = circle(canvas.x(there[0]), canvas.y(there[1]), PERSON_PX, **_GHOST)
            body += _belief(canvas, (x, y), there, [ghost], PERSON_PX)
            title += f"; believed at ({there[0]:.2f}, {there[1]:.2f})"
        yield _linked(link(iri), title, body, "person")
        entries.append(Entry(iri, person.name, "person", _classes(smap, iri), where, _room_of(smap, x, y), there))


def _camera_ink(index: int) -> str:
    return CAMERA_INKS[index % len(CAMERA_INKS)]


def _cameras_views(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str]) -> Iterator[str]:
    """The floor each camera looking down sees, under everything but the rooms and walls."""
    for index, iri in enumerate(sorted(smap.cameras)):
        camera = smap.cameras[iri]
        corners = floor_view(camera)
        if corners is None or not camera.looks_down:
            continue
        ink = _camera_ink(index)
        shape = canvas.polygon(
            corners,
            fill="none",
            stroke=ink,
            stroke_width=2,
            stroke_dasharray="8 5",
            clip_path="url(#home-plan-floor)",
        )
        xs, ys = [c[0] for c in corners], [c[1] for c in corners]
        title = (
            f"what {camera.name} sees of the floor: x {min(xs):.2f} to {max(xs):.2f}, y {min(ys):.2f} to {max(ys):.2f}"
        )
        yield _linked(link(iri), title, [shape], "camera-view")


def _cameras(canvas: Canvas, smap: SemanticMap, link: Callable[[str], str], entries: list[Entry]) -> Iterator[str]:
    for index, iri in enumerate(sorted(smap.cameras)):
        camera = smap.cameras[iri]
        x, y, z = camera.position
        ink = _camera_ink(index) if camera.looks_down else ROBOT[1]
        px, py = canvas.x(x), canvas.y(y)
        body = [
            f'<rect x="{px - 7:.1f}" y="{py - 6:.1f}" width="14" height="12" rx="2" fill="{ink}" '
            'stroke="#ffffff" stroke-width="1"/>',
            f'<circle cx="{px:.1f}" cy="{py:.1f}" r="3.2" fill="#ffffff"/>',
        ]
        if not camera.looks_down:  # which way it looks, flat on the floor plan
            dx, dy = math.cos(camera.yaw), math.sin(camera.yaw)
            body.insert(
                0,
                f'<line x1="{px:.1f}" y1="{py:.1f}" x2="{px + 22 * dx:.1f}" y2="{py - 22 * dy:.1f}" '
                f'stroke="{ink}" stroke-width="2"/>',
            )
        if camera.mount is None:  # one on a robot is named in its tooltip: the robot's own label is there
            body.append(canvas.label(px, py, 8, camera.name, 11, fill=ink, font_weight="bold"))
            canvas.block(px - 7, py - 6, px + 7, py + 6)
        corners = floor_view(camera)
        where = f"at ({x:g}, {y:g}, {z:g}), field of view {camera.fov:g}°"
        if camera.looks_down:
            where += ", looking straight down"
            if corners is not None:
                xs, ys = [c[0] for c in corners], [c[1] for c in corners]
                where += f", sees the floor x {min(xs):.2f} to {max(xs):.2f}, y {min(ys):.2f} to {max(ys):.2f}"
            else:
                where += ", too high for its range to reach the floor"
        if camera.mount:
            where += f", on {local_name(camera.mount)}"
        yield _linked(link(iri), f"{_label(smap, iri)}: camera {where}", body, "camera")
        entries.append(Entry(iri, camera.name, "camera", _classes(smap, iri), where, _room_of(smap, x, y)))


def _elsewhere(
    believed: dict[str, tuple[float, float]], iri: str, x: float, y: float, moved: float
) -> tuple[float, float] | None:
    there = believed.get(iri)
    if there is None or math.hypot(there[0] - x, there[1] - y) < moved:
        return None
    return there


def _belief(
    canvas: Canvas, start: tuple[float, float], there: tuple[float, float], ghost: list[str], size: float = 0.0
) -> list[str]:
    """An arrow from a thing's start to where it is believed to be, its head ``size`` px short of the
    middle (the thing's outline there), and the outline."""
    x0, y0, x1, y1 = canvas.x(start[0]), canvas.y(start[1]), canvas.x(there[0]), canvas.y(there[1])
    length = math.hypot(x1 - x0, y1 - y0)
    cut = min(size + 2, length / 2) / length if length else 0.0
    x1, y1 = x1 - (x1 - x0) * cut, y1 - (y1 - y0) * cut
    return [
        f'<line x1="{x0:.1f}" y1="{y0:.1f}" x2="{x1:.1f}" y2="{y1:.1f}" stroke="{BELIEF}" stroke-width="1.5" '
        'stroke-dasharray="6 3" marker-end="url(#home-plan-arrow)" class="home-belief"/>',
        *ghost,
    ]


def _colour(rgba: tuple[float, float, float, float]) -> tuple[str, float]:
    r, g, b, a = (max(0.0, min(1.0, v)) for v in rgba)
    return f"#{round(r * 255):02x}{round(g * 255):02x}{round(b * 255):02x}", a


_COLOUR_NAMES = {"red", "yellow", "green", "cyan", "blue", "magenta"}


def _css_colour(name: str) -> str:
    """A marker patch's colour name as SVG paints it; an unknown name grey (it is data, not markup)."""
    return name if name in _COLOUR_NAMES else "#9aa7b8"
