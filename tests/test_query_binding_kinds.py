"""A value bound to a named query's parameter is of the parameter's kind, or a ``BindingError`` naming the
parameter and the value: a literal bound to an IRI parameter (``ox.Literal("home:Cup")``) matched nothing
and gave no rows, a number bound to an integer parameter lost its fraction (``int(3.7)``), an infinite or
NaN decimal and one written with an exponent (``1e-05``, no lexical form of xsd:decimal) were bound
as they came."""

from __future__ import annotations

import re

import pyoxigraph as ox
import pytest

from cbrs.kb import BindingError, KnowledgeBase
from cbrs.kb.namespaces import XSD
from cbrs.kb.queries import Parameter, to_term


def test_a_literal_bound_to_an_iri_parameter_is_refused(bundled_kb: KnowledgeBase) -> None:
    with pytest.raises(BindingError, match="a literal, where the query takes an IRI") as refused:
        bundled_kb.select("things_in_room", {"class": ox.Literal("home:Cup"), "room": "world:Kitchen"})
    assert refused.value.variable == "class"
    assert bundled_kb.select("things_in_room", {"class": "home:Cup", "room": "world:Kitchen"})  # as a name: rows


@pytest.mark.parametrize(
    ("kind", "value", "written"),
    [
        pytest.param("integer", 3, "3", id="int"),
        pytest.param("integer", "3", "3", id="int-text"),
        pytest.param("integer", 3.0, "3", id="whole-float"),
        pytest.param("decimal", 1e-05, "0.00001", id="small-decimal"),
        pytest.param("decimal", "2.5", "2.5", id="decimal-text"),
    ],
)
def test_numbers_of_their_kind_are_bound(kind: str, value: str | float, written: str) -> None:
    assert to_term(Parameter("n", kind, False, ""), value) == ox.Literal(written, datatype=ox.NamedNode(XSD + kind))


@pytest.mark.parametrize(
    ("kind", "value", "said"),
    [
        pytest.param("integer", 3.7, "3.7 is not a whole number", id="fraction"),
        pytest.param("integer", True, "True is a truth value", id="bool"),
        pytest.param("decimal", "nan", "'nan' is no finite number", id="nan"),
        pytest.param("decimal", "1e400", "'1e400' is no finite number", id="infinite"),
        pytest.param(
            "integer", ox.NamedNode("http://example.org/n"), "an IRI, where the query takes an integer", id="iri"
        ),
    ],
)
def test_a_value_not_of_its_kind_is_refused_naming_it(kind: str, value: object, said: str) -> None:
    with pytest.raises(BindingError, match=re.escape(said)) as refused:
        to_term(Parameter("n", kind, False, ""), value)  # type: ignore[arg-type]
    assert refused.value.variable == "n" and refused.value.value == value
