"""Pictures drawn on the server as inline SVG: a class among its superclasses, subclasses and parts, and a
plan's data flow from step to step.

A lab user reads a hierarchy or a plan faster as a picture than as nested lists or a table; the taxonomy
had none, and the plan only the planner's search graph. Inline SVG needs no script and no library: each
box is a link (keyboard-focusable, named by its title), the picture a group with a title and a
description for screen readers (not role="img", which would hide the links inside from them), and
the colours are presentation attributes, so the picture needs no stylesheet of its own.

The layout is layered: the caller gives the rows, top to bottom; an arrow that spans rows gets a
waypoint (a narrow slot) in each row between, so that it bends past the boxes instead of under them;
boxes and waypoints are ordered within a row by where their neighbours in the row above sit (one
barycentre sweep), which keeps most arrows uncrossed.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from markupsafe import Markup, escape

CHAR_WIDTH = 7.0  # px per character at the 12 px font, a little over DejaVu Sans's mean
MAX_TEXT = 34  # characters shown in a box; the whole text is its tooltip
BOX_HEIGHT = 30
ROW_GAP = 54
BOX_GAP = 16
MARGIN = 12

# fill, stroke, text colour per kind of box
COLOURS = {
    "focus": ("#0a4aad", "#0a4aad", "#ffffff"),
    "node": ("#ffffff", "#8c96a8", "#1d2330"),
    "part": ("#f1f8f1", "#1a7f37", "#1d2330"),
    "more": ("#f4f6f9", "#c3cad6", "#474f5e"),
    "end": ("#fff8e1", "#9a6700", "#1d2330"),
}


@dataclass(frozen=True)
class Box:
    """A box; ``text`` may have several lines, and a line's part up to its last ``#`` (a file name, see
    ``links.name_parts``) is drawn lighter."""

    key: str
    text: str
    title: str
    href: str | None = None
    kind: str = "node"


@dataclass(frozen=True)
class Edge:
    """An arrow; ``label`` is drawn beside its head, ``note`` only shown as its tooltip."""

    source: str
    target: str
    label: str = ""
    dashed: bool = False
    note: str = ""


@dataclass
class _Placed:
    box: Box
    x: float
    y: float
    width: float
    height: float


def _shown(text: str) -> str:
    return text if len(text) <= MAX_TEXT else text[: MAX_TEXT - 1] + "…"


LINE_HEIGHT = 14


VIRTUAL = "virtual"  # a waypoint of an edge that spans rows: a slot in each row between, not drawn
VIRTUAL_WIDTH = 6.0


def _width(box: Box) -> float:
    if box.kind == VIRTUAL:
        return VIRTUAL_WIDTH
    return max(48.0, max(len(_shown(line)) for line in box.text.split("\n")) * CHAR_WIDTH + 18)


def _centre(box: Box, above: dict[str, int], links: Sequence[tuple[str, str]]) -> float:
    """The mean position of the box's neighbours in the row above (past its end when it has none)."""
    linked = [above[a] for a, b in links if b == box.key and a in above]
    linked += [above[b] for a, b in links if a == box.key and b in above]
    return sum(linked) / len(linked) if linked else float(len(above))


def _ordered(rows: Sequence[Sequence[Box]], links: Sequence[tuple[str, str]]) -> list[list[Box]]:
    """Each row after the first sorted by the mean position of its boxes' neighbours in the row above."""
    ordered = [list(rows[0])] if rows else []
    for row in rows[1:]:
        above = {box.key: i for i, box in enumerate(ordered[-1])}
        fixed = [b for b in row if b.kind in ("more", "part")]  # "N more" and parts stay at the end
        movable = [b for b in row if b not in fixed]
        ordered.append(sorted(movable, key=lambda box: _centre(box, above, links)) + fixed)
    return ordered


def _routed(
    rows: Sequence[Sequence[Box]], edges: Sequence[Edge]
) -> tuple[list[list[Box]], list[tuple[Edge, list[str]]]]:
    """The rows with a waypoint in every row an edge passes, and each edge's keys from end to end: an
    arrow that spans rows bends through its waypoints instead of running under the boxes between."""
    row_of = {box.key: depth for depth, row in enumerate(rows) for box in row}
    grown = [list(row) for row in rows]
    routes = []
    for number, edge in enumerate(edges):
        if edge.source not in row_of or edge.target not in row_of:
            continue
        first, last = row_of[edge.source], row_of[edge.target]
        step = 1 if last > first else -1
        keys = [edge.source]
        for depth in range(first + step, last, step) if abs(last - first) > 1 else ():
            waypoint = Box(f"~{number}-{depth}", "", "", None, VIRTUAL)
            grown[depth].append(waypoint)
            keys.append(waypoint.key)
        routes.append((edge, [*keys, edge.target]))
    return grown, routes


