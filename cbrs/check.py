"""``cbrs check``: the store's ontologies and descriptions through an OWL 2 DL reasoner (HermiT, from owlready2).

HermiT runs on Java. The graphs are written to a temporary N-Triples file without their ``owl:imports``
(the imported ontologies are in the store already, and nothing may be fetched), loaded into a fresh
owlready2 world and classified. The report says whether the graphs are consistent, which classes are
unsatisfiable, and, since the reasoner gives no reason for an inconsistency, the literals whose datatype
is not the range their property declares (``4.5`` is an ``xsd:decimal``, not an ``xsd:double``): places
to look first.

The graphs are cbrs's own by name (``ontology``) or any named graph by its IRI, a lab's own that ``cbrs load
--graph IRI`` wrote included: checked with cbrs's ontologies when given with ``ontology`` too, alone otherwise
(its classes then mean what the graph alone says of them). An IRI the store holds no graph of is refused
(:class:`NoSuchGraphError`), naming the store's other graphs, rather than checked as empty and "consistent".

HermiT runs once and briefly, so its JVM gets the client compiler only and the serial collector
(:data:`JVM_OPTIONS`, passed in ``JDK_JAVA_OPTIONS``, which owlready2's launch leaves to the environment):
a fresh store's check took about 7 s with the JVM's defaults and 3.5 s so, with the same answer. A user's
own ``JDK_JAVA_OPTIONS`` comes after them, so it wins where they disagree.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cbrs.kb import KnowledgeBase, KnowledgeBaseError
from cbrs.kb.loader import resolve_graph
from cbrs.kb.namespaces import OWL, GraphName, shorten

DEFAULT_GRAPHS = (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS)
JVM_OPTIONS = ("-XX:TieredStopAtLevel=1", "-XX:+UseSerialGC")
"""The JVM options HermiT runs with: a short run is dominated by compiling and collecting, not by the
reasoning these options would slow down."""
JAVA_HINT = "install a Java runtime (Debian/Ubuntu: apt-get install default-jre-headless) or put java on PATH"


class JavaMissingError(KnowledgeBaseError):
    """No Java runtime to run HermiT with."""

    http_status = 503

    def __init__(self, java: str) -> None:
        self.java = java
        super().__init__(
            f"cbrs check runs the HermiT reasoner, which needs Java, but {java!r} was not found: {JAVA_HINT}"
        )


class NoSuchGraphError(KnowledgeBaseError):
    """A graph to check given by an IRI the store holds no graph of (a misspelt one would check as empty)."""

    http_status = 404

    def __init__(self, graph: str, others: Sequence[str]) -> None:
        self.graph = graph
        self.others = list(others)
        held = f"its graphs other than cbrs's own: {', '.join(self.others)}" if self.others else "it has none"
        super().__init__(
            f"the store holds no graph {graph}; check a graph of cbrs's by its name ("
            + ", ".join(g.value for g in GraphName)
            + f") or one of the store's own by its IRI ({held})"
        )


class ReasonerError(KnowledgeBaseError):
    """The reasoner could not load or classify the graphs (other than by finding them inconsistent)."""

    def __init__(self, message: str) -> None:
        self.message = message
        super().__init__(f"HermiT failed: {' '.join(message.split())[:400]}")


@dataclass(frozen=True)
class RangeClash:
    subject: str
    property: str
    value: str
    datatype: str
    range: str

    def text(self) -> str:
        return (
            f"{shorten(self.subject)} {shorten(self.property)} {self.value} is an {shorten(self.datatype)}, "
            f"but {shorten(self.property)} has range {shorten(self.range)}"
        )


@dataclass
class CheckResult:
    """What the reasoner found over ``graphs``."""

    graphs: tuple[str, ...]
    triples: int
    consistent: bool
    unsatisfiable: list[str] = field(default_factory=list)
    range_clashes: list[RangeClash] = field(default_factory=list)
    seconds: float = 0.0
    reasoner: str = "HermiT (owlready2)"

    @property
    def ok(self) -> bool:
        return self.consistent and not self.unsatisfiable

    def to_dict(self) -> dict[str, Any]:
        return {
            "reasoner": self.reasoner,
            "graphs": list(self.graphs),
            "triples": self.triples,
            "consistent": self.consistent,
            "unsatisfiable": self.unsatisfiable,
            "range_clashes": [vars(clash) for clash in self.range_clashes],
            "seconds": round(self.seconds, 2),
        }


def check(kb: KnowledgeBase, graphs: Sequence[GraphName | str] = DEFAULT_GRAPHS) -> CheckResult:
    """Classify ``graphs`` of the store with HermiT: cbrs's graphs by name, any other named graph by its IRI
    (:class:`NoSuchGraphError` for one the store does not hold); :class:`JavaMissingError` without Java."""
    import owlready2

    nodes = checked_graphs(kb, graphs)
    java = str(owlready2.JAVA_EXE)
    if shutil.which(java) is None:
        raise JavaMissingError(java)
    start = time.perf_counter()
    triples = [
        ox.Triple(q.subject, q.predicate, q.object)
        for graph in nodes
        for q in kb.store.quads(graph=graph)
        if q.predicate.value != OWL + "imports"
    ]
    names = tuple(graph.value for graph in nodes)
    with tempfile.TemporaryDirectory(prefix="cbrs-check-") as folder:
        path = Path(folder) / "graphs.nt"
        path.write_bytes(ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES) or b"")
        world = owlready2.World()
        try:
            ontology = world.get_ontology(path.as_uri()).load(format="ntriples")
            with ontology, _java_options(JVM_OPTIONS):
                owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
        except owlready2.OwlReadyInconsistentOntologyError:
            return CheckResult(names, len(triples), False, [], _range_clashes(kb, names), time.perf_counter() - start)
        except (owlready2.OwlReadyError, OSError) as error:
            raise ReasonerError(str(error)) from error
        unsatisfiable = sorted(
            c.iri for c in world.inconsistent_classes() if getattr(c, "iri", OWL + "Nothing") != OWL + "Nothing"
        )
        world.close()
    return CheckResult(names, len(triples), True, unsatisfiable, _range_clashes(kb, names), time.perf_counter() - start)


@contextmanager
def _java_options(options: Sequence[str]) -> Iterator[None]:
    """``JDK_JAVA_OPTIONS`` set to ``options`` then the user's own, for the java launched inside; as it was after."""
    own = os.environ.get("JDK_JAVA_OPTIONS")
    os.environ["JDK_JAVA_OPTIONS"] = " ".join([*options, *([own] if own else [])])
    try:
        yield
    finally:
        if own is None:
            del os.environ["JDK_JAVA_OPTIONS"]
        else:
            os.environ["JDK_JAVA_OPTIONS"] = own


