"""Statuses a measured quantity decides, and the units readings give quantities in.

A status class may say with ``home:holdsWhen`` under what reading it holds of a place: a
``home:MeasuredCondition`` names the quantity (``home:measuredQuantity``, a class under
``home:Measurement``), one bound or both (``home:atLeast`` included, ``home:below`` not) and the unit
they are in (``qudt:hasUnit``). ``lab9:Dark``: a ``home:Illuminance`` below 50 lx. Knowledge about the
lab's words, so it lives in the store (docs/ontologies.md, "Measured states"); the named query
``measured_conditions`` reads it and :func:`read_conditions` checks each.

A reading is a value of its quantity's class whose key names its unit (``{"@type": "home:Illuminance",
"lux": 12.0}``, docs/values.md); the store says which unit a key is (``home:readingKey``) and how each
converts to the SI unit of its quantity kind (``qudt:conversionMultiplier``, ``qudt:conversionOffset``),
read by the named query ``reading_units`` into :class:`Units`. Two units convert where they are of one
quantity kind; any other comparison is a :class:`UnitError` naming the unit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import shorten

if TYPE_CHECKING:
    from cbrs.kb.knowledge_base import KnowledgeBase

__all__ = [
    "MeasuredCondition",
    "MeasuredConditionError",
    "Reading",
    "UnitError",
    "Units",
    "conditions_by_status",
    "read_conditions",
]


class MeasuredConditionError(KnowledgeBaseError):
    """A status's ``home:holdsWhen`` condition the store states so that no reading can decide it: no
    quantity, no bound, no unit, several of one, or a lower bound not under the upper. Keeps the status
    and what is wrong."""

    http_status = 422

    def __init__(self, status: str, wrong: str) -> None:
        self.status, self.wrong = status, wrong
        super().__init__(
            f"the measured condition of {shorten(status)} (home:holdsWhen) {wrong}: a condition names one"
            " home:measuredQuantity, a home:atLeast or a home:below or both, and one qudt:hasUnit"
            ' (docs/ontologies.md, "Measured states")'
        )


class UnitError(KnowledgeBaseError):
    """A quantity in a unit the store cannot compare with the one wanted: a reading under a key no unit
    has (``home:readingKey``), a unit the store gives no conversion for, or a unit of another quantity
    kind. Keeps the unit (or key) and the unit wanted."""

    http_status = 422

    def __init__(self, unit: str, wanted: str, why: str) -> None:
        self.unit, self.wanted = unit, wanted
        super().__init__(f"{why}; it cannot be compared with {shorten(wanted)}")


@dataclass(frozen=True)
class Unit:
    iri: str
    key: str
    kind: str | None
    multiplier: float | None
    offset: float
    symbol: str


@dataclass(frozen=True)
class Reading:
    """A number a reading gives and the unit its key names."""

    value: float
    unit: str
    key: str


@dataclass(frozen=True)
class Units:
    """The units the store gives reading keys for, by IRI and by key."""

    by_iri: Mapping[str, Unit]

    @classmethod
    def read(cls, kb: KnowledgeBase) -> Units:
        found: dict[str, Unit] = {}
        for row in kb.select("reading_units"):
            iri = row["unit"].value
            if iri in found:
                continue
            found[iri] = Unit(
                iri,
                row["key"].value,
                row["kind"].value if "kind" in row else None,
                _number(row, "multiplier"),
                _number(row, "offset") or 0.0,
                row["symbol"].value if "symbol" in row else "",
            )
        return cls(found)

    def symbol(self, unit: str) -> str:
        """How ``unit`` is written after a number (``lx``), else its short name."""
        known = self.by_iri.get(unit)
        return known.symbol if known is not None and known.symbol else shorten(unit)

    def reading(self, value: Any, wanted: str) -> Reading:
        """The number a reading (a value's JSON) gives under the key of a unit the store knows, the one of
        ``wanted``'s quantity kind if it gives several; :class:`UnitError` naming its keys when it gives a
        number under no known unit's key, or none at all."""
        keys = {unit.key: unit for unit in self.by_iri.values()}
        numbers = {
            key: float(number)
            for key, number in (value.items() if isinstance(value, dict) else ())
            if not key.startswith("@") and isinstance(number, int | float) and not isinstance(number, bool)
        }
        known = [key for key in numbers if key in keys]
        if not known:
            what = ", ".join(f"{key!r}" for key in numbers) or "no number"
            raise UnitError(
                ", ".join(numbers) or "?",
                wanted,
                f"the reading {_json(value)} gives {what} under no unit's key the store knows (home:readingKey:"
                f" {', '.join(sorted(keys)) or 'none'})",
            )
        kind = self.by_iri[wanted].kind if wanted in self.by_iri else None
        same = [key for key in known if keys[key].kind == kind] or known
        key = same[0]
        return Reading(numbers[key], keys[key].iri, key)

    def convert(self, value: float, unit: str, wanted: str) -> float:
        """``value`` in ``unit`` given in ``wanted``, through the SI unit of their quantity kind."""
        if unit == wanted:
            return value
        source, target = self.by_iri.get(unit), self.by_iri.get(wanted)
        for iri, known in ((unit, source), (wanted, target)):
            if known is None or known.multiplier is None or known.kind is None:
                raise UnitError(
                    iri,
                    wanted if iri == unit else unit,
                    f"the store gives {shorten(iri)} no reading key, quantity"
                    " kind or conversion (home:readingKey, qudt:hasQuantityKind, qudt:conversionMultiplier)",
                )
        assert source is not None and target is not None and source.multiplier and target.multiplier
        if source.kind != target.kind:
            raise UnitError(
                unit,
                wanted,
                f"{shorten(unit)} is a unit of {shorten(source.kind or '')}, not of {shorten(target.kind or '')}",
            )
        return (value * source.multiplier + source.offset - target.offset) / target.multiplier


@dataclass(frozen=True)
class MeasuredCondition:
    """Under which reading ``status`` holds of a place: a reading of ``quantity`` (or a class below it) at
    least ``at_least`` and below ``below`` (None: unbounded that side), both in ``unit``."""

    status: str
    quantity: str
    at_least: float | None
    below: float | None
    unit: str

    def holds(self, value: float) -> bool:
        """Whether a reading of ``value`` in :attr:`unit` meets the condition."""
        return (self.at_least is None or value >= self.at_least) and (self.below is None or value < self.below)

    def text(self, units: Units) -> str:
        """``below 50 lx``, ``at least 18 °C and below 24 °C``."""
        symbol = units.symbol(self.unit)
        parts = [f"at least {self.at_least:g} {symbol}"] if self.at_least is not None else []
        parts += [f"below {self.below:g} {symbol}"] if self.below is not None else []
        return " and ".join(parts)


def read_conditions(kb: KnowledgeBase) -> dict[str, MeasuredCondition]:
    """Each status class's measured condition (the named query ``measured_conditions``), checked:
    :class:`MeasuredConditionError` for the first no reading can decide."""
    found: dict[str, MeasuredCondition] = {}
    for status, condition in conditions_by_status(kb).items():
        if isinstance(condition, MeasuredConditionError):
            raise condition
        found[status] = condition
    return found


def conditions_by_status(kb: KnowledgeBase) -> dict[str, MeasuredCondition | MeasuredConditionError]:
    """Each status class's measured condition, or the error that says why no reading can decide it: a
    run raises it only for a status it asks about, so that a lab's broken condition of one status does
    not stop the tasks about another."""
    rows: dict[str, list[Mapping[str, Any]]] = {}
    for row in kb.select("measured_conditions"):
        rows.setdefault(row["status"].value, []).append(row)
    found: dict[str, MeasuredCondition | MeasuredConditionError] = {}
    for status, its in rows.items():
        try:
            found[status] = _condition(status, its)
        except MeasuredConditionError as error:
            found[status] = error
    return found


def _condition(status: str, its: list[Mapping[str, Any]]) -> MeasuredCondition:
    conditions = {row["condition"].value for row in its}
    if len(conditions) > 1:
        raise MeasuredConditionError(status, f"is {len(conditions)} conditions, where one is meant")
    values = {
        name: {row[name].value for row in its if name in row} for name in ("quantity", "atLeast", "below", "unit")
    }
    for name, prop in (("quantity", "home:measuredQuantity"), ("unit", "qudt:hasUnit")):
        if len(values[name]) != 1:
            raise MeasuredConditionError(status, f"has {len(values[name]) or 'no'} {prop}, where one is meant")
    bounds: list[float | None] = []
    for name, prop in (("atLeast", "home:atLeast"), ("below", "home:below")):
        if len(values[name]) > 1:
            raise MeasuredConditionError(status, f"has {len(values[name])} {prop}, where one at most is meant")
        try:
            bound = float(next(iter(values[name]))) if values[name] else None
        except ValueError:
            raise MeasuredConditionError(status, f"has {prop} {next(iter(values[name]))!r}, not a number") from None
        if bound is not None and not math.isfinite(bound):
            raise MeasuredConditionError(status, f"has {prop} {bound}, not a finite number")
        bounds.append(bound)
    at_least, below = bounds
    if at_least is None and below is None:
        raise MeasuredConditionError(status, "has no bound (home:atLeast, home:below)")
    if at_least is not None and below is not None and not at_least < below:
        raise MeasuredConditionError(status, f"holds at least {at_least:g} and below {below:g}, which nothing is")
    (quantity,), (unit,) = values["quantity"], values["unit"]
    return MeasuredCondition(status, quantity, at_least, below, unit)


def _number(row: Mapping[str, Any], name: str) -> float | None:
    if name not in row:
        return None
    try:
        value = float(row[name].value)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _json(value: Any) -> str:
    import json

    try:
        return json.dumps(value, sort_keys=True)
    except (TypeError, ValueError):
        return repr(value)