def layered(
    rows: Sequence[Sequence[Box]], edges: Sequence[Edge], title: str, description: str, ident: str = "diagram"
) -> Markup:
    """The rows of boxes, top to bottom, with the edges between them, as an ``<svg>`` element whose ids
    start with ``ident`` (unique on its page)."""
    grown, routes = _routed(rows, edges)
    ordered = _ordered(grown, [pair for _, keys in routes for pair in itertools.pairwise(keys)])
    lines = max((b.text.count("\n") + 1 for row in ordered for b in row), default=1)
    box_height = BOX_HEIGHT + (lines - 1) * LINE_HEIGHT
    widths = [sum(_width(b) for b in row) + BOX_GAP * max(len(row) - 1, 0) for row in ordered]
    total = max([*widths, 200.0]) + 2 * MARGIN
    placed: dict[str, _Placed] = {}
    for depth, (row, row_width) in enumerate(zip(ordered, widths, strict=True)):
        x = (total - row_width) / 2
        y = MARGIN + depth * (box_height + ROW_GAP)
        for box in row:
            width = _width(box)
            placed[box.key] = _Placed(box, x, y, width, box_height)
            x += width + BOX_GAP
    height = MARGIN * 2 + len(ordered) * box_height + max(len(ordered) - 1, 0) * ROW_GAP
    parts = [
        f'<svg class="diagram" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {total:.0f} {height:.0f}" '
        f'width="{total:.0f}" height="{height:.0f}" style="{_fitted(total)}" role="group" '
        f'aria-labelledby="{ident}-title {ident}-desc" '
        'font-family="DejaVu Sans, system-ui, sans-serif" font-size="12">',
        f'<title id="{ident}-title">{escape(title)}</title><desc id="{ident}-desc">{escape(description)}</desc>',
        f'<defs><marker id="{ident}-arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" '
        'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="#5d6778"/></marker></defs>',
    ]
    paths = [[placed[key] for key in keys] for _, keys in routes]
    ends = _spread(paths)
    runs = [_points(path, start, end) for path, (start, end) in zip(paths, ends, strict=True)]
    taken = [_rect(item) for item in placed.values() if item.box.kind != VIRTUAL]
    for (edge, _), points in zip(routes, runs, strict=True):
        parts.append(_edge(points, edge, f"{ident}-arrow", _label_place(points, edge.label, taken)))
    for item in placed.values():
        if item.box.kind != VIRTUAL:
            parts.append(_box(item))
    parts.append("</svg>")
    return Markup("".join(parts))


def _spread(paths: list[list[_Placed]]) -> list[tuple[float | None, float | None]]:
    """Where each arrow leaves its first box and enters its last, along the box's top or bottom side:
    the arrows at one side spread over it in the order of where their other ends are, instead of all
    meeting at its middle, where their heads and names lay on one another."""
    sides: dict[tuple[str, bool], list[tuple[float, int, int]]] = {}
    for number, path in enumerate(paths):
        source, target = path[0], path[-1]
        if len(path) == 2 and abs(source.y - target.y) < 1:
            continue  # side to side, in one row
        down = target.y > source.y
        after, before = path[1], path[-2]
        sides.setdefault((source.box.key, down), []).append((after.x + after.width / 2, number, 0))
        sides.setdefault((target.box.key, not down), []).append((before.x + before.width / 2, number, 1))
    found: list[list[float | None]] = [[None, None] for _ in paths]
    for (key, _), attached in sides.items():
        box = next(p for path in paths for p in (path[0], path[-1]) if p.box.key == key)
        for place, (_, number, end) in enumerate(sorted(attached)):
            found[number][end] = box.x + box.width * (place + 1) / (len(attached) + 1)
    return [(start, end) for start, end in found]


def _points(path: list[_Placed], start: float | None = None, end: float | None = None) -> list[tuple[float, float]]:
    """Where the arrow runs: out of the first box (at ``start`` along its side, else its middle),
    through each waypoint's slot, into the last box (at ``end``)."""
    source, target = path[0], path[-1]
    if len(path) == 2 and abs(source.y - target.y) < 1:  # the same row: side to side
        y = source.y + source.height / 2
        if source.x < target.x:
            return [(source.x + source.width, y), (target.x, y)]
        return [(source.x, y), (target.x + target.width, y)]
    down = target.y > source.y
    first = source.x + source.width / 2 if start is None else start
    last = target.x + target.width / 2 if end is None else end
    points = [(first, source.y + (source.height if down else 0))]
    for waypoint in path[1:-1]:
        x = waypoint.x + waypoint.width / 2
        points += (
            [(x, waypoint.y), (x, waypoint.y + waypoint.height)]
            if down
            else [
                (x, waypoint.y + waypoint.height),
                (x, waypoint.y),
            ]
        )
    points.append((last, target.y + (0 if down else target.height)))
    return points


