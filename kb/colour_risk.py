"""Warnings for colours the cameras may not tell: a thing painted at the edge of its colour's window, or
outside every window, or too grey or dark for the windows' floors.

Not wrong, so nothing is refused: risky. A map whose apple was painted at hue 100 degrees, the very edge
of green's 100-150, loaded without a word, and in the run the camera saw only part of its pixels and the
grasp went wrong; a colour outside every window was found only when the task looked for the thing. So a
load or an update that paints a thing says so (``cbrs load``, ``cbrs update``), and so does the report
of a run that perceives it (:mod:`actions.colour_warnings`; docs/simulation.md, "Colour windows").

A thing is checked when the map gives it a ``home:colourName`` (what perception looks for it by) and
``home:rgba`` (how the simulation paints it; one with a colour name and no rgba is painted grey). Its
paint's hue, saturation and value (:func:`kb.colour_windows.hsv`) are held to the windows the map's
cameras know (:func:`kb.colour_windows.read_colour_windows`): the window of its colour name, and where
the hue lies in none, the nearest of all. The margin at a window's edge is the window's
``home:hueMargin`` unless the caller gives one.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from enum import Enum
from typing import TYPE_CHECKING, Any

from pyoxigraph import Triple

from cbrs.kb.colour_windows import SIMULATED_LIGHTING, ColourWindow, Lighting, hsv, read_colour_windows
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.semantic_map import UNPAINTED

if TYPE_CHECKING:
    from collections.abc import Collection, Iterable, Sequence

    from pyoxigraph import Quad

    from cbrs.kb.knowledge_base import KnowledgeBase

__all__ = [
    "UNPAINTED",
    "ColourRisk",
    "Risk",
    "colour_risk",
    "colour_risks",
    "known_windows",
    "written_colour_risks",
]

HOME = PREFIXES["home"]


class Risk(Enum):
    """Why a camera may not tell a thing's colour."""

    EDGE = "edge"
    """Its hue is within the margin of its window's edge: shading moves part of its pixels out."""
    OUTSIDE = "outside"
    """Its hue is outside its colour's window (in another's, or in none)."""
    GREY = "grey"
    """It is less saturated than the window's floor: its pixels are no colour at all."""
    DARK = "dark"
    """Even its lit top is seen darker than the window's floor: its paint's brightness times the light's
    shading (:class:`kb.colour_windows.Lighting`)."""
    SHADED = "shaded"
    """Its faces turned from the light are seen darker than the window's floor: a camera sees only its lit
    faces (part of it)."""
    UNKNOWN = "unknown"
    """No camera of the map has a window of its colour name."""


