"""The belief state: what the robot believes about the world now, as RDF in the world graph.

KnowRob keeps beliefs in the knowledge base so that a query answers "where is the pen now". Here the
world graph is rewritten from an ``Observation`` after every executed step, in one transaction: the
things (typed individuals), the relations that hold between them (the verified effects among them)
and their positions. Queries ``world_facts`` and ``world_positions`` read it back.

One other writer: an actuator's answer that came after its call was given up (:mod:`actions.late_answers`)
sets what holds of some (thing, relation) pairs with :func:`correct`. A run still going then keeps that
in its later writes, whose observation knows nothing of it, for as long as its own belief of those pairs
stays what the world graph held before the correction, or until its observation says it has taken the
correction into its own belief (``Observation.heard``, by :class:`Heard`; docs/reliability.md, "Late
answers").
"""

from __future__ import annotations

import threading
import weakref
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import pyoxigraph as ox

from cbrs.kb import GraphName, KnowledgeBase
from cbrs.kb.namespaces import BASE, PREFIXES
from cbrs.kb.vocab import CBRS

WORLD = BASE + "world#"
STATE = WORLD + "State"
_TYPE = ox.NamedNode(PREFIXES["rdf"] + "type")
_DOUBLE = ox.NamedNode(PREFIXES["xsd"] + "double")

Fact = tuple[str, str, str]
"""A relation believed to hold: (thing, relation, other thing or quality), as IRIs."""
Pair = tuple[str, str]
"""A thing and one of its relations: what a correction decides the values of."""


@dataclass(frozen=True)
class Correction:
    """What :func:`correct` set of ``pairs``: ``before``, the facts of them the world graph held; ``held``,
    those that hold now (none: unknown, neither believed nor denied)."""

    pairs: frozenset[Pair]
    before: frozenset[Fact]
    held: frozenset[Fact]

    def of(self, facts: Iterable[Fact]) -> frozenset[Fact]:
        """The facts among ``facts`` about the corrected pairs."""
        return frozenset(f for f in facts if (f[0], f[1]) in self.pairs)

    def applied(self, facts: frozenset[Fact]) -> frozenset[Fact]:
        return (facts - self.of(facts)) | self.held


@dataclass(frozen=True)
class Observation:
    """Things with their classes, the relations that hold, positions, and when (simulated seconds);
    ``heard``, the corrections the observer has taken into its own belief (:class:`Heard`), which a belief
    state then stops keeping for it."""

    types: Mapping[str, str] = field(default_factory=dict)
    facts: frozenset[tuple[str, str, str]] = frozenset()
    positions: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)
    time: float = 0.0
    heard: tuple[Correction, ...] = ()


class BeliefState:
    def __init__(self, kb: KnowledgeBase) -> None:
        self.kb = kb
        self._written: frozenset[ox.Quad] | None = None  # what this object last wrote, while it may trust it
        self._corrections: list[Correction] = []  # made while this object lived, and still kept (:func:`correct`)
        self._made: list[Correction] = []  # every correction made while this object lived, for :meth:`restore`
        with _guard:
            _live.add(self)

    def write(self, observation: Observation, whole: bool = False) -> None:
        """Make the world graph ``observation``, atomically, in at most one request to a remote store (the
        graph is not read first: a run writes it after every step).

        The first write, one after a failed write or :meth:`restore`, and one asked ``whole`` replace the
        graph (:meth:`Store.replace_graph`), whatever another client put in it. Any other sends only the
        difference from the last write, as ``DELETE DATA`` and ``INSERT DATA``, which a cbrs server follows
        in graph:entailed statement by statement instead of working it out again from the whole store (a
        statement another client wrote meanwhile stays until the next whole write; docs/remote-store.md).
        A correction made while this object lived is kept (:meth:`_corrected`)."""
        graph = GraphName.WORLD.node
        with _guard:
            facts = self._corrected(frozenset(observation.facts), observation.heard)
            new = [
                ox.Quad(ox.NamedNode(t), _TYPE, ox.NamedNode(c), graph) for t, c in sorted(observation.types.items())
            ]
            new += _quads(facts)
            for thing, xyz in sorted(observation.positions.items()):
                for axis, value in zip((CBRS.positionX, CBRS.positionY, CBRS.positionZ), xyz, strict=True):
                    new.append(ox.Quad(ox.NamedNode(thing), ox.NamedNode(axis), _double(value), graph))
            new.append(ox.Quad(ox.NamedNode(STATE), ox.NamedNode(CBRS.believedAt), _double(observation.time), graph))
            written, self._written = self._written, None  # forgotten until this write is known to have gone through
            if written is None or whole:
                self.kb.store.replace_graph(graph, new)
            else:
                self.kb.store.replace(sorted(written.difference(new), key=str), [q for q in new if q not in written])
            self._written = frozenset(new)

    def _corrected(self, facts: frozenset[Fact], heard: Iterable[Correction] = ()) -> frozenset[Fact]:
        """``facts`` (an observation's) with the corrections this object keeps applied. One is kept while
        the observation holds of its pairs what the world graph held before it: the run has not changed
        them since, so the correction is the newer word. Once the observation differs there (a step of
        the run set them, or the run read the correction back), the run's own belief is: it is dropped.
        So is one the observer has ``heard``: its own belief took it in, and a step of the run that sets
        the pairs back to what they were before it is then the newer word, not the correction."""
        taken = set(heard)
        kept = []
        for correction in self._corrections:
            if correction not in taken and correction.of(facts) == correction.before:
                facts = correction.applied(facts)
                kept.append(correction)
        self._corrections = kept
        return facts

    def snapshot(self) -> list[ox.Quad]:
        """The world graph as it is, for :meth:`restore`."""
        return list(self.kb.store.quads(graph=GraphName.WORLD.node))

    def restore(self, quads: list[ox.Quad]) -> None:
        """Put the world graph back as a :meth:`snapshot` found it (a run refused before it acted), with
        the corrections made since this object was made (those a write since has dropped too: the snapshot
        may be older than them)."""
        graph = GraphName.WORLD.node
        with _guard:
            self._written = None
            found = {
                (q.subject.value, q.predicate.value, q.object.value): q
                for q in quads
                if isinstance(q.subject, ox.NamedNode) and isinstance(q.object, ox.NamedNode) and q.predicate != _TYPE
            }
            facts = frozenset(found)
            for correction in self._made:
                if correction.of(facts) == correction.before:
                    facts = correction.applied(facts)
            replaced = set(found.values())
            kept = [q for q in quads if q not in replaced]
            self.kb.store.replace_graph(graph, kept + _quads(facts))

    def facts(self, thing: str | None = None) -> set[tuple[str, str, str]]:
        rows = self.kb.select("world_facts", {"thing": thing} if thing else None)
        return {(r["thing"].value, r["relation"].value, r["other"].value) for r in rows}

    def positions(self) -> dict[str, tuple[float, float, float]]:
        rows = self.kb.select("world_positions")
        return {r["thing"].value: (float(r["x"].value), float(r["y"].value), float(r["z"].value)) for r in rows}