Rect = tuple[float, float, float, float]  # left, top, right, bottom

LABEL_CHAR_WIDTH = 6.2  # px per character of an arrow's 10 px label, DejaVu Sans's widest lower case is 6.5
LABEL_HEIGHT = 12.0  # px from the label's top to a little below its baseline
LABEL_SPOTS = (0.8, 0.6, 0.4, 0.2)  # where along a segment a label may sit, nearest the head first


def _rect(item: _Placed) -> Rect:
    return item.x, item.y, item.x + item.width, item.y + item.height


def _label_rect(x: float, baseline: float, label: str) -> Rect:
    width = len(_shown(label)) * LABEL_CHAR_WIDTH
    return x - width / 2, baseline - LABEL_HEIGHT + 2, x + width / 2, baseline + 2


def _overlap(a: Rect, b: Rect) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _label_place(points: list[tuple[float, float]], label: str, taken: list[Rect]) -> tuple[float, float] | None:
    """Where an arrow's label goes (the middle of its baseline): the spot nearest its head, along its last
    segment and then the ones before, whose box meets no box and no label placed before it; ``taken``
    gains it. Labels at one fixed spot lay on one another where arrows converge on a box. With no free
    spot, the one nearest the head."""
    if not label:
        return None
    spots = [
        (x1 + (x2 - x1) * t, y1 + (y2 - y1) * t - 3)
        for (x1, y1), (x2, y2) in reversed(list(itertools.pairwise(points)))
        for t in LABEL_SPOTS
    ]
    found = next((s for s in spots if not any(_overlap(_label_rect(*s, label), r) for r in taken)), spots[0])
    taken.append(_label_rect(*found, label))
    return found


def _edge(points: list[tuple[float, float]], edge: Edge, arrow: str, place: tuple[float, float] | None) -> str:
    dash = ' stroke-dasharray="5 3"' if edge.dashed else ""
    drawn = " ".join(f"{x:.1f},{y:.1f}" for x, y in points)
    line = (
        f'<polyline points="{drawn}" fill="none" stroke="#8c96a8" stroke-width="1.3"'
        f'{dash} marker-end="url(#{arrow})"><title>{escape(edge.note or edge.label)}</title></polyline>'
    )
    if place is None:
        return line
    x, y = place
    return line + (
        f'<text x="{x:.1f}" y="{y:.1f}" text-anchor="middle" font-size="10" fill="#474f5e" '
        f'stroke="#ffffff" stroke-width="3" paint-order="stroke">{escape(_shown(edge.label))}</text>'
    )


def _text(shown: str) -> Markup:
    head, hash_, local = shown.rpartition("#")
    if not hash_ or not local or " " in head:
        return escape(shown)
    return Markup(f'<tspan fill-opacity="0.6">{escape(head)}#</tspan>{escape(local)}')


def _box(item: _Placed) -> str:
    fill, stroke, ink = COLOURS.get(item.box.kind, COLOURS["node"])
    lines = item.box.text.split("\n")
    top = item.y + item.height / 2 - (len(lines) - 1) * LINE_HEIGHT / 2 + 4
    centre = item.x + item.width / 2
    text = "".join(
        f'<tspan x="{centre:.1f}" y="{top + i * LINE_HEIGHT:.1f}">{_text(_shown(line))}</tspan>'
        for i, line in enumerate(lines)
    )
    body = (
        f"<title>{escape(item.box.title)}</title>"
        f'<rect x="{item.x:.1f}" y="{item.y:.1f}" width="{item.width:.1f}" height="{item.height:.1f}" rx="6" '
        f'fill="{fill}" stroke="{stroke}" stroke-width="1.3"/>'
        f'<text text-anchor="middle" fill="{ink}">{text}</text>'
    )
    if item.box.href is None:
        return f'<g class="box">{body}</g>'
    return f'<a class="box" href="{escape(item.box.href)}">{body}</a>'


FIT_SCALE = 0.7
"""The smallest a picture is drawn to fit its column (its 12 px labels at 8.4 px); wider, it scrolls."""


def _fitted(width: float) -> str:
    """Inline sizing: the picture's own width at most, shrunk to its column down to FIT_SCALE of it, so a
    plan of seven boxes a row fits the page instead of being cut at both sides."""
    return f"width:100%;height:auto;max-width:{width:.0f}px;min-width:{width * FIT_SCALE:.0f}px"
