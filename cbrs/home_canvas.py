"""Drawing the home's picture (:mod:`cbrs.home_plan`): metres to pixels with y up, labels that keep off
each other and off the furniture, the colours, and what is no thing of the home: the metre grid, the
scale bar and axes, and the legend. Every text is escaped here, in :meth:`Canvas.text`."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from html import escape

from cbrs.kb.semantic_map import Box

MARGIN = 44  # px around the plan: the metre ticks on the left and below
_LEGEND_ROW = 26
FONT = "DejaVu Sans, Helvetica, Arial, sans-serif"
INK, MUTED = "#1d2330", "#474f5e"  # MUTED: the pages' --muted, 7:1 on every room fill (a projector)
ROOM_FILLS = ("#eaf2fb", "#f1edf9", "#eaf6ee", "#fbf3e6", "#f8ebf0", "#e8f5f5")
CAMERA_INKS = ("#c2410c", "#7c3aed", "#0e7490", "#be185d", "#4d7c0f")
FURNITURE = ("#ead8b9", "#8a5a2b")
APPLIANCE = ("#d5dde8", "#4b5563")
THING = ("#f3e8c8", "#7a5c12")
"""A physical thing of the map outside the reader's groups (a lab's lamp, a tap lever): fill and ink."""
ROBOT = ("#b9cbe4", "#2f4f7a")
BASE = ("#5b6b82", "#1d2330")
DOCK = "#1a7f37"
BELIEF = "#b42318"
PERSON_PX = 9.0  # the person is drawn as a mark, not to scale: the map gives no body's size


@dataclass
class Canvas:
    """Metres to pixels: x to the right, y up (the SVG's y runs down), ``scale`` px a metre."""

    extent: Box
    scale: float
    left: float = MARGIN
    top: float = 16.0
    taken: list[tuple[float, float, float, float]] = field(default_factory=list)
    """Pixel boxes (left, top, right, bottom) labels keep off: other labels, furniture, robots, marks."""

    def x(self, x: float) -> float:
        return self.left + (x - self.extent.min_x) * self.scale

    def y(self, y: float) -> float:
        return self.top + (self.extent.max_y - y) * self.scale

    def point(self, x: float, y: float) -> str:
        return f"{self.x(x):.1f},{self.y(y):.1f}"

    def rect(self, box: Box, **attributes: object) -> str:
        x, y = self.x(box.min_x), self.y(box.max_y)
        w, h = (box.max_x - box.min_x) * self.scale, (box.max_y - box.min_y) * self.scale
        return f'<rect x="{x:.1f}" y="{y:.1f}" width="{w:.1f}" height="{h:.1f}"{svg_attributes(attributes)}/>'

    def polygon(self, points: list[tuple[float, float]], **attributes: object) -> str:
        shown = " ".join(self.point(px, py) for px, py in points)
        return f'<polygon points="{shown}"{svg_attributes(attributes)}/>'

    def block(self, left: float, top: float, right: float, bottom: float) -> None:
        self.taken.append((left, top, right, bottom))

    def block_box(self, box: Box) -> None:
        self.block(self.x(box.min_x), self.y(box.max_y), self.x(box.max_x), self.y(box.min_y))

    def label(self, px: float, py: float, gap: float, text: str, size: float = 11, **attributes: object) -> str:
        """``text`` beside the mark at pixel (``px``, ``py``) of radius ``gap``: below it, else above, right
        or left, the first place no other label or blocked box takes (below when none is free)."""
        width, height = CHAR * size * len(text), size
        spots = (
            (px, py + gap + size + 1, "middle"),
            (px, py - gap - 4, "middle"),
            (px + gap + 4, py + size / 2 - 1, "start"),
            (px - gap - 4, py + size / 2 - 1, "end"),
        )
        chosen = spots[0]
        for spot in spots:
            if not any(overlap(_text_box(spot, width, height), box) for box in self.taken):
                chosen = spot
                break
        self.block(*_text_box(chosen, width, height))
        return self.text(chosen[0], chosen[1], text, size, text_anchor=chosen[2], **attributes)

    def text(self, x: float, y: float, text: str, size: float = 11, **attributes: object) -> str:
        """``text`` at pixel (``x``, ``y``), escaped."""
        attributes.setdefault("fill", INK)
        shown = escape(text, quote=False)
        return f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size:g}"{svg_attributes(attributes)}>{shown}</text>'


CHAR = 0.6  # a character's mean width, in font sizes


def _text_box(spot: tuple[float, float, str], width: float, height: float) -> tuple[float, float, float, float]:
    x, y, anchor = spot
    left = x - width / 2 if anchor == "middle" else x - width if anchor == "end" else x
    return (left, y - height, left + width, y + 2)


