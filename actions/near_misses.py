"""Near misses: the components that would have met an unmet need after a small change.

A need no component meets (an input of class C, a precondition statement) may be close to what some
component gives: the kitchen's tracker gives a home:PersonLocation where the drive to a person takes a
home:PersonPosition. A "no plan" answer names such components, what differs and the change that would do.

A concept D is *near* a needed concept C (docs/composition.md, "Near misses") when neither is an is-a
relative of the other (a relative is a provider already), they are not declared disjoint, their
complementary words do not say they are about different things (:func:`about_other_things`:
PersonLocation and PersonPosition are both about a person; RobotPosition is about a robot, a sibling of
the person; DeviceStatus and DoorStatus are about a device and a door, which no sibling or disjointness
keeps apart) and, by the store's taxonomy, they

* have the same parts (the same non-empty set of hasPart classes, own or inherited) and a superclass in
  common other than the root (the same idea under another name, in one branch: a home:Person and a
  home:PersonProfile both have a given and a family name, but meet only at the root), or
* are siblings (a direct superclass in common, not the root), or
* in a statement whose predicate is met, one is a kind of the other's sibling (a direct superclass of one
  is a sibling of the other): a lab's own lab10:TravelMug, a home:Mug, beside the home:Cup a fill at the
  tap gives (docs/tasks.md, "A tenth round"), a lab's classes being refinements one level below where
  the bundled siblings meet. Only in a statement, where the relation and the other side are the need's
  already: an input's class alone, so widened, would bring a home:Path near a home:PersonPosition.

An offered statement is near a needed one when its predicate is met (an is-a relative: another relation
is another action, not a small change), its subject and object are each met or near, and one is near.
A component comes close only if it would then have done: the forward search enabled it (all it needs
is there), or would have with each offered term it is near read as the needed one (the fill of a cup
needs the cup it fills, an input and a precondition of class home:Cup, and the task gives the mug), and
the area rule does not refuse it for the task's things it is given. Near misses are
ranked by Sem-Str similarity (the measure edges are ranked by), then by IRI, and capped
(``ComposeConfig.near_misses``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any

from cbrs.actions.graph import SRI, Matcher, Need, ServiceResourceGraph, statement_text
from cbrs.kb import Statement
from cbrs.kb.namespaces import shorten
from cbrs.reasoner.degrees import degree_of_match
from cbrs.reasoner.names import core_split, local_name
from cbrs.reasoner.statements import statement_similarity
from cbrs.reasoner.taxonomy import ROOT

SAME_PARTS = "the same parts"
SIBLINGS = "siblings"
SIBLINGS_KIND = "a kind of a sibling"
_POSITIONS = ("subject", "predicate", "object")


@dataclass(frozen=True)
class Difference:
    """One term in which a near miss differs from the need: the needed term, the offered one, and how near."""

    wanted: str
    offered: str
    relation: str  # SAME_PARTS, SIBLINGS or SIBLINGS_KIND
    position: str = ""  # for a statement: subject, predicate or object
    via: str = ""  # for SIBLINGS_KIND: the direct superclass of one that is the other's sibling
    kind: str = ""  # for SIBLINGS_KIND: which is the kind of that sibling, "wanted" or "offered"

    def to_dict(self) -> dict[str, str]:
        found = {"wanted": self.wanted, "offered": self.offered, "relation": self.relation}
        if self.position:
            found["position"] = self.position
        if self.via:
            found["via"] = self.via
            found["kind"] = self.kind
        return found

    def how(self) -> str:
        """How the two are near, for the answer's text."""
        if not self.via:
            return f"{self.relation}, neither a kind of the other"
        kind, sibling = (self.wanted, self.offered) if self.kind == "wanted" else (self.offered, self.wanted)
        return f"{shorten(kind)} is a {shorten(self.via)}, a sibling of {shorten(sibling)}; neither a kind of the other"


