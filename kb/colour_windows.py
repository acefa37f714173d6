"""What a camera can tell apart: the colour windows its colour segmentation classifies pixels by.

A colour window (``home:ColourWindow``) is a hue window, ``home:hueCentre`` plus or minus
``home:hueTolerance`` degrees, with floors of saturation and brightness below which a pixel is no colour
at all; ``home:colourName`` is the name perception finds things by and ``home:rgba`` how the simulation
paints that colour. Knowledge about the device, so it lives in the store: a camera names its windows
(``home:hasColourWindow``), or a class of cameras (a model) names them for its individuals, or
``home:Camera`` does for every camera that names none (the bundled ``home.ttl`` names the simulated
cameras' six there). The named query ``colour_windows`` reads them; :func:`read_colour_windows` picks
each camera's: its own, else its nearest class's, else home:Camera's (docs/simulation.md, "Colour
windows"). The simulation segments each camera's images by its windows; :mod:`kb.colour_risk` warns of
a thing painted where its camera may not tell its colour.
"""

from __future__ import annotations

import colorsys
import math
from collections import defaultdict
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pyoxigraph import NamedNode

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapError

if TYPE_CHECKING:
    from collections.abc import Iterable, Mapping

    from cbrs.kb.knowledge_base import KnowledgeBase

__all__ = [
    "DEFAULT_HUE_MARGIN",
    "DEFAULT_MIN_SATURATION",
    "DEFAULT_MIN_VALUE",
    "SIMULATED_LIGHTING",
    "ColourWindow",
    "ColourWindowError",
    "Lighting",
    "hsv",
    "read_colour_windows",
]

HOME = PREFIXES["home"]
DEFAULT_MIN_SATURATION = 0.55
"""A window's ``home:minSaturation`` when it states none: keeps out greys, whites and the wooden table."""
DEFAULT_MIN_VALUE = 0.20
"""A window's ``home:minBrightness`` when it states none: darker pixels are shadow, not colour."""
DEFAULT_HUE_MARGIN = 3.0
"""A window's ``home:hueMargin`` when it states none (degrees): how far a pixel's hue may stray from its
paint's. The renderer scales brightness, which keeps hue, but each channel is rounded to 8 bits, and one
step moves the hue of a pixel of chroma C by 60/(255 C) degrees: 2.9 at chroma 0.08, a little under the
floors' least (saturation 0.55 of brightness 0.20 is 0.11). Painted things in the bundled home spread
by 0.44 degrees at most (docs/simulation.md, "Colour windows")."""


class ColourWindowError(MapError):
    """A colour window the store describes cannot be used: a property missing, not a number, out of range
    or given twice. Names the window and the property; refused as the map's other faults are (a load into
    the map, a run)."""

    def __init__(self, window: str, problem: str) -> None:
        self.window = window
        super().__init__(window, f"is a colour window and {problem}")


@dataclass(frozen=True)
class ColourWindow:
    """One colour a camera tells apart: pixels whose hue lies within ``hue_tolerance`` degrees of ``hue``,
    at least ``min_saturation`` saturated and ``min_value`` bright."""

    name: str
    hue: float
    hue_tolerance: float
    min_saturation: float = DEFAULT_MIN_SATURATION
    min_value: float = DEFAULT_MIN_VALUE
    hue_margin: float = DEFAULT_HUE_MARGIN
    rgba: tuple[float, float, float, float] | None = None
    """How the simulation paints a thing of this colour that gives no rgba of its own (a marker's patch)."""
    iri: str = ""

    def distance(self, hue: float) -> float:
        """How far ``hue`` is from the window's centre, the short way round the circle (0 to 180)."""
        return abs((hue - self.hue + 180.0) % 360.0 - 180.0)

    def span(self) -> str:
        """The window as its readers write it: ``green (100-150°)``."""
        low, high = (self.hue - self.hue_tolerance) % 360.0, (self.hue + self.hue_tolerance) % 360.0
        return f"{self.name} ({low:g}-{high:g}°)"


@dataclass(frozen=True)
class Lighting:
    """How the simulated cameras' renderer lights a face: a face of paint brightness V is seen at V times
    ``ambient + diffuse * max(0, n . l)``, n its normal and l the unit direction towards the light (the
    renderer's Lambert shading; no specular part, no cast shadows), which scales the channels and so keeps
    hue and saturation. The paint's channel is made a byte and the shaded one too, each cut down, not
    rounded (measured: docs/simulation.md, "Colour windows")."""

    direction: tuple[float, float, float] = (0.3, 0.2, 1.0)
    """Towards the light, not normalised (as ``pybullet.getCameraImage`` takes it): above, a little to +x and +y."""
    ambient: float = 0.6
    diffuse: float = 0.4

    def factor(self, normal: tuple[float, float, float]) -> float:
        """What a face of unit ``normal`` scales its paint's brightness by."""
        length = math.sqrt(sum(part * part for part in self.direction))
        facing = sum(n * d for n, d in zip(normal, self.direction, strict=True)) / length
        return self.ambient + self.diffuse * max(0.0, facing)

    @property
    def lit(self) -> float:
        """The factor of a thing's top, the face every camera looking down on it sees, and its best lit
        (the light is mostly above): 0.976 for the simulated light."""
        return self.factor((0.0, 0.0, 1.0))

    @property
    def shaded(self) -> float:
        """The factor of a face turned from the light: the ambient part alone."""
        return self.ambient

    def seen(self, value: float, factor: float) -> float:
        """The brightness a camera sees of a face of paint brightness ``value`` lit by ``factor``."""
        return math.floor(math.floor(value * 255.0 + 1e-9) * factor + 1e-9) / 255.0

    def least(self, floor: float, factor: float) -> float:
        """The least paint brightness whose face lit by ``factor`` is seen at ``floor`` or brighter (1.0
        when none is)."""
        return next((level / 255.0 for level in range(256) if self.seen(level / 255.0, factor) >= floor), 1.0)


