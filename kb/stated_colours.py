"""A thing's colour the map states, and the colour preconditions it decides.

The map gives each thing the colour perception finds it by, a name (``home:colourName "green"``); the
ontology's colours are classes (``home:Green``), what a task's precondition names: ``(home:Mug,
home:hasColour, home:Green)``. The two meet at the colour windows, which are what a name means to a camera:
a window has the name (``home:GreenWindow home:colourName "green"``) and is tied to the class whose things it
finds (``home:windowColour home:Green``). So a thing of the map is of the class of every window of its name,
and ``(thing, home:hasColour, K)`` holds when one of those classes is ``K`` or below it, and is false when it
has some and none is: the map paints a thing one colour, and what the map states of a thing is what the
store knows of it. A thing whose name no window has, or whose windows are tied to no class, has its colour
decided by nothing. Used where a task's class names several things, to tell them apart by what its
preconditions guarantee of the one it means (:meth:`kb.stated_quantities.StatedQuantities.meeting`).
docs/execution.md, "A thing's colour stated in the map".
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from cbrs.kb.namespaces import PREFIXES

__all__ = ["COLOUR", "HAS_COLOUR", "StatedColours"]

HAS_COLOUR = PREFIXES["home"] + "hasColour"
COLOUR = PREFIXES["home"] + "Colour"


@dataclass(frozen=True)
class StatedColours:
    """The colour classes each thing of the map is of by its colour name (named query ``thing_colours``), and
    that name, by thing."""

    classes: Mapping[str, frozenset[str]]
    names: Mapping[str, str] = field(default_factory=dict)

    @classmethod
    def of_rows(cls, rows: Iterable[Mapping[str, Any]]) -> StatedColours:
        found: dict[str, set[str]] = {}
        names: dict[str, str] = {}
        for row in rows:
            found.setdefault(row["thing"].value, set()).add(row["colour"].value)
            names[row["thing"].value] = row["name"].value
        return cls({thing: frozenset(classes) for thing, classes in found.items()}, names)

    def decide(self, thing: str, colour: str, is_a: Callable[[str, str], bool]) -> bool | None:
        """Whether ``thing`` has ``colour`` (a class at or below ``home:Colour``) by its colour name: one of its
        classes is ``colour`` or below it (``is_a``); None where its name ties it to no class."""
        classes = self.classes.get(thing)
        if not classes:
            return None
        return any(is_a(each, colour) for each in classes)