@dataclass(frozen=True)
class NearMiss:
    """A component whose output (or effect) is near the needed concept (or statement)."""

    component: str
    offer: str  # the output's name, or the effect's text
    gives: str  # the offered concept's IRI, or the offered statement's text
    wanted: str  # the needed concept's IRI, or the needed statement's text
    differs: tuple[Difference, ...]
    similarity: float
    consumer: str = ""  # who takes the need it is near, when not the unmet need's own consumer (one above it)

    @property
    def statement(self) -> bool:
        return bool(self.differs[0].position)

    def text(self, taker: str) -> str:
        """``taker``: who takes the need, as the answer names it ("svc:NavigateToPerson_P3DX01 takes")."""
        component = shorten(self.component)
        if self.statement:
            how = "; ".join(
                f"its {d.position} {shorten(d.offered)} for {shorten(d.wanted)} ({d.how()})" for d in self.differs
            )
            said = f"{component} comes close: its effect {self.gives} differs from the {self.wanted} {taker}: {how}"
            fix = f"register a component like it whose effect is {self.wanted}"
        else:
            said = (
                f"{component} comes close: it gives {shorten(self.gives)}, {taker} {shorten(self.wanted)}"
                f" ({self.differs[0].how()})"
            )
            fix = f"register a component like it that gives {shorten(self.wanted)}"
        # the same idea under another name, or a class below a sibling of what a component handles (a lab's
        # own travel mug, a home:Mug, by a fill of a home:Cup): the ontology may say the one is a kind of the other
        claims = [(d.offered, d.wanted) for d in self.differs if d.relation == SAME_PARTS] + [
            (d.wanted, d.offered) for d in self.differs if d.relation == SIBLINGS_KIND and d.kind == "wanted"
        ]
        if claims:
            every = " and ".join(f"every {shorten(kind)} is a {shorten(of)}" for kind, of in claims)
            declared = ", ".join(f"{shorten(kind)} rdfs:subClassOf {shorten(of)}" for kind, of in claims)
            fix += f", or, if {every} here, say so ({declared}, loaded into the ontology graph)"
        return f"{said}: {fix}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "component": self.component,
            "offer": self.offer,
            "gives": self.gives,
            "wanted": self.wanted,
            "differs": [d.to_dict() for d in self.differs],
            "similarity": round(self.similarity, 6),
            **({"consumer": self.consumer} if self.consumer else {}),
        }


def near(matcher: Matcher, wanted: str, offered: str, in_statement: bool = False) -> str | None:
    """How ``offered`` is near ``wanted`` (SAME_PARTS, SIBLINGS; SIBLINGS_KIND ``in_statement``), or None:
    not near, or met already."""
    found = nearness(matcher, wanted, offered, in_statement)
    return None if found is None else found.relation


def nearness(matcher: Matcher, wanted: str, offered: str, in_statement: bool = False) -> Difference | None:
    """How ``offered`` is near ``wanted`` (a Difference without its position), or None; a kind of a
    sibling only ``in_statement``, at a subject or object."""
    index = matcher.index
    if wanted not in index or offered not in index or degree_of_match(index, wanted, offered).accepted:
        return None
    first, second = index.canonical(wanted), index.canonical(offered)
    if index.disjoint(first, second) or about_other_things(matcher, first, second):
        return None
    parts = index.parts_of(first)
    if parts and parts == index.parts_of(second) and index.common_ancestor(first, second)[0] != ROOT:
        return Difference(wanted, offered, SAME_PARTS)
    if _superclasses(matcher, first) & _superclasses(matcher, second):
        return Difference(wanted, offered, SIBLINGS)
    if not in_statement:
        return None
    for one, other, kind in ((first, second, "wanted"), (second, first, "offered")):  # a kind of a sibling
        for parent in sorted(_superclasses(matcher, one)):
            if _superclasses(matcher, parent) & _superclasses(matcher, other):
                return Difference(wanted, offered, SIBLINGS_KIND, via=parent, kind=kind)
    return None


def about_other_things(matcher: Matcher, first: str, second: str) -> bool:
    """Whether the complementary words of two concepts say they are about different things.

    Differing words alone do not: home:DeviceStatus and home:DoorStatus differ in "device" and "door",
    yet nothing says a door is no device (a motorised one is both). Where each concept's complementary
    words name a class of its own vocabulary (home:RobotPosition's "Robot", home:Robot), those classes
    decide: they set the concepts apart when declared disjoint or siblings (a direct superclass in
    common, not the root: a home:Robot or a home:Person, both home:Agents), and never when one is a kind
    of the other or they meet only further up (home:Device is an artifact, home:Door a building element).
    Words that name no class are all there is to go by: differing, they set the concepts apart."""
    if matcher.measure.qualifier_factor(first, second) >= 1:
        return False  # the same complementary words, or a name without any
    one, other = _named_thing(matcher, first), _named_thing(matcher, second)
    if one is None or other is None:
        return True
    index = matcher.index
    if index.is_a(one, other) or index.is_a(other, one):
        return False
    return index.disjoint(one, other) or bool(_superclasses(matcher, one) & _superclasses(matcher, other))


def _named_thing(matcher: Matcher, concept: str) -> str | None:
    """The class a concept's complementary words name in its own vocabulary (home:RobotPosition:
    home:Robot), or None."""
    local = local_name(concept)
    core, rest = core_split(local)
    if not rest or not local.lower().endswith(core):
        return None
    words = local[: len(local) - len(core)].strip("_- ")
    named = concept[: len(concept) - len(local)] + words
    return named if words and named in matcher.index else None


def _superclasses(matcher: Matcher, concept: str) -> set[str]:
    return {p for p, kind in matcher.index.parents(concept).items() if kind == "is-a" and p != ROOT}


