"""``cbrs check``: the store's ontologies and descriptions through an OWL 2 DL reasoner (HermiT, from owlready2).

HermiT runs on Java. The graphs are written to a temporary N-Triples file without their ``owl:imports``
(the imported ontologies are in the store already, and nothing may be fetched), loaded into a fresh
owlready2 world and classified. The report says whether the graphs are consistent, which classes are
unsatisfiable, and, since the reasoner gives no reason for an inconsistency, the literals whose datatype
is not the range their property declares (``4.5`` is an ``xsd:decimal``, not an ``xsd:double``): places
to look first.

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


def check(kb: KnowledgeBase, graphs: Sequence[GraphName] = DEFAULT_GRAPHS) -> CheckResult:
    """Classify ``graphs`` of the store with HermiT; :class:`JavaMissingError` without Java."""
    import owlready2

    java = str(owlready2.JAVA_EXE)
    if shutil.which(java) is None:
        raise JavaMissingError(java)
    start = time.perf_counter()
    triples = [
        ox.Triple(q.subject, q.predicate, q.object)
        for graph in graphs
        for q in kb.store.quads(graph=graph.node)
        if q.predicate.value != OWL + "imports"
    ]
    names = tuple(graph.iri for graph in graphs)
    with tempfile.TemporaryDirectory(prefix="cbrs-check-") as folder:
        path = Path(folder) / "graphs.nt"
        path.write_bytes(ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES) or b"")
        world = owlready2.World()
        try:
            ontology = world.get_ontology(path.as_uri()).load(format="ntriples")
            with ontology, _java_options(JVM_OPTIONS):
                owlready2.sync_reasoner_hermit(world, infer_property_values=False, debug=0)
        except owlready2.OwlReadyInconsistentOntologyError:
            return CheckResult(names, len(triples), False, [], _range_clashes(kb, graphs), time.perf_counter() - start)
        except (owlready2.OwlReadyError, OSError) as error:
            raise ReasonerError(str(error)) from error
        unsatisfiable = sorted(
            c.iri for c in world.inconsistent_classes() if getattr(c, "iri", OWL + "Nothing") != OWL + "Nothing"
        )
        world.close()
    return CheckResult(
        names, len(triples), True, unsatisfiable, _range_clashes(kb, graphs), time.perf_counter() - start
    )


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


def _range_clashes(kb: KnowledgeBase, graphs: Sequence[GraphName]) -> list[RangeClash]:
    """Literals typed with another XSD datatype than the one their property's rdfs:range names."""
    rows = [row for graph in graphs for row in kb.select("range_clashes", {"graph": graph.iri})]
    clashes = []
    for row in rows:
        literal = row["o"]
        assert isinstance(literal, ox.Literal)
        clashes.append(
            RangeClash(row["s"].value, row["p"].value, literal.value, literal.datatype.value, row["range"].value)
        )
    return clashes