def checked_graphs(kb: KnowledgeBase, graphs: Sequence[GraphName | str]) -> list[ox.NamedNode]:
    """The graphs to check, each once, in order: a name of cbrs's (``ontology``: its graph, even while it is
    empty) or a graph IRI the store holds; ``UnknownGraphError`` for a word that is neither a name nor an
    IRI, :class:`NoSuchGraphError` for an IRI of no graph of the store."""
    nodes = list(dict.fromkeys(resolve_graph(graph) for graph in graphs))
    own = {graph.iri for graph in GraphName}
    held = kb.store.graphs()
    for node in nodes:
        if node.value not in own and node.value not in held:
            raise NoSuchGraphError(node.value, [graph for graph in held if graph not in own])
    return nodes


def _range_clashes(kb: KnowledgeBase, graphs: Sequence[str]) -> list[RangeClash]:
    """Literals typed with another XSD datatype than the one their property's rdfs:range names."""
    rows = [row for graph in graphs for row in kb.select("range_clashes", {"graph": graph})]
    clashes = []
    for row in rows:
        literal = row["o"]
        assert isinstance(literal, ox.Literal)
        clashes.append(
            RangeClash(row["s"].value, row["p"].value, literal.value, literal.datatype.value, row["range"].value)
        )
    return clashes