def near_misses(
    graph: ServiceResourceGraph,
    consumer: str,
    need: Need,
    enabled: Callable[[str], bool],
    refused: Callable[[str, Iterable[str]], bool],
    named: Iterable[str] = (),
    most: int = 3,
) -> tuple[NearMiss, ...]:
    """The components of ``graph`` whose output or effect is near ``need`` of ``consumer``, at most ``most``,
    best first.

    ``enabled``: whether the forward search enabled a component; ``refused``: whether the area rule refuses
    a component handling the given requirement inputs; ``named``: components the answer names already
    (passed over, planned but unrunnable); those that provide the need as it is are left out too."""
    if most <= 0:
        return ()
    skip = set(named) | {e.source for e in graph.providers(consumer, need)}
    found = [
        miss
        for miss in _candidates(graph, need)
        if miss.component not in skip
        and (enabled(miss.component) or _enabled_after(graph, enabled, miss))
        and not refused(miss.component, _given(graph, miss.component))
    ]
    found.sort(key=lambda m: (-m.similarity, m.component, m.offer))
    best: dict[str, NearMiss] = {}
    for miss in found:  # one near miss per component: its closest offer
        best.setdefault(miss.component, miss)
    return tuple(best.values())[:most]


def _candidates(graph: ServiceResourceGraph, need: Need) -> Iterator[NearMiss]:
    matcher = graph.matcher
    for vertex in graph.pool.vertices.values():
        for offer in vertex.offers:
            if need.concept is not None and offer.concept is not None:
                difference = nearness(matcher, need.concept, offer.concept)
                if difference is not None:
                    similarity = matcher.measure(need.concept, offer.concept).value
                    yield NearMiss(vertex.iri, offer.name, offer.concept, need.concept, (difference,), similarity)
            elif need.statement is not None and offer.statement is not None:
                differs = statement_differences(matcher, need.statement, offer.statement)
                if differs:
                    value = statement_similarity(need.statement, offer.statement, matcher.measure, matcher.config)
                    yield NearMiss(
                        vertex.iri,
                        offer.name,
                        statement_text(offer.statement),
                        statement_text(need.statement),
                        differs,
                        value.value,
                    )


def _enabled_after(graph: ServiceResourceGraph, enabled: Callable[[str], bool], miss: NearMiss) -> bool:
    """Whether the forward search would have enabled ``miss``'s component with each offered term it is near
    read as the needed one: every need of it no enabled vertex meets is met so read (the fill of a home:Cup
    needs a home:Cup given and below the tap; read as the task's mug, the task gives it and the carry puts
    it there)."""
    swap = {d.offered: d.wanted for d in miss.differs}
    ready = [v for v in graph.vertices.values() if v.iri != miss.component and enabled(v.iri)]
    for need in graph.needs(miss.component):
        if any(enabled(edge.source) for edge in graph.providers(miss.component, need)):
            continue
        read = _read_as(need, swap)
        if read == need or not any(graph.matcher.match(read, offer) for v in ready for offer in v.offers):
            return False
    return True


def _read_as(need: Need, swap: dict[str, str]) -> Need:
    """``need`` with each term ``swap`` names replaced."""
    if need.concept is not None:
        return replace(need, concept=swap.get(need.concept, need.concept))
    if need.statement is not None:
        s = need.statement
        return replace(
            need, statement=Statement(swap.get(s.subject, s.subject), s.predicate, swap.get(s.object, s.object))
        )
    return need


def statement_differences(matcher: Matcher, wanted: Statement, offered: Statement) -> tuple[Difference, ...]:
    """The positions in which ``offered`` is near ``wanted``; empty when one is neither met nor near, the
    predicate is not met, or every position is met (then it is no miss)."""
    differs = []
    pairs = zip(_POSITIONS, _terms(wanted), _terms(offered), strict=True)
    for position, want, offer in pairs:
        if degree_of_match(matcher.index, want, offer).accepted:
            continue
        found = nearness(matcher, want, offer, in_statement=True) if position != "predicate" else None
        if found is None:  # another relation is another action, not a small change
            return ()
        differs.append(replace(found, position=position))
    return tuple(differs)


def _terms(statement: Statement) -> tuple[str, str, str]:
    return statement.subject, statement.predicate, statement.object


def _given(graph: ServiceResourceGraph, component: str) -> list[str]:
    """The requirement inputs a component would be given directly (the things it would handle)."""
    return [
        edge.offer.name
        for need in graph.needs(component)
        if need.role == "input"
        for edge in graph.providers(component, need)
        if edge.source == SRI
    ]


__all__ = [
    "SAME_PARTS",
    "SIBLINGS",
    "SIBLINGS_KIND",
    "Difference",
    "NearMiss",
    "about_other_things",
    "near",
    "near_misses",
    "nearness",
    "statement_differences",
]