@dataclass(frozen=True)
class ColourRisk:
    """One thing whose colour a camera may not tell: what it is painted, its hue, and the window."""

    thing: str
    colour: str
    """Its home:colourName."""
    rgba: tuple[float, float, float, float]
    hue: float
    saturation: float
    value: float
    risk: Risk
    window: ColourWindow | None
    """The window it is held to: its colour's, or the nearest where its colour has none."""
    margin: float
    inside: ColourWindow | None = None
    """The window its hue lies in, when that is another colour's."""
    nearest: ColourWindow | None = None
    """The window whose edge is nearest its hue, of every colour (for one whose hue is in none)."""
    painted: bool = True
    """False: the map gives it no home:rgba, and it is painted grey."""
    seen: float | None = None
    """For a dark or shaded one: the brightness the cameras see of its lit top, or of a face in shadow."""
    needed: float | None = None
    """For a shaded one: the least paint brightness whose faces in shadow the cameras see."""

    def text(self) -> str:
        """One line naming the thing, its hue and the window: what ``cbrs load`` prints after ``warning:``."""
        thing = shorten(self.thing)
        paint = f"home:rgba {' '.join(f'{part:g}' for part in self.rgba)}" if self.painted else "no home:rgba (grey)"
        said = f"{thing} ({self.colour}, {paint}) has hue {self.hue:.0f}°"
        window = self.window
        near = self.nearest
        if self.risk is Risk.UNKNOWN:
            return f"{said}, and no camera tells {self.colour!r} apart" + (
                f"; the nearest window is {near.span()}" if near is not None else ""
            )
        assert window is not None
        if self.risk is Risk.GREY:
            return (
                f"{said} but saturation {self.saturation:.2f}, below {window.name}'s floor of "
                f"{window.min_saturation:g}: the cameras see no colour in it (window {window.span()})"
            )
        if self.risk is Risk.DARK:
            return (
                f"{said} but brightness {self.value:.2f}, seen at {self.seen or 0.0:.2f} on its lit top, below "
                f"{window.name}'s floor of {window.min_value:g}: too dark for the cameras to tell its hue (window "
                f"{window.span()})"
            )
        if self.risk is Risk.SHADED:
            return (
                f"{said} and brightness {self.value:.2f}, seen at {self.seen or 0.0:.2f} on a face turned from the "
                f"light, below {window.name}'s floor of {window.min_value:g} (window {window.span()}): a camera may "
                f"see only its lit faces; paint it at least {self.needed or 1.0:.2f} bright"
            )
        if self.risk is Risk.EDGE:
            return (
                f"{said}, within {self.margin:g}° of the edge of the window {window.span()}: a camera may see "
                f"only part of it; paint it nearer {window.hue:g}°"
            )
        if self.inside is not None:
            return (
                f"{said}, in the window {self.inside.span()}, not {window.span()}: the cameras would take it "
                f"for {self.inside.name}"
            )
        if near is None or near.name == window.name:  # beside its own window: say how far and which way
            return (
                f"{said}, outside {window.span()} and every other window the cameras know: they would not find "
                f"it as {self.colour}; paint it nearer {window.hue:g}°"
            )
        return (
            f"{said}, outside every window the cameras know (the nearest: {near.span()}), not in "
            f"{window.span()}: the cameras would not find it as {self.colour}"
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "thing": self.thing,
            "colour": self.colour,
            "rgba": list(self.rgba) if self.painted else None,
            "hue": round(self.hue, 1),
            "saturation": round(self.saturation, 3),
            "value": round(self.value, 3),
            "seen": None if self.seen is None else round(self.seen, 3),
            "risk": self.risk.value,
            "window": None if self.window is None else self.window.span(),
            "nearest": None if self.nearest is None else self.nearest.span(),
            "margin": self.margin,
            "text": self.text(),
        }


def colour_risk(
    thing: str,
    colour: str,
    rgba: tuple[float, float, float, float] | None,
    windows: Sequence[ColourWindow],
    margin: float | None = None,
    lighting: Lighting = SIMULATED_LIGHTING,
) -> ColourRisk | None:
    """Why the cameras whose windows are ``windows`` may not tell ``thing``'s colour (None: they will).
    ``rgba`` None is the grey a thing the map gives no rgba is painted; its brightness is held to a
    window's floor as ``lighting`` shades it."""
    paint = rgba if rgba is not None else UNPAINTED
    hue, saturation, value = hsv(paint)

    def risk(kind: Risk, window: ColourWindow | None, inside: ColourWindow | None = None) -> ColourRisk:
        edge = margin if margin is not None else (window.hue_margin if window is not None else 0.0)
        nearest = _nearest(hue, windows)
        painted = rgba is not None
        seen = needed = None
        if window is not None and kind is Risk.DARK:
            seen = lighting.seen(value, lighting.lit)
        if window is not None and kind is Risk.SHADED:
            seen, needed = lighting.seen(value, lighting.shaded), lighting.least(window.min_value, lighting.shaded)
        return ColourRisk(
            thing, colour, paint, hue, saturation, value, kind, window, edge, inside, nearest, painted, seen, needed
        )

    own = [window for window in windows if window.name == colour]
    if not own:
        return risk(Risk.UNKNOWN, None)
    found: list[tuple[Risk, ColourWindow]] = []
    for window in own:
        kind = _held(hue, saturation, value, window, margin, lighting)
        if kind is None:
            return None  # some camera tells it (where cameras differ, one that can is the one to use)
        found.append((kind, window))
    kind, window = min(found, key=lambda held: _ORDER.index(held[0]))
    inside = None
    if kind is Risk.OUTSIDE:
        inside = next((other for other in windows if other.name != colour and _within(hue, other, 0.0)), None)
    return risk(kind, window, inside)


