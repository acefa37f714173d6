"""The belief state: what the robot believes about the world now, as RDF in the world graph.

KnowRob keeps beliefs in the knowledge base so that a query answers "where is the pen now". Here the
world graph is rewritten from an ``Observation`` after every executed step, in one transaction: the
things (typed individuals), the relations that hold between them (the verified effects among them)
and their positions. Queries ``world_facts`` and ``world_positions`` read it back.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import pyoxigraph as ox

from cbrs.kb import GraphName, KnowledgeBase
from cbrs.kb.namespaces import BASE, PREFIXES
from cbrs.kb.vocab import CBRS

WORLD = BASE + "world#"
STATE = WORLD + "State"
_TYPE = ox.NamedNode(PREFIXES["rdf"] + "type")
_DOUBLE = ox.NamedNode(PREFIXES["xsd"] + "double")


@dataclass(frozen=True)
class Observation:
    """Things with their classes, the relations that hold, positions, and when (simulated seconds)."""

    types: Mapping[str, str] = field(default_factory=dict)
    facts: frozenset[tuple[str, str, str]] = frozenset()
    positions: Mapping[str, tuple[float, float, float]] = field(default_factory=dict)
    time: float = 0.0


class BeliefState:
    def __init__(self, kb: KnowledgeBase) -> None:
        self.kb = kb
        self._written: frozenset[ox.Quad] | None = None  # what this object last wrote, while it may trust it

    def write(self, observation: Observation, whole: bool = False) -> None:
        """Make the world graph ``observation``, atomically, in at most one request to a remote store (the
        graph is not read first: a run writes it after every step).

        The first write, one after a failed write or :meth:`restore`, and one asked ``whole`` replace the
        graph (:meth:`Store.replace_graph`), whatever another client put in it. Any other sends only the
        difference from the last write, as ``DELETE DATA`` and ``INSERT DATA``, which a cbrs server follows
        in graph:entailed statement by statement instead of working it out again from the whole store (a
        statement another client wrote meanwhile stays until the next whole write; docs/remote-store.md)."""
        graph = GraphName.WORLD.node
        new = [ox.Quad(ox.NamedNode(t), _TYPE, ox.NamedNode(c), graph) for t, c in sorted(observation.types.items())]
        new += [
            ox.Quad(ox.NamedNode(s), ox.NamedNode(p), ox.NamedNode(o), graph) for s, p, o in sorted(observation.facts)
        ]
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

    def snapshot(self) -> list[ox.Quad]:
        """The world graph as it is, for :meth:`restore`."""
        return list(self.kb.store.quads(graph=GraphName.WORLD.node))

    def restore(self, quads: list[ox.Quad]) -> None:
        """Put the world graph back as a :meth:`snapshot` found it (a run refused before it acted)."""
        self._written = None
        self.kb.store.replace_graph(GraphName.WORLD.node, quads)

    def facts(self, thing: str | None = None) -> set[tuple[str, str, str]]:
        rows = self.kb.select("world_facts", {"thing": thing} if thing else None)
        return {(r["thing"].value, r["relation"].value, r["other"].value) for r in rows}

    def positions(self) -> dict[str, tuple[float, float, float]]:
        rows = self.kb.select("world_positions")
        return {r["thing"].value: (float(r["x"].value), float(r["y"].value), float(r["z"].value)) for r in rows}


def _double(value: float) -> ox.Literal:
    return ox.Literal(repr(round(float(value), 4)), datatype=_DOUBLE)
