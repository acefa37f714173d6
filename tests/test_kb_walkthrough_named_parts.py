"""A description whose parts have IRIs of their own (``<camera#model>``, ``<camera#output1>``), as an
update must write them since it may not insert blank nodes: the shapes check those parts too, and the
registry reads, replaces and removes them with the description. Before, the check stopped at the first
named node, so a parameter type "x" got in through /update or a registration and every later
``kb.advertisements()`` failed on it; and a deregistration left the parts behind."""

from __future__ import annotations

import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase

pytestmark = pytest.mark.both_stores

A = "http://example.org/mini#A"
TURTLE = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:A a cbrs:StaticDataComponent ; cbrs:deviceName "Server" ; cbrs:serviceName "Map" ;
    cbrs:hasOWLSModel <http://example.org/mini#A-model> ;
    cbrs:hasQoSModel <http://example.org/mini#A-qos> .
<http://example.org/mini#A-model> cbrs:hasOutput <http://example.org/mini#A-output> .
<http://example.org/mini#A-output> cbrs:parameterType {type} .
<http://example.org/mini#A-qos> cbrs:responseTime {time} .
"""
UPDATE = """INSERT DATA {{ GRAPH graph:services {{
  <http://example.org/mini#A> a cbrs:StaticDataComponent ; cbrs:deviceName "Server" ; cbrs:serviceName "Map" ;
      cbrs:hasOWLSModel <http://example.org/mini#A-model> .
  <http://example.org/mini#A-model> cbrs:hasOutput <http://example.org/mini#A-output> .
  <http://example.org/mini#A-output> cbrs:parameterType {type} .
}} }}"""


def _turtle(type_: str = "<http://example.org/mini#Location>", time: str = "0.5") -> str:
    return TURTLE.format(type=type_, time=time)


@pytest.mark.parametrize(
    ("type_", "time", "message"),
    [
        ('"x"', "0.5", 'got cbrs:parameterType "x"'),
        ("<http://example.org/mini#Location>", '"fast"', 'got cbrs:responseTime "fast"'),
    ],
)
def test_a_registration_s_named_parts_are_checked(mini_kb: KnowledgeBase, type_: str, time: str, message: str) -> None:
    before = mini_kb.store.dump()
    with pytest.raises(InvalidDescriptionError, match=message):
        mini_kb.registry.register(_turtle(type_, time))
    assert mini_kb.store.dump() == before


def test_an_update_s_named_parts_are_checked_and_the_store_keeps_working(mini_kb: KnowledgeBase) -> None:
    before = mini_kb.store.dump()
    count = len(mini_kb.advertisements())
    with pytest.raises(InvalidDescriptionError, match='got cbrs:parameterType "x"'):
        mini_kb.update(UPDATE.format(type='"x"'))
    assert mini_kb.store.dump() == before
    assert len(mini_kb.advertisements()) == count


def test_deregistering_removes_the_named_parts(mini_kb: KnowledgeBase) -> None:
    before = mini_kb.store.dump()
    mini_kb.registry.register(_turtle())
    assert [p.type for p in mini_kb.description(A).outputs] == ["http://example.org/mini#Location"]
    assert mini_kb.registry.deregister(A) == 8
    assert mini_kb.store.dump() == before


def test_an_update_replaces_the_named_parts(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(_turtle())
    changed = _turtle("<http://example.org/mini#Position>", "0.25")
    mini_kb.registry.update(changed)
    description = mini_kb.description(A)
    assert [p.type for p in description.outputs] == ["http://example.org/mini#Position"]
    assert [q.value for q in description.qos] == [0.25]
    quads = mini_kb.registry.description_quads(A)
    assert len(quads) == 8
    assert not [q for q in quads if q.object.value in ("http://example.org/mini#Location", "0.5")]


def test_a_named_part_another_description_points_at_stays(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(_turtle())
    other = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:B a cbrs:StaticDataComponent ; cbrs:deviceName "Server" ; cbrs:serviceName "Map2" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel <http://example.org/mini#A-qos> .
"""
    mini_kb.registry.register(other)
    mini_kb.registry.deregister(A)
    assert [q.value for q in mini_kb.description("http://example.org/mini#B").qos] == [0.5]


def test_a_stored_literal_where_an_iri_is_needed_is_passed_over(mini_kb: KnowledgeBase) -> None:
    """Data written around cbrs (or before the shapes covered named parts): the listing goes on without
    it, and reading it names it, instead of a TypeError from every kb.advertisements()."""
    import pyoxigraph as ox

    from cbrs.kb.errors import NotAnIriError
    from cbrs.kb.namespaces import GraphName

    count = len(mini_kb.advertisements())
    turtle = _turtle('"x"').encode()
    graph = GraphName.SERVICES.node
    mini_kb.store.add(
        ox.Quad(t.subject, t.predicate, t.object, graph) for t in ox.parse(turtle, format=ox.RdfFormat.TURTLE)
    )
    assert len(mini_kb.advertisements()) == count
    with pytest.raises(NotAnIriError, match=r'<http://example.org/mini#A> .*"x" stands where an IRI is needed'):
        mini_kb.description(A)