_ORDER = (Risk.SHADED, Risk.EDGE, Risk.DARK, Risk.GREY, Risk.OUTSIDE)
"""Which of a thing's risks to say where several cameras' windows of its colour give different ones: the
mildest (the camera that comes nearest to telling it)."""


def _held(
    hue: float, saturation: float, value: float, window: ColourWindow, margin: float | None, lighting: Lighting
) -> Risk | None:
    """How a paint of ``hue``, ``saturation`` and ``value`` fares in ``window`` under ``lighting`` (None:
    well inside it). Brightness is held to the floor as the cameras see it, shaded (docs/simulation.md)."""
    edge = window.hue_margin if margin is None else margin
    if saturation < window.min_saturation:
        return Risk.GREY
    if lighting.seen(value, lighting.lit) < window.min_value:
        return Risk.DARK
    distance = window.distance(hue)
    if distance > window.hue_tolerance + edge:
        return Risk.OUTSIDE
    if distance >= window.hue_tolerance - edge:
        return Risk.EDGE
    if lighting.seen(value, lighting.shaded) < window.min_value:
        return Risk.SHADED
    return None


def _within(hue: float, window: ColourWindow, margin: float) -> bool:
    return window.distance(hue) <= window.hue_tolerance + margin


def _nearest(hue: float, windows: Iterable[ColourWindow]) -> ColourWindow | None:
    """The window whose edge is nearest ``hue`` (None: there are none)."""
    return min(windows, key=lambda window: (window.distance(hue) - window.hue_tolerance, window.name), default=None)


def known_windows(kb: KnowledgeBase) -> list[ColourWindow]:
    """Every window some camera of the map has, once each (home:Camera's when the map has no camera)."""
    found = {window for windows in read_colour_windows(kb).values() for window in windows}
    return sorted(found, key=lambda window: (window.name, window.iri, window.hue))


def colour_risks(
    kb: KnowledgeBase, things: Collection[str] | None = None, margin: float | None = None
) -> list[ColourRisk]:
    """The things of the map (or of ``things``) whose colour the map's cameras may not tell, by IRI: those
    with a home:colourName held to the cameras' windows (:func:`colour_risk`). A map whose cameras have no
    windows at all gives none: there is nothing to hold them to (the simulation refuses such a map)."""
    windows = known_windows(kb)
    if not windows:
        return []
    facts: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for row in kb.select("map_facts"):
        thing = row["thing"].value
        if things is None or thing in things:
            facts[thing][row["property"].value].append(row["value"].value)
    risks = []
    for thing, values in sorted(facts.items()):
        if HOME + "hueCentre" in values:
            continue  # a colour window of the map's: its rgba is how the colour is painted, not a thing
        for colour in sorted(set(values.get(HOME + "colourName", []))):
            found = colour_risk(thing, colour, _paint(values.get(HOME + "rgba", [])), windows, margin)
            if found is not None:
                risks.append(found)
    return risks


def _paint(texts: list[str]) -> tuple[float, float, float, float] | None:
    """The rgba a thing is painted, or None (none, or not one that reads: the map's reader says why)."""
    if len(set(texts)) != 1:
        return None
    try:
        parts = [float(part) for part in texts[0].split()]
    except ValueError:
        return None
    if len(parts) == 3:
        parts.append(1.0)
    return (parts[0], parts[1], parts[2], parts[3]) if len(parts) == 4 else None


_WINDOW_TERMS = frozenset(
    HOME + name
    for name in ("hasColourWindow", "hueCentre", "hueTolerance", "minSaturation", "minBrightness", "hueMargin")
)
_PAINT = frozenset((HOME + "rgba", HOME + "colourName"))


def written_colour_risks(kb: KnowledgeBase, quads: Iterable[Quad]) -> list[ColourRisk]:
    """The risks of what a write of ``quads`` painted: the things it gave a home:rgba or home:colourName,
    or every thing when it changed the windows (then a thing painted before may now be at an edge)."""
    things: set[str] = set()
    for quad in quads:
        if quad.predicate.value in _WINDOW_TERMS:
            return colour_risks(kb)
        if quad.predicate.value in _PAINT and not isinstance(quad.subject, Triple):
            things.add(quad.subject.value)
    return colour_risks(kb, things) if things else []