def overlap(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def svg_attributes(attributes: dict[str, object]) -> str:
    return "".join(f' {name.replace("_", "-")}="{escape(str(value))}"' for name, value in attributes.items())


def grid(canvas: Canvas) -> Iterator[str]:
    """Faint metre lines under the plan, numbered along its left and bottom edges."""
    e = canvas.extent
    step = 1.0 if (e.max_x - e.min_x) <= 16 else 2.0
    yield '<g stroke="#eef0f3" stroke-width="1">'
    lines: list[tuple[float | None, float | None]] = []
    x = math.ceil(e.min_x / step) * step
    while x <= e.max_x:
        lines.append((x, None))
        x += step
    y = math.ceil(e.min_y / step) * step
    while y <= e.max_y:
        lines.append((None, y))
        y += step
    labels = []
    for gx, gy in lines:
        if gx is not None:
            px = canvas.x(gx)
            yield f'<line x1="{px:.1f}" y1="{canvas.y(e.max_y):.1f}" x2="{px:.1f}" y2="{canvas.y(e.min_y):.1f}"/>'
            labels.append(canvas.text(px, canvas.y(e.min_y) + 14, f"{gx:g}", 10, fill=MUTED, text_anchor="middle"))
        elif gy is not None:
            py = canvas.y(gy)
            yield f'<line x1="{canvas.x(e.min_x):.1f}" y1="{py:.1f}" x2="{canvas.x(e.max_x):.1f}" y2="{py:.1f}"/>'
            labels.append(canvas.text(canvas.x(e.min_x) - 6, py + 3.5, f"{gy:g}", 10, fill=MUTED, text_anchor="end"))
    yield "</g>"
    yield from labels


def circle(px: float, py: float, r: float, **attributes: object) -> str:
    """A circle at pixel (``px``, ``py``)."""
    return f'<circle cx="{px:.1f}" cy="{py:.1f}" r="{r:.1f}"{svg_attributes(attributes)}/>'


def dot(canvas: Canvas, x: float, y: float, r: float, fill: str) -> str:
    return f'<circle cx="{canvas.x(x):.1f}" cy="{canvas.y(y):.1f}" r="{r:g}" fill="{fill}"/>'


def arrow(canvas: Canvas, x: float, y: float, yaw: float, length: float, ink: str, stroke_width: float = 2) -> str:
    """An arrow of ``length`` m centred at (``x``, ``y``) pointing along ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    tail = (x - c * length / 2, y - s * length / 2)
    head = (x + c * length / 2, y + s * length / 2)
    barb = length * 0.35
    left = (head[0] - barb * math.cos(yaw - 0.5), head[1] - barb * math.sin(yaw - 0.5))
    right = (head[0] - barb * math.cos(yaw + 0.5), head[1] - barb * math.sin(yaw + 0.5))
    tip = canvas.point(*head)
    path = f"M{canvas.point(*tail)} L{tip} M{canvas.point(*left)} L{tip} L{canvas.point(*right)}"
    return (
        f'<path d="{path}" fill="none" stroke="{ink}" stroke-width="{stroke_width:g}" stroke-linecap="round" '
        'stroke-linejoin="round"/>'
    )


def scale_bar(canvas: Canvas, y: float) -> Iterator[str]:
    """A scale bar of a round length about a sixth of the width, and the axes: x east, y north."""
    width_m = canvas.extent.max_x - canvas.extent.min_x
    length = next((n for n in (0.5, 1, 2, 5, 10, 20, 50) if n * canvas.scale >= (width_m * canvas.scale) / 7), 50)
    x0 = canvas.left
    x1 = x0 + length * canvas.scale
    yield f'<g stroke="{INK}" stroke-width="1.5" fill="none">'
    yield f'<path d="M{x0:.1f},{y - 5:.1f} L{x0:.1f},{y:.1f} L{x1:.1f},{y:.1f} L{x1:.1f},{y - 5:.1f}"/>'
    yield "</g>"
    yield canvas.text(x0, y + 13, "0", 10)
    yield canvas.text(x1, y + 13, f"{length:g} m", 10, text_anchor="middle")
    ax, ay = x1 + 70, y + 4
    yield (
        f'<path d="M{ax:.1f},{ay:.1f} L{ax + 34:.1f},{ay:.1f} M{ax + 28:.1f},{ay - 4:.1f} L{ax + 34:.1f},{ay:.1f} '
        f"L{ax + 28:.1f},{ay + 4:.1f} M{ax:.1f},{ay:.1f} L{ax:.1f},{ay - 34:.1f} M{ax - 4:.1f},{ay - 28:.1f} "
        f'L{ax:.1f},{ay - 34:.1f} L{ax + 4:.1f},{ay - 28:.1f}" stroke="{INK}" stroke-width="1.5" fill="none"/>'
    )
    yield canvas.text(ax + 38, ay + 4, "x (east)", 10)
    yield canvas.text(ax + 6, ay - 30, "y (north)", 10)
    yield canvas.text(ax + 100, ay + 4, "metres; the origin at the home's south-west corner", 10, fill=MUTED)


_LEGEND = (
    ("room", "room"),
    ("wall", "wall"),
    ("furniture", "furniture (top height)"),
    ("appliance", "appliance"),
    ("thing", "other physical thing"),
    ("object", "object (its colour)"),
    ("robot", "dual-arm robot, arm reach"),
    ("base", "mobile base, heading"),
    ("person", "person"),
    ("camera", "camera, floor it sees"),
    ("dock", "docking pose"),
    ("belief", "believed now (world graph)"),
)


def legend(canvas: Canvas, top: float, width: int, things: bool = False) -> tuple[list[str], float]:
    """The legend's swatches in rows below the plan, and its height; the other things' swatch only
    where ``things`` are drawn."""
    column = 176
    per_row = max(1, int((width - 2 * MARGIN) // column))
    parts: list[str] = []
    shown = [(kind, text) for kind, text in _LEGEND if things or kind != "thing"]
    for index, (kind, text) in enumerate(shown):
        x = canvas.left + (index % per_row) * column
        y = top + (index // per_row) * _LEGEND_ROW
        parts.append(_swatch(kind, x, y))
        parts.append(canvas.text(x + 26, y + 4, text, 11))
    rows = -(-len(shown) // per_row)
    return parts, rows * _LEGEND_ROW


def _swatch(kind: str, x: float, y: float) -> str:
    box = f'x="{x:.1f}" y="{y - 7:.1f}" width="20" height="14"'
    swatches = {
        "room": f'<rect {box} fill="{ROOM_FILLS[0]}" stroke="#9aa7b8"/>',
        "wall": f'<rect x="{x:.1f}" y="{y - 3:.1f}" width="20" height="6" fill="#4b5563"/>',
        "furniture": f'<rect {box} fill="{FURNITURE[0]}" stroke="{FURNITURE[1]}"/>',
        "appliance": f'<rect {box} fill="{APPLIANCE[0]}" stroke="{APPLIANCE[1]}"/>',
        "thing": f'<rect x="{x + 3:.1f}" y="{y - 6:.1f}" width="14" height="12" fill="{THING[0]}" '
        f'stroke="{THING[1]}"/>',
        "object": f'<circle cx="{x + 6:.1f}" cy="{y:.1f}" r="5" fill="#d91414" stroke="{INK}" stroke-width="0.8"/>'
        f'<rect x="{x + 12:.1f}" y="{y - 1.5:.1f}" width="9" height="3" fill="#1a33d9"/>',
        "robot": f'<circle cx="{x + 10:.1f}" cy="{y:.1f}" r="9" fill="{ROBOT[1]}" fill-opacity="0.05" '
        f'stroke="{ROBOT[1]}" '
        f'stroke-dasharray="3 2"/><rect x="{x + 5:.1f}" y="{y - 3:.1f}" width="10" height="6" fill="{ROBOT[0]}" '
        f'stroke="{ROBOT[1]}"/>',
        "base": f'<rect {box} fill="{BASE[0]}" stroke="{BASE[1]}"/>'
        f'<path d="M{x + 4:.1f},{y:.1f} L{x + 16:.1f},{y:.1f} '
        f'M{x + 12:.1f},{y - 3:.1f} L{x + 16:.1f},{y:.1f} L{x + 12:.1f},{y + 3:.1f}" '
        'stroke="#ffffff" stroke-width="2" fill="none"/>',
        "person": f'<circle cx="{x + 10:.1f}" cy="{y:.1f}" r="7" fill="#f2d91a" stroke="{INK}" stroke-width="1.5"/>',
        "camera": f'<rect {box} fill="{CAMERA_INKS[0]}" fill-opacity="0.08" stroke="{CAMERA_INKS[0]}" '
        'stroke-dasharray="4 3"/>'
        f'<rect x="{x + 5:.1f}" y="{y - 4:.1f}" width="10" height="8" rx="1.5" fill="{CAMERA_INKS[0]}"/>',
        "dock": f'<path d="M{x + 2:.1f},{y:.1f} L{x + 18:.1f},{y:.1f} M{x + 12:.1f},{y - 4:.1f} L{x + 18:.1f},{y:.1f} '
        f'L{x + 12:.1f},{y + 4:.1f}" stroke="{DOCK}" stroke-width="2" fill="none"/>',
        "belief": f'<path d="M{x:.1f},{y:.1f} L{x + 14:.1f},{y:.1f}" stroke="{BELIEF}" stroke-width="1.5" '
        f'stroke-dasharray="4 2" marker-end="url(#home-plan-arrow)"/>',
    }
    return swatches[kind]