SIMULATED_LIGHTING = Lighting()
"""The light the simulated cameras render by (``sim.cameras.render``), the same for every camera."""


def hsv(rgba: tuple[float, ...]) -> tuple[float, float, float]:
    """Hue (degrees), saturation and value of a colour in 0..1, the segmentation's HSV (hue 0 for a grey,
    which has none)."""
    hue, saturation, value = colorsys.rgb_to_hsv(rgba[0], rgba[1], rgba[2])
    return hue * 360.0, saturation, value


def read_colour_windows(kb: KnowledgeBase, camera: str | None = None) -> dict[str, tuple[ColourWindow, ...]]:
    """Each camera of the map's windows (or ``camera``'s only), by camera IRI, ordered by name: those it
    names; else those its nearest class names; else home:Camera's. A camera with none has an empty tuple
    (it tells no colour apart); a window the store describes badly raises :class:`ColourWindowError`."""
    rows = kb.select("colour_windows", None if camera is None else {"camera": NamedNode(camera)})
    by_camera: dict[str, list[dict[str, str]]] = defaultdict(list)
    for row in rows:
        by_camera[row["camera"].value].append({key: term.value for key, term in row.items()})
    windows: dict[str, tuple[ColourWindow, ...]] = {}
    for iri, found in by_camera.items():
        chosen = _nearest(iri, found)
        windows[iri] = tuple(sorted(_windows(chosen), key=lambda window: (window.name, window.iri)))
    return windows


def _nearest(camera: str, rows: list[dict[str, str]]) -> list[dict[str, str]]:
    """The rows of the windows that apply to ``camera``: its own, else its nearest class's, else home:Camera's."""
    own = [row for row in rows if row["source"] == camera]
    if own:
        return own
    classes = [row for row in rows if row["source"] not in (camera, HOME + "Camera")]
    if classes:
        nearest = min(int(row["distance"]) for row in classes)
        return [row for row in classes if int(row["distance"]) == nearest]
    return [row for row in rows if row["source"] == HOME + "Camera"]


def _windows(rows: Iterable[dict[str, str]]) -> list[ColourWindow]:
    said: dict[str, dict[str, set[str]]] = defaultdict(lambda: defaultdict(set))
    for row in rows:
        for key, value in row.items():
            said[row["window"]][key].add(value)
    return [_window(iri, values) for iri, values in sorted(said.items())]


_PROPERTY = {
    "name": "colourName",
    "hue": "hueCentre",
    "tolerance": "hueTolerance",
    "saturation": "minSaturation",
    "brightness": "minBrightness",
    "margin": "hueMargin",
    "rgba": "rgba",
}


def _one(iri: str, values: Mapping[str, set[str]], key: str) -> str | None:
    given = values.get(key, set())
    if len(given) > 1:
        shown = " and ".join(repr(value) for value in sorted(given))
        raise ColourWindowError(iri, f"has home:{_PROPERTY[key]} {shown}: one value is needed")
    return next(iter(given), None)


def _number(iri: str, values: Mapping[str, set[str]], key: str, low: float, high: float) -> float | None:
    text = _one(iri, values, key)
    if text is None:
        return None
    try:
        number = float(text)
    except ValueError:
        raise ColourWindowError(iri, f"has home:{_PROPERTY[key]} {text!r}, not a number") from None
    if not (low <= number <= high) or math.isnan(number):
        raise ColourWindowError(iri, f"has home:{_PROPERTY[key]} {text}; it must be from {low:g} to {high:g}")
    return number


def _window(iri: str, values: Mapping[str, set[str]]) -> ColourWindow:
    name = _one(iri, values, "name")
    hue = _number(iri, values, "hue", 0.0, 360.0)
    tolerance = _number(iri, values, "tolerance", 0.0, 180.0)
    for key, given in (("name", name), ("hue", hue), ("tolerance", tolerance)):
        if given is None:
            raise ColourWindowError(iri, f"has no home:{_PROPERTY[key]}: a window needs a name, a centre and a width")
    assert name is not None and hue is not None and tolerance is not None
    if tolerance <= 0:
        raise ColourWindowError(iri, f"has home:hueTolerance {tolerance:g}; it must be more than 0")
    saturation = _number(iri, values, "saturation", 0.0, 1.0)
    brightness = _number(iri, values, "brightness", 0.0, 1.0)
    margin = _number(iri, values, "margin", 0.0, 180.0)
    return ColourWindow(
        name,
        hue,
        tolerance,
        DEFAULT_MIN_SATURATION if saturation is None else saturation,
        DEFAULT_MIN_VALUE if brightness is None else brightness,
        DEFAULT_HUE_MARGIN if margin is None else margin,
        _rgba(iri, _one(iri, values, "rgba")),
        iri,
    )


def _rgba(iri: str, text: str | None) -> tuple[float, float, float, float] | None:
    if text is None:
        return None
    try:
        parts = [float(part) for part in text.split()]
    except ValueError:
        parts = []
    if len(parts) == 3:
        parts.append(1.0)
    if len(parts) != 4 or not all(0.0 <= part <= 1.0 for part in parts):
        raise ColourWindowError(iri, f"has home:rgba {text!r}; write four numbers in 0..1")
    return (parts[0], parts[1], parts[2], parts[3])
