"""The datatype choices of the shapes (shape:Number's numeric types, shape:Text's string types), settled
before pySHACL runs when no value could fail them (kb/shapes.py ``_shapes_for``): the same verdicts and
the same messages as checking against the whole shapes file, which the check still does for an input
with a value that might fail one (a word for a number, an ill-typed literal, an IRI for a name).

"Full" below is the check with the shortcut off (``_datatype_choices`` giving none), as it was before.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import pyoxigraph as ox
import pytest
import rdflib

import cbrs.kb.shapes as shapes
from cbrs.kb.namespaces import XSD
from cbrs.kb.resources import ontology_dir
from cbrs.kb.shapes import DescriptionShapeError, check_descriptions
from cbrs.kb.store import Store
from cbrs.kb.vocab import CBRS

SHAPE = "https://w3id.org/cbrs/shapes#"
HEAD = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
@prefix ex: <http://example.org/lab#> .
"""


def camera(name: str, qos: str = "cbrs:responseTime 0.1", sea: str = "", device: str = '"Cam"') -> str:
    """One description, ``ex:<name>``, with the QoS, SEA box and device name given."""
    box = f" cbrs:hasSEAModel [ {sea} ] ;" if sea else ""
    return f"""ex:{name} a cbrs:DynamicPerceptionComponent ; cbrs:deviceName {device} ; cbrs:serviceName "Locate" ;{box}
    cbrs:hasQoSModel [ {qos} ] ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:Marker ; cbrs:parameterName "marker" ] ;
                        cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] .
"""


def quads(turtle: str) -> list[ox.Quad]:
    return list(ox.parse(HEAD + turtle, format=ox.RdfFormat.TURTLE, base_iri="http://example.org/lab"))


@contextmanager
def full() -> Iterator[None]:
    """The check against the whole shapes file, every datatype choice left to pySHACL."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(shapes, "_datatype_choices", lambda: ())
        yield


def refusal(turtle: str) -> str | None:
    """What ``check_descriptions`` says of ``turtle`` on an empty store (None: accepted)."""
    try:
        check_descriptions(Store.open(":memory:"), quads(turtle))
    except DescriptionShapeError as error:
        return str(error)
    return None


def settled(turtle: str) -> set[str]:
    """The choices the check of ``turtle`` leaves out of pySHACL's shapes."""
    data = shapes._rdflib_graph(ox.Triple(q.subject, q.predicate, q.object) for q in quads(turtle))
    lighter = shapes._shapes_for(data)
    return {str(c.shape) for c in shapes._datatype_choices() if (c.shape, rdflib.SH["or"], None) not in lighter}


def file_datatypes(shape: str) -> set[str]:
    """The datatypes of ``shape``'s sh:or as the shapes file lists them, read with Oxigraph's SPARQL."""
    store = ox.Store()
    store.load(path=ontology_dir() / shapes.SHAPES_FILE, format=ox.RdfFormat.TURTLE)
    rows = store.query(
        "PREFIX sh: <http://www.w3.org/ns/shacl#> PREFIX rdf: <http://www.w3.org/1999/02/22-rdf-syntax-ns#> "
        "SELECT ?s ?d WHERE { ?s sh:or/rdf:rest*/rdf:first/sh:datatype ?d }",
        substitutions={ox.Variable("s"): ox.NamedNode(shape)},
    )
    return {row["d"].value for row in rows}  # type: ignore[index, union-attr]


NUMBERS = sorted(d.removeprefix(XSD) for d in file_datatypes(SHAPE + "Number"))


def test_the_choices_are_read_from_the_shapes_file() -> None:
    choices = {str(c.shape): c for c in shapes._datatype_choices()}
    assert set(choices) == {SHAPE + "Number", SHAPE + "Text"}
    assert choices[SHAPE + "Number"].datatypes == file_datatypes(SHAPE + "Number") and len(NUMBERS) == 16
    assert choices[SHAPE + "Text"].datatypes == file_datatypes(SHAPE + "Text")
    number = {str(p) for p in choices[SHAPE + "Number"].properties}
    assert {CBRS.responseTime, CBRS.availability, CBRS.minX, CBRS.maxY} <= number  # by sh:path and sh:alternativePath
    text = {str(p) for p in choices[SHAPE + "Text"].properties}
    assert {CBRS.deviceName, CBRS.parameterName} <= text  # deviceName by way of shape:Name


def _number(datatype: str) -> tuple[str, str]:
    """A SEA box whose cbrs:minX, and a QoS whose cbrs:cost (unless negative), is a ``datatype`` literal."""
    lexical = {"negativeInteger": "-1", "nonPositiveInteger": "0"}.get(datatype, "1")
    bound = f'"{lexical}"^^xsd:{datatype}'
    sea = f"cbrs:minX {bound} ; cbrs:maxX 2 ; cbrs:minY 0 ; cbrs:maxY 1"
    return (sea, "cbrs:responseTime 0.1" if lexical.startswith("-") else f"cbrs:cost {bound}")


def test_a_number_of_every_numeric_datatype_of_the_file_is_accepted_and_settled() -> None:
    turtle = "".join(camera(f"Cam_{d}", qos=_number(d)[1], sea=_number(d)[0]) for d in NUMBERS)
    assert settled(turtle) == {SHAPE + "Number", SHAPE + "Text"}
    assert refusal(turtle) is None


