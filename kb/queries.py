"""Named SPARQL queries: one ``queries/<name>.rq`` file each, run by name with bound values.

A query file declares its title and parameters in its leading comments::

    # title: Advertisements with their inputs and outputs
    # param: service iri  Only this advertisement (optional)
    # param: kind iri required  The component kind

A parameter's value is substituted for the variable of the same name by Oxigraph
(SEP-0007 substitution), never pasted into the query text.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cbrs.kb.errors import BindingError, UnknownQueryError
from cbrs.kb.namespaces import XSD, expand
from cbrs.kb.results import releases_results
from cbrs.kb.store import QueryResult, Store, Term

PARAMETER_KINDS = ("iri", "string", "integer", "decimal", "literal")
_PARAM_LINE = re.compile(r"^#\s*param:\s*(\w+)\s+(\w+)(\s+required)?\s*(.*)$")
_TITLE_LINE = re.compile(r"^#\s*title:\s*(.+)$")


@dataclass(frozen=True)
class Parameter:
    name: str
    kind: str
    required: bool
    description: str


@dataclass(frozen=True)
class NamedQuery:
    name: str
    title: str
    text: str
    parameters: dict[str, Parameter] = field(default_factory=dict)

    def bind(self, values: Mapping[str, Term | str | int | float]) -> dict[str, Term]:
        """Check ``values`` against the declared parameters and turn them into RDF terms."""
        unknown = sorted(set(values) - set(self.parameters))
        if unknown:
            declared = ", ".join(self.parameters) or "none"
            raise BindingError(
                unknown[0],
                values[unknown[0]],
                f"query {self.name!r} takes no such parameter (it takes: {declared})",
            )
        missing = [p for p in self.parameters.values() if p.required and p.name not in values]
        if missing:
            first = missing[0]
            what = f"{first.kind}: {first.description}" if first.description else first.kind
            raise BindingError(first.name, None, f"query {self.name!r} needs this parameter ({what})")
        return {name: to_term(self.parameters[name], value) for name, value in values.items()}


def to_term(parameter: Parameter, value: Term | str | int | float) -> Term:
    """The RDF term for ``value`` as the parameter's kind reads it (``svc:X`` or a full IRI for iri). A term
    given is taken when it is of the parameter's kind: a literal bound to an IRI parameter (``"home:Cup"``
    as ``ox.Literal``) matched nothing, and a number bound to an integer one lost its fraction, without a
    word; each is a :class:`BindingError` naming the parameter and the value."""
    if isinstance(value, ox.NamedNode | ox.BlankNode | ox.Literal):
        if (parameter.kind == "iri") != (not isinstance(value, ox.Literal)):
            given, wanted = ("a literal", "IRI") if isinstance(value, ox.Literal) else ("an IRI", parameter.kind)
            raise BindingError(parameter.name, value, f"{given}, where the query takes {_article(wanted)}")
        return value
    try:
        if parameter.kind == "iri":  # white space around an IRI is a paste's, never the IRI's (IRIs have none)
            return ox.NamedNode(expand(str(value).strip()))
        if parameter.kind == "integer":
            return ox.Literal(str(_whole(value)), datatype=ox.NamedNode(XSD + "integer"))
        if parameter.kind == "decimal":
            number = float(value)
            if not math.isfinite(number) or isinstance(value, bool):
                raise ValueError(f"{value!r} is no finite number")
            # xsd:decimal has no exponent: 1e-05 is written 0.00001
            return ox.Literal(format(Decimal(repr(number)), "f"), datatype=ox.NamedNode(XSD + "decimal"))
        return ox.Literal(str(value))
    except ValueError as error:
        raise BindingError(parameter.name, value, f"not a valid {parameter.kind}: {error}") from error


def _article(kind: str) -> str:
    return f"an {kind}" if kind[0] in "aeiouAEIOU" else f"a {kind}"


def _whole(value: str | int | float) -> int:
    """``value`` as a whole number: ``3``, ``"3"`` and ``3.0`` are, ``3.7`` is refused (``int`` cut it to 3)."""
    if isinstance(value, bool):
        raise ValueError(f"{value!r} is a truth value")
    if isinstance(value, float):
        if not value.is_integer():
            raise ValueError(f"{value!r} is not a whole number")
        return int(value)
    return int(value)


class QueryLibrary:
    """The named queries found in one folder."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self._queries = {path.stem: _read(path) for path in sorted(folder.glob("*.rq"))}

    def names(self) -> list[str]:
        return list(self._queries)

    def get(self, name: str) -> NamedQuery:
        try:
            return self._queries[name]
        except KeyError:
            raise UnknownQueryError(name, self.names()) from None

    def run(self, store: Store, name: str, values: Mapping[str, Term | str | int | float] | None = None) -> QueryResult:
        query = self.get(name)
        return store.query(query.text, query.bind(values or {}))

    def select(
        self, store: Store, name: str, values: Mapping[str, Term | str | int | float] | None = None
    ) -> list[dict[str, Term]]:
        """Rows of a SELECT query as dicts from variable name to term (unbound variables left out)."""
        return _rows(name, self.run(store, name, values))

    def select_each(
        self, store: Store, asked: Sequence[tuple[str, Mapping[str, Term | str | int | float]]]
    ) -> list[list[dict[str, Term]]]:
        """The rows of each named SELECT query with its values, as :meth:`select` gives them, asked for
        at once (:meth:`Store.select_each`: one request to a remote store). Values of none bound give a
        query's rows for every value, as :meth:`select_every`."""
        bound = [(self.get(name).text, self.get(name).bind(values) if values else {}) for name, values in asked]
        return store.select_each(bound)

    def select_every(self, store: Store, name: str) -> list[dict[str, Term]]:
        """Rows of a SELECT query for every value of its parameters at once: the query run with none
        bound, required ones included. Every parameter is projected (tests/test_queries.py checks it),
        so each row names the value it belongs to; a reader that needs the rows of many values makes
        one pass over the store instead of one query per value (a query costs milliseconds on disk)."""
        return _rows(name, store.query(self.get(name).text, {}))


@releases_results
def _rows(name: str, result: QueryResult) -> list[dict[str, Term]]:
    if not isinstance(result, ox.QuerySolutions):
        raise TypeError(f"query {name!r} is not a SELECT query")
    return _read_rows([v.value for v in result.variables], result)


@releases_results
def _read_rows(names: list[str], solutions: Iterable[Any]) -> list[dict[str, Term]]:
    """Read ``solutions`` whole, on this thread even when reading fails half way (:mod:`cbrs.kb.results`)."""
    return [{n: row[n] for n in names if row[n] is not None} for row in solutions]


def _read(path: Path) -> NamedQuery:
    text = path.read_text(encoding="utf-8")
    title = path.stem.replace("_", " ")
    parameters: dict[str, Parameter] = {}
    for line in text.splitlines():
        if not line.startswith("#"):
            if line.strip():
                break
            continue
        if match := _TITLE_LINE.match(line):
            title = match.group(1).strip()
        elif match := _PARAM_LINE.match(line):
            name, kind, required, description = match.groups()
            if kind not in PARAMETER_KINDS:
                raise ValueError(f"{path}: parameter {name} has unknown kind {kind!r}; use one of {PARAMETER_KINDS}")
            parameters[name] = Parameter(name, kind, bool(required), description.strip())
    return NamedQuery(path.stem, title, text, parameters)
