"""Whether a remote component's answer contradicts the effect its step was chosen for.

A component in another process reports what it did in its outputs: a kitchen light's ``lampStatus``.
The type check (``sim.values.check``) only asks whether a value is of the output's class
(``home:DeviceStatus``); an answer of ``home:SwitchedOff`` to a step whose effect is ``(home:Lamp,
home:hasStatus, home:SwitchedOn)`` passes it, and the lamp would be believed on. Here an answer is
read against the effects as well (docs/execution.md, "An answer that contradicts the effect"):

- an output *reports* an effect when the effect's object is a class at or below the output's class
  (``home:SwitchedOn`` is a ``home:DeviceStatus``): the value could be the effect's outcome;
- the answered value *contradicts* that effect when the store says its class shares no instance with
  the effect's object: the two, or a superclass of each, are declared disjoint (``owl:disjointWith``,
  ``owl:AllDisjointClasses``; the named query ``taxonomy_disjoint``), so a subclass of
  ``home:SwitchedOff`` contradicts ``home:SwitchedOn`` too;
- an output that reports several effects contradicts only when it contradicts every one of them (some
  reading of the answer agrees with the step otherwise);
- the same class, a subclass or a superclass of the effect's object is no contradiction (a superclass
  says less, not otherwise), nor is a class the store does not know: nothing proves it is not the
  effect's, so the step is believed as before and the answer noted (:attr:`Reading.unknown`).

An answer may also *designate* a thing of the world (``{"@id": ..., "@type": ...}``), and its ``@type`` is
the component's word only. A thing the semantic map states classes of is checked against them
(:func:`check_designation`): one of them must be the answered class or below it (so, as the type check
already asked that of the answered class, of the port's), or the answer points at the wrong thing, the
pen for a weight, and is refused with :class:`WrongThingError`. A thing the map does not know, or
states no class of, is taken on the component's word, as before.

The store's classes are read by two named queries (``subclasses``, ``taxonomy_disjoint``), once, at the
first answer that needs them; a designated thing's by ``map_types``, once per thing.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from pyoxigraph import NamedNode

from cbrs.actions.errors import ActionsError
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.kb.namespaces import expand, shorten

__all__ = [
    "CONTRADICTIONS",
    "Classes",
    "ContradictedEffectError",
    "Reading",
    "StoreClasses",
    "UnitInTextError",
    "UnknownTypeError",
    "WrongThingError",
    "check_designation",
    "check_quantities",
    "class_named",
    "read_answer",
]

CONTRADICTIONS = ("fail", "warn")
"""What a run does with an answer that contradicts its step's effect (setting ``remote_contradictions``):
fail the step (the default), or take the answer as before and log a warning."""


class Classes(Protocol):
    """What the store knows of classes: enough to tell whether two share no instance."""

    def known(self, concept: str) -> bool:
        """Whether the store declares ``concept`` a class."""

    def is_a(self, concept: str, superclass: str) -> bool:
        """Whether ``concept`` is ``superclass`` or below it."""

    def disjoint(self, first: str, second: str) -> bool:
        """Whether the store says no instance of ``first`` is one of ``second``."""


class ContradictedEffectError(ActionsError):
    """A remote component answered a value the store says its step's effect excludes: a light asked to
    switch on answering that it is off. Keeps the component, its service, the output, the class
    answered and the effect contradicted."""

    def __init__(self, component: str, service: str, output: str, answered: str, effect: Statement) -> None:
        self.component, self.service, self.output = component, service, output
        self.answered, self.effect = answered, effect
        super().__init__(
            f"{shorten(component)} ({service}) answered {output} = {shorten(answered)}, which contradicts its"
            f" effect ({_text(effect)}): the store declares {shorten(answered)} disjoint with"
            f" {shorten(effect.object)}; nothing of the answer is believed (a handler that could not act should"
            " raise instead; docs/execution.md)"
        )


class UnknownTypeError(ActionsError, ValueError):
    """A value's ``@type`` that names no class: a prefix nobody declared (``hom:Cup``, with the prefixes
    nearest it) or none at all. Taken as typed, it was of no class the store knows, and the value matched
    nothing without a word. Keeps the ``@type`` as ``written``; a ``ValueError``, as every name that does
    not read is."""

    def __init__(self, written: str, reason: str) -> None:
        self.written = written
        super().__init__(f"the '@type' {written!r} names no class: {reason}")


def class_named(written: str) -> str:
    """The class ``written`` (a value's ``@type``: an IRI or a prefixed name) names, in full;
    :class:`UnknownTypeError` when it names none."""
    try:
        return expand(written)
    except UnknownPrefixError as error:
        raise UnknownTypeError(written, error.reason) from error
    except ValueError as error:
        raise UnknownTypeError(written, "no IRI and no prefixed name") from error


class WrongThingError(ActionsError, ValueError):
    """A remote answer designates a thing the store knows as no instance of the class answered: the pen
    as a weight. Keeps the port's class, the thing, the class answered and the thing's stated classes;
    a ``ValueError``, so the answer check fails the step that produced it (``actions.remote``)."""

    def __init__(self, concept: str, thing: str, answered: str, classes: Iterable[str]) -> None:
        self.concept, self.thing, self.answered = concept, thing, answered
        self.classes = tuple(sorted(classes))
        stated = ", ".join(shorten(c) for c in self.classes)
        super().__init__(
            f"it designates {shorten(thing)}, a {stated} by the store's map and no {shorten(answered)}: a value of"
            f' {shorten(concept)} was expected, not another thing (docs/execution.md, "An answer that points at'
            ' the wrong thing")'
        )


def check_designation(concept: str, value: Any, classes: StoreClasses) -> None:
    """Refuse (:class:`WrongThingError`) a checked value of port class ``concept`` that designates a
    thing of the map stated to be of no class at or below its ``@type`` (the module's rule)."""
    if not isinstance(value, dict) or not isinstance(value.get("@id"), str):
        return
    thing, answered = value["@id"], _class_of(value)
    stated = classes.classes_of(thing)
    if answered is None or not stated or any(classes.is_a(c, answered) for c in stated):
        return
    raise WrongThingError(concept, thing, answered, stated)


MEASUREMENT = expand("home:Measurement")
"""The class whose values carry quantities: a temperature, a humidity, a weight, a distance."""

_NUMBER_WITH_UNIT = re.compile(
    r"\s*(?P<number>[-+]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][-+]?\d+)?)\s*(?P<unit>[%°µA-Za-z][^\d\s:-]*)?\s*"
)
"""A number as text, with a unit (letters, %, °) or none; a date or a time ("2026-11-28", "12:30") is not one."""


class UnitInTextError(ActionsError, ValueError):
    """A remote answer of a measurement gives a quantity as text, a number with its unit in it
    (``"percent": "47.5 %"``): values carry numbers as JSON numbers, in the units docs/values.md fixes, so
    the reading would be passed on as a text no consumer can compare. Keeps the class, the key and the
    text; a ``ValueError``, so the answer check fails the step that produced it (``actions.remote``)."""

    def __init__(self, concept: str, key: str, text: str, number: str, unit: str | None) -> None:
        self.concept, self.key, self.text, self.unit = concept, key, text, unit
        what = f"a number with its unit ({unit!r}) written as text" if unit else "a number written as text"
        super().__init__(
            f"malformed {shorten(concept)}: {key!r} is {text!r}, {what}: a value carries a quantity as a JSON "
            "number, in the units the conventions fix (docs/values.md), the unit in the key's name if need be "
            f'("{key}": {number.replace(",", ".")})'
        )


def check_quantities(concept: str, value: Any, classes: Classes) -> None:
    """Refuse (:class:`UnitInTextError`) a value of a measurement class (``home:Measurement`` or below) one
    of whose keys is a number written as text, with or without a unit: a lab's hygrometer answering
    ``{"@type": "home:Humidity", "percent": "47.5 %"}`` was believed, and its reading passed on as the text
    (docs/tasks.md, "An eighth round"). Classes with a JSON shape of their own are checked by their shape."""
    if not isinstance(value, dict) or not classes.is_a(concept, MEASUREMENT):
        return
    for key, field_value in value.items():
        if key.startswith("@") or not isinstance(field_value, str):
            continue
        found = _NUMBER_WITH_UNIT.fullmatch(field_value)
        if found is not None:
            raise UnitInTextError(concept, key, field_value, found.group("number"), found.group("unit"))


def _text(statement: Statement) -> str:
    return f"{shorten(statement.subject)}, {shorten(statement.predicate)}, {shorten(statement.object)}"


@dataclass(frozen=True)
class Reading:
    """What an answer says about the step's effects: the first output that contradicts them (with the
    class answered and the effect), and the answered classes the store does not know (output, class)."""

    contradiction: tuple[str, str, Statement] | None = None
    unknown: tuple[tuple[str, str], ...] = ()


def read_answer(
    outputs: Mapping[str, Any], types: Mapping[str, str], effects: Iterable[Statement], classes: Classes
) -> Reading:
    """Read each output's value (``outputs``, checked, with its ``@type``) of class ``types[name]``
    against the ``effects`` it reports (the module's definition)."""
    effects = tuple(effects)
    unknown: list[tuple[str, str]] = []
    for name, concept in types.items():
        answered = _class_of(outputs.get(name))
        reported = [e for e in effects if classes.known(e.object) and classes.is_a(e.object, concept)]
        if answered is None or not reported:
            continue
        if not classes.known(answered):
            unknown.append((name, answered))
            continue
        against = [e for e in reported if classes.disjoint(answered, e.object)]
        if len(against) == len(reported):
            return Reading((name, answered, against[0]), tuple(unknown))
    return Reading(None, tuple(unknown))


def _class_of(value: Any) -> str | None:
    """The class a value names by its ``@type`` (expanded), None for a value with none;
    :class:`UnknownTypeError` for an ``@type`` that names no class."""
    written = value.get("@type") if isinstance(value, dict) else None
    if not isinstance(written, str) or not written:
        return None
    return class_named(written)


@dataclass
class StoreClasses:
    """:class:`Classes` from a store, read by two named queries at the first question."""

    kb: KnowledgeBase
    _up: dict[str, frozenset[str]] | None = field(default=None, repr=False)
    _declared: dict[str, set[str]] = field(default_factory=dict, repr=False)
    _things: dict[str, frozenset[str]] = field(default_factory=dict, repr=False)

    def _read(self) -> dict[str, frozenset[str]]:
        if self._up is None:
            up: dict[str, set[str]] = {}
            for row in self.kb.select("subclasses"):
                up.setdefault(row["class"].value, {row["class"].value}).add(row["superclass"].value)
            for row in self.kb.select("taxonomy_disjoint"):
                first, second = row["first"].value, row["second"].value
                self._declared.setdefault(first, set()).add(second)
                self._declared.setdefault(second, set()).add(first)
            self._up = {concept: frozenset(above) for concept, above in up.items()}
        return self._up

    def known(self, concept: str) -> bool:
        return concept in self._read()

    def classes_of(self, thing: str) -> frozenset[str]:
        """The classes the semantic map's graph states ``thing`` is (none for a thing it does not hold)."""
        found = self._things.get(thing)
        if found is None:
            rows = self.kb.select("map_types", {"thing": NamedNode(thing)})
            found = self._things[thing] = frozenset(row["type"].value for row in rows)
        return found

    def is_a(self, concept: str, superclass: str) -> bool:
        return concept == superclass or superclass in self._read().get(concept, ())

    def disjoint(self, first: str, second: str) -> bool:
        up = self._read()
        above_second = up.get(second, frozenset({second}))
        return any(self._declared.get(a, set()) & above_second for a in up.get(first, frozenset({first})))
