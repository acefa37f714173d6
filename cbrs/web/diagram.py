"""Pictures drawn on the server as inline SVG: a class among its superclasses, subclasses and parts, and a
plan's data flow from step to step.

A lab user reads a hierarchy or a plan faster as a picture than as nested lists or a table; the taxonomy
had none, and the plan only the planner's search graph. Inline SVG needs no script and no library: each
box is a link (keyboard-focusable), the picture has a title and a description for screen readers, and
the colours are presentation attributes (the pages' CSP allows no inline styles in elements).

The layout is layered: the caller gives the rows, top to bottom; boxes are ordered within a row by
where their neighbours in the row above sit (one barycentre sweep), which keeps most edges uncrossed.
"""

from __future__ import annotations

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
    "focus": ("#1f6feb", "#1f6feb", "#ffffff"),
    "node": ("#ffffff", "#8c96a8", "#1d2330"),
    "part": ("#f1f8f1", "#1a7f37", "#1d2330"),
    "more": ("#f4f6f9", "#c3cad6", "#5d6778"),
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


def _width(text: str) -> float:
    return max(48.0, max(len(_shown(line)) for line in text.split("\n")) * CHAR_WIDTH + 18)


def _centre(box: Box, above: dict[str, int], edges: Sequence[Edge]) -> float:
    """The mean position of the box's neighbours in the row above (past its end when it has none)."""
    linked = [above[e.source] for e in edges if e.target == box.key and e.source in above]
    linked += [above[e.target] for e in edges if e.source == box.key and e.target in above]
    return sum(linked) / len(linked) if linked else float(len(above))


def _ordered(rows: Sequence[Sequence[Box]], edges: Sequence[Edge]) -> list[list[Box]]:
    """Each row after the first sorted by the mean position of its boxes' neighbours in the row above."""
    ordered = [list(rows[0])] if rows else []
    for row in rows[1:]:
        above = {box.key: i for i, box in enumerate(ordered[-1])}

        fixed = [b for b in row if b.kind in ("more", "part")]  # "N more" and parts stay at the end
        movable = [b for b in row if b not in fixed]
        ordered.append(sorted(movable, key=lambda box: _centre(box, above, edges)) + fixed)
    return ordered


def layered(
    rows: Sequence[Sequence[Box]], edges: Sequence[Edge], title: str, description: str, ident: str = "diagram"
) -> Markup:
    """The rows of boxes, top to bottom, with the edges between them, as an ``<svg>`` element whose ids
    start with ``ident`` (unique on its page)."""
    ordered = _ordered(rows, edges)
    lines = max((b.text.count("\n") + 1 for row in ordered for b in row), default=1)
    box_height = BOX_HEIGHT + (lines - 1) * LINE_HEIGHT
    widths = [sum(_width(b.text) for b in row) + BOX_GAP * max(len(row) - 1, 0) for row in ordered]
    total = max([*widths, 200.0]) + 2 * MARGIN
    placed: dict[str, _Placed] = {}
    for depth, (row, row_width) in enumerate(zip(ordered, widths, strict=True)):
        x = (total - row_width) / 2
        y = MARGIN + depth * (box_height + ROW_GAP)
        for box in row:
            width = _width(box.text)
            placed[box.key] = _Placed(box, x, y, width, box_height)
            x += width + BOX_GAP
    height = MARGIN * 2 + len(ordered) * box_height + max(len(ordered) - 1, 0) * ROW_GAP
    parts = [
        f'<svg class="diagram" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {total:.0f} {height:.0f}" '
        f'width="{total:.0f}" height="{height:.0f}" role="img" aria-labelledby="{ident}-title {ident}-desc" '
        'font-family="DejaVu Sans, system-ui, sans-serif" font-size="12">',
        f'<title id="{ident}-title">{escape(title)}</title><desc id="{ident}-desc">{escape(description)}</desc>',
        f'<defs><marker id="{ident}-arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" '
        'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="#5d6778"/></marker></defs>',
    ]
    for edge in edges:
        source, target = placed.get(edge.source), placed.get(edge.target)
        if source is None or target is None:
            continue
        parts.append(_edge(source, target, edge, f"{ident}-arrow"))
    for item in placed.values():
        parts.append(_box(item))
    parts.append("</svg>")
    return Markup("".join(parts))


def _edge(source: _Placed, target: _Placed, edge: Edge, arrow: str) -> str:
    if abs(source.y - target.y) < 1:  # the same row: side to side
        left, right = (source, target) if source.x < target.x else (target, source)
        x1, x2 = left.x + left.width, right.x
        y1 = y2 = source.y + source.height / 2
        if right is source:
            x1, x2 = x2, x1
    else:
        x1 = source.x + source.width / 2
        x2 = target.x + target.width / 2
        y1 = source.y + (source.height if target.y > source.y else 0)
        y2 = target.y + (0 if target.y > source.y else target.height)
    dash = ' stroke-dasharray="5 3"' if edge.dashed else ""
    line = (
        f'<line x1="{x1:.1f}" y1="{y1:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" stroke="#8c96a8" stroke-width="1.3"'
        f'{dash} marker-end="url(#{arrow})"><title>{escape(edge.note or edge.label)}</title></line>'
    )
    if not edge.label:
        return line
    # beside the arrow's head: edges that fan out from one box keep their labels apart
    mx, my = x1 + (x2 - x1) * 0.8, y1 + (y2 - y1) * 0.8
    return line + (
        f'<text x="{mx:.1f}" y="{my - 3:.1f}" text-anchor="middle" font-size="10" fill="#5d6778" '
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