# (a QoS value that is no number, what the error shows of it)
NOT_NUMBERS = [
    pytest.param('"fast"', '"fast"', id="word"),
    pytest.param('"5"^^xsd:string', '"5"', id="typed-string"),
    pytest.param('"5"@en', '"5"@en', id="language-tagged"),
    pytest.param("true", '"true"^^xsd:boolean', id="boolean"),
    pytest.param('"2026-11-27"^^xsd:date', '"2026-11-27"^^xsd:date', id="date"),
    pytest.param('"5"^^ex:Seconds', '"5"^^lab:Seconds', id="unknown-datatype"),  # derived prefix
    pytest.param('"abc"^^xsd:double', '"abc"^^xsd:double (not a valid xsd:double)', id="ill-typed-double"),
    pytest.param('"300"^^xsd:byte', '"300"^^xsd:byte (not a valid xsd:byte)', id="byte-out-of-range"),
    pytest.param('"-1"^^xsd:nonNegativeInteger', "(not a valid xsd:nonNegativeInteger)", id="ill-typed-unsigned"),
    pytest.param("ex:Five", "got cbrs:responseTime lab:Five", id="iri"),  # derived prefix (kb.derived_prefixes)
    pytest.param('"INF"^^xsd:double', "inf", id="infinite"),
]


@pytest.mark.parametrize(("value", "shown"), NOT_NUMBERS)
def test_a_number_of_another_datatype_is_refused_as_before(value: str, shown: str) -> None:
    turtle = camera("Cam", qos=f"cbrs:responseTime {value}")
    message = refusal(turtle)
    assert message is not None
    assert 'cbrs:responseTime is one number of seconds, 0 or more (0.1, not "fast"); got cbrs:responseTime ' in message
    assert shown in message
    with full():
        assert refusal(turtle) == message


# A value the choices pass but another test of the shapes refuses: with the choices settled, every
# other problem is still found, with the same message.
SETTLED_BUT_BROKEN = [
    camera("Infinite", qos='cbrs:responseTime "INF"^^xsd:double'),
    camera("NotANumber", qos='cbrs:cost "NaN"^^xsd:float'),
    camera("Negative", qos='cbrs:updateRate "-3"^^xsd:int'),
    camera("Percent", qos='cbrs:availability "95"^^xsd:unsignedByte'),
    camera("Reversed", sea='cbrs:minX "9"^^xsd:long ; cbrs:maxX 2.5 ; cbrs:minY 0 ; cbrs:maxY 1e0'),
    camera("HalfABox", sea='cbrs:minX "-INF"^^xsd:double ; cbrs:maxX 1'),
    camera("TwoLines", device='"Cam\\nera"'),
    camera("Blank", device='"  "@de'),
    camera("TwoNames", device='"Cam", "Kamera"@de'),
]


def test_problems_other_than_a_datatype_are_the_same_with_the_choices_settled() -> None:
    turtle = "".join(SETTLED_BUT_BROKEN)
    assert settled(turtle) == {SHAPE + "Number", SHAPE + "Text"}
    closures = shapes._closures(quads(turtle))
    found = shapes._shape_problems(closures)  # what the message is made of (DescriptionShapeError)
    assert len({p.description for p in found}) == len(SETTLED_BUT_BROKEN)
    with full():
        assert shapes._shape_problems(closures) == found


def test_a_value_that_might_fail_leaves_its_choice_to_pyshacl() -> None:
    assert settled(camera("Word", qos='cbrs:responseTime "fast"')) == {SHAPE + "Text"}
    assert settled(camera("Iri", device="ex:Cam")) == {SHAPE + "Number"}
    assert settled(camera("Both", qos="cbrs:cost ex:Free", device="5")) == set()


def test_a_literal_the_shortcut_passes_passes_pyshacl_s_datatype_test() -> None:
    """Soundness, against pySHACL itself: every literal ``_has_datatype`` takes for a datatype of a
    choice passes ``sh:datatype`` of that datatype (a shape per datatype, the literals taken its targets)."""
    datatypes = sorted({d for c in shapes._datatype_choices() for d in c.datatypes})
    lexicals = ["5", "-1", "0", "300", "1.5", "1e5", "abc", " 7 ", "+5", "05", "INF", "NaN"]
    literals = [rdflib.Literal(x, datatype=rdflib.URIRef(d)) for x in lexicals for d in datatypes]
    literals += [rdflib.Literal("x"), rdflib.Literal("x", lang="de"), rdflib.Literal("1", datatype=rdflib.XSD.boolean)]
    literals += [rdflib.Literal("5", datatype=rdflib.URIRef("http://example.org/lab#Seconds"))]
    sh = rdflib.SH
    tests = rdflib.Graph()
    taken: dict[str, list[rdflib.Literal]] = {}
    for index, datatype in enumerate(datatypes):
        shape = rdflib.URIRef(f"http://example.org/test#shape{index}")
        tests.add((shape, sh.datatype, rdflib.URIRef(datatype)))
        taken[str(shape)] = [lit for lit in literals if shapes._has_datatype(lit, frozenset({datatype}))]
        for literal in taken[str(shape)]:
            tests.add((shape, sh.targetNode, literal))
    assert all(taken.values())  # something of every datatype is taken: the shortcut is not idle
    assert not shapes._has_datatype(rdflib.Literal("abc", datatype=rdflib.XSD.double), frozenset({XSD + "double"}))
    from pyshacl import validate

    conforms, results, _ = validate(rdflib.Graph(), shacl_graph=tests, inference="none")
    wrong = [(results.value(r, sh.sourceShape), results.value(r, sh.focusNode)) for r in results.subjects(sh.focusNode)]
    assert conforms and wrong == []