class Heard:
    """The corrections of a store's belief (:func:`correct`) made from now on, for an environment that keeps a
    belief of its own (``sim.components.SimEnvironment.effects``, the relations only steps set) to take in,
    in its own thread, before it next uses that belief (:meth:`take`). Without it a run's step that set a
    corrected relation back to what it was before the correction looked like no change to the run's belief
    state, and the correction stood. Heard for as long as the owner keeps it (held weakly here)."""

    def __init__(self, kb: KnowledgeBase) -> None:
        self._store = kb.store
        self._pending: deque[Correction] = deque()  # appended by the correcting thread, taken by the owner's
        self.taken: tuple[Correction, ...] = ()
        """Every correction :meth:`take` has dealt with, for the owner's observations (``Observation.heard``)."""
        with _guard:
            _hearing.add(self)

    def take(self, facts: set[Fact], about: Callable[[Pair], bool] = lambda pair: True) -> set[Fact]:
        """``facts`` (the owner's belief) with the corrections heard since the last call applied, in order:
        each whose pairs are all ``about`` the owner's belief and where ``facts`` hold of its pairs what the
        world graph held before it (the owner has not changed them since, so the correction is the newer
        word). Where they differ the owner's own act is the newer and the correction is passed over. Either
        way it is taken, so a belief state stops keeping it once an observation says so. ``facts`` itself
        when none was heard."""
        if not self._pending:
            return facts
        held = frozenset(facts)
        while self._pending:
            correction = self._pending.popleft()
            if all(about(pair) for pair in correction.pairs) and correction.of(held) == correction.before:
                held = correction.applied(held)
            self.taken += (correction,)
        return set(held)


def believed(kb: KnowledgeBase, pairs: Iterable[Pair]) -> frozenset[Fact]:
    """What the world graph holds of ``pairs`` now (one named query per thing)."""
    wanted = frozenset(pairs)
    found: set[Fact] = set()
    for thing in sorted({thing for thing, _ in wanted}):
        for row in kb.select("world_facts", {"thing": ox.NamedNode(thing)}):
            fact = (row["thing"].value, row["relation"].value, row["other"].value)
            if (fact[0], fact[1]) in wanted:
                found.add(fact)
    return frozenset(found)


def correct(
    kb: KnowledgeBase, pairs: Iterable[Pair], decide: Callable[[frozenset[Fact]], frozenset[Fact]]
) -> Correction:
    """Make what the world graph holds of ``pairs`` ``decide(what it holds of them now)``, in one transaction,
    and have every :class:`BeliefState` of the store living now keep it (:meth:`BeliefState._corrected`) and
    every :class:`Heard` of the store hear it.
    The reading, the decision and the write are one step for this process's belief writers. ``decide``
    may only return facts of ``pairs`` (``ValueError`` naming the others: nothing is written)."""
    wanted = frozenset(pairs)
    with _guard:
        before = believed(kb, wanted)
        held = frozenset(decide(before))
        stray = sorted(f for f in held if (f[0], f[1]) not in wanted)
        if stray:
            raise ValueError(f"a correction of {sorted(wanted)} may not set {stray}: nothing was written")
        correction = Correction(wanted, before, held)
        if held == before:
            return correction
        kb.store.replace(_quads(before - held), _quads(held - before))
        for state in list(_live):
            if state.kb.store is kb.store:
                state._corrections.append(correction)
                state._made.append(correction)
        for heard in list(_hearing):
            if heard._store is kb.store:
                heard._pending.append(correction)
    return correction


def _quads(facts: Iterable[Fact]) -> list[ox.Quad]:
    graph = GraphName.WORLD.node
    return [ox.Quad(ox.NamedNode(s), ox.NamedNode(p), ox.NamedNode(o), graph) for s, p, o in sorted(facts)]


def _double(value: float) -> ox.Literal:
    return ox.Literal(repr(round(float(value), 4)), datatype=_DOUBLE)


_guard = threading.RLock()
"""Held by every write of the world graph from this process: a correction's reading, decision and write
are not interleaved with a run's write."""
_live: weakref.WeakSet[BeliefState] = weakref.WeakSet()
"""The belief states of this process that may write again (a run's lives as long as the run)."""
_hearing: weakref.WeakSet[Heard] = weakref.WeakSet()
"""The environments' ears of this process (:class:`Heard`; a simulation environment's lives as long as it)."""
