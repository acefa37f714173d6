"""The arm behind a side grasp: where it is, in bands back from the grasp point, as the store describes it.

A hand coming in from the side has its wrist and forearm behind it, lower than the hand: a cup carried by
its side past a second cup 20 cm behind its way knocked that one off the table until the carry kept the
arm over it. The gripper names the bands of its arm (``home:sideGraspBand``, each a ``home:ArmBand`` with
``home:bandFrom``, ``home:bandTo``, ``home:bandHalfWidth`` and ``home:bandUnderside``), on itself or once
on a class of grippers; a gripper that names none has :data:`PANDA_SIDE_ARM`, the arm of every simulated
robot. The named query ``side_grasp_bands`` reads them; :func:`kb.hands.read_hands` puts them on each
:class:`~kb.hands.Hand` and reports a band no arm can have (:func:`band_problem`).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.store import Term

__all__ = ["BAND_PROPERTIES", "PANDA_SIDE_ARM", "ArmBand", "StatedBands", "band_problem", "stated_bands"]

HOME = PREFIXES["home"]


@dataclass(frozen=True)
class ArmBand:
    """Where the arm is behind a side grasp's grasp point: from ``near`` to ``far`` back along the approach
    (m, level) and ``half_width`` either side of it, no part of the arm but the fingers is lower than
    ``underside`` above the grasp point (below it when negative)."""

    near: float
    far: float
    half_width: float
    underside: float


PANDA_SIDE_ARM = (ArmBand(0.0, 0.175, 0.10, 0.01), ArmBand(0.175, 0.325, 0.10, -0.03))
"""The Franka Panda arm behind a side grasp tilted down by the default 35 degrees: the hand, rising back
from the grasp point, and the wrist and forearm, 17.5-32.5 cm back, as low as 3 cm below it. Measured on
the simulated arms' kinematics (``ontologies/world.ttl`` states the same bands on the bundled robot's hands,
with how; tests/test_designate_subclass.py checks a sample): the bands of a gripper that names none."""

BAND_PROPERTIES = ("bandFrom", "bandTo", "bandHalfWidth", "bandUnderside")
"""The store's properties (local names in the home namespace) of :class:`ArmBand`'s values, in its order."""
_COLUMNS = ("from", "to", "halfWidth", "underside")


@dataclass(frozen=True)
class StatedBands:
    """The bands a gripper names through ``source`` (itself, or a class of it ``distance`` classes up):
    for each band node, each property's values as the store states them (empty when missing)."""

    source: str
    distance: int
    bands: dict[str, dict[str, tuple[str, ...]]]


def stated_bands(rows: Iterable[Mapping[str, Term]]) -> dict[str, list[StatedBands]]:
    """What the store states of the bands of each gripper (by gripper IRI), from the rows of the named
    query ``side_grasp_bands``: per source, nearest first."""
    found: dict[str, dict[tuple[str, int], dict[str, dict[str, set[str]]]]] = defaultdict(dict)
    for row in rows:
        key = (row["source"].value, int(row["distance"].value))
        band = found[row["hand"].value].setdefault(key, {}).setdefault(row["band"].value, defaultdict(set))
        for name, column in zip(BAND_PROPERTIES, _COLUMNS, strict=True):
            if column in row:
                band[name].add(row[column].value)
    return {
        hand: [
            StatedBands(source, distance, {band: _sorted(values) for band, values in bands.items()})
            for (source, distance), bands in sorted(by_source.items(), key=lambda item: (item[0][1], item[0][0]))
        ]
        for hand, by_source in found.items()
    }


def _sorted(values: Mapping[str, set[str]]) -> dict[str, tuple[str, ...]]:
    return {name: tuple(sorted(values.get(name, ()))) for name in BAND_PROPERTIES}


def band_problem(band: ArmBand) -> tuple[str, str]:
    """Why ``band`` cannot be where an arm is, as the property at fault and the reason (empty if it can)."""
    for name, number in zip(BAND_PROPERTIES, (band.near, band.far, band.half_width, band.underside), strict=True):
        if not math.isfinite(number):
            return name, "write a finite number"
    if band.near < 0.0:
        return "bandFrom", "a length in metres back from the grasp point, at least 0"
    if band.far <= band.near:
        return "bandTo", f"a band ends further back than it begins (home:bandFrom {band.near:g})"
    if band.half_width <= 0.0:
        return "bandHalfWidth", "a length in metres, more than 0"
    return "", ""
