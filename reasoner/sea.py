"""The service effective area (SEA): whether an advertised area covers, or reaches into, a wanted one.

One rule for matchmaking's SEA filter and for composition's steps (``cbrs.actions.areas``): when both
sides give a bounding box, the wanted box must lie inside the offered one; otherwise every wanted area
concept must be an offered area or below one by is-a or has-part links (a room that is part of the
home). A side that states no area, or that gives nothing the other can be compared with, does not
filter: an advertisement without an SEA model is effective everywhere.
"""

from __future__ import annotations

from cbrs.kb import EffectiveArea
from cbrs.reasoner.names import local_name
from cbrs.reasoner.taxonomy import TaxonomyIndex

Bounds = tuple[float, float, float, float]  # min x, max x, min y, max y

_EPS = 1e-9


def uncovered(index: TaxonomyIndex, wanted: EffectiveArea | None, offered: EffectiveArea | None) -> list[str]:
    """Why ``offered`` does not cover ``wanted`` (empty: it does, or a side states nothing to compare)."""
    reasons: list[str] = []
    if not wanted or not offered:
        return reasons
    if wanted.bounds and offered.bounds:
        if not within(wanted.bounds, offered.bounds):
            reasons.append(f"SEA: effective area {offered.bounds} does not cover {wanted.bounds}")
    elif wanted.areas and offered.areas:
        for area in wanted.areas:
            if not any(covers_concept(index, place, area) for place in offered.areas):
                reasons.append(f"SEA: {_short(area)} is outside {', '.join(map(_short, offered.areas))}")
    return reasons


def reaches(index: TaxonomyIndex, wanted: EffectiveArea | None, offered: EffectiveArea | None) -> bool:
    """Whether ``offered`` reaches into ``wanted`` at all: the boxes overlap (by more than an edge) when
    both give one, else some concept of one side is, or is below, some concept of the other. True when
    a side states nothing to compare."""
    if not wanted or not offered:
        return True
    if wanted.bounds and offered.bounds:
        return overlap(wanted.bounds, offered.bounds)
    if wanted.areas and offered.areas:
        return any(
            covers_concept(index, a, b) or covers_concept(index, b, a) for a in wanted.areas for b in offered.areas
        )
    return True


def covers_concept(index: TaxonomyIndex, place: str, area: str) -> bool:
    """``place`` covers ``area`` when it is the same, a superclass, or a whole it is part of."""
    if place == area:
        return True
    return area in index and place in index and index.distance_down(area, place) is not None


def within(inner: Bounds, outer: Bounds) -> bool:
    return (
        inner[0] >= outer[0] - _EPS
        and inner[1] <= outer[1] + _EPS
        and inner[2] >= outer[2] - _EPS
        and inner[3] <= outer[3] + _EPS
    )


def overlap(a: Bounds, b: Bounds) -> bool:
    """Whether two boxes share more than an edge: on each axis they meet, and where both have an extent
    the shared part has one too (rooms that only touch along a wall do not overlap; a point inside does)."""
    for low, high in ((0, 1), (2, 3)):
        start, end = max(a[low], b[low]), min(a[high], b[high])
        if start > end + _EPS:
            return False
        if a[high] - a[low] > _EPS and b[high] - b[low] > _EPS and end - start <= _EPS:
            return False
    return True


def _short(iri: str) -> str:
    return local_name(iri) if "://" in iri else iri


__all__ = ["Bounds", "covers_concept", "overlap", "reaches", "uncovered", "within"]
