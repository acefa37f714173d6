"""``cbrs check``: the store's ontologies and descriptions through an OWL 2 DL reasoner (HermiT, from owlready2).

HermiT runs on Java. The graphs are written to a temporary N-Triples file without their ``owl:imports``
(the imported ontologies are in the store already, and nothing may be fetched), which HermiT classifies.
The report says whether the graphs are consistent, which classes are unsatisfiable, and, since the reasoner
gives no reason for an inconsistency, the literals whose datatype is not one their property's range admits
(``"seven"`` on ``home:x``, whose range is ``xsd:decimal or xsd:double or xsd:float``): places to look first.

HermiT runs as a child process with a time limit (``timeout``, else the ``check_timeout`` setting): past it
the child is killed and :class:`ReasonerTimeoutError` says so (docs/ontologies.md, "How long HermiT may take").

The graphs are cbrs's own by name (``ontology``) or any named graph by its IRI, a lab's own that ``cbrs load
--graph IRI`` wrote included: checked with cbrs's ontologies when given with ``ontology`` too, alone otherwise
(its classes then mean what the graph alone says of them). An IRI the store holds no graph of is refused
(:class:`NoSuchGraphError`), naming the store's other graphs, rather than checked as empty and "consistent".

With :func:`write_inferred` (``cbrs check --write-inferred``) what HermiT concluded and the store does not
already say (inferred subclasses and equivalences of named classes and properties, types of named
individuals) is written to graph:inferred (:mod:`kb.inferred`), replacing what it held; over
inconsistent graphs, or with an unsatisfiable class, nothing is (:class:`WriteRefusedError`).

HermiT runs once and briefly, so its JVM gets the client compiler only and the serial collector
(:data:`JVM_OPTIONS`, passed in the child's ``JDK_JAVA_OPTIONS``; HermiT's jar is owlready2's):
a fresh store's check took about 7 s with the JVM's defaults and 3.5 s so, with the same answer. A user's
own ``JDK_JAVA_OPTIONS`` comes after them, so it wins where they disagree.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cbrs.kb import KnowledgeBase, KnowledgeBaseError
from cbrs.kb.inferred import INFERRED, InferredGraph, replace_inferred
from cbrs.kb.loader import resolve_graph
from cbrs.kb.namespaces import GENID, OWL, RDF, RDFS, GraphName, shorten
from cbrs.kb.skolem import is_skolem
from cbrs.settings import setting

DEFAULT_GRAPHS = (GraphName.ONTOLOGY, GraphName.SERVICES, GraphName.REQUIREMENTS)
JVM_OPTIONS = ("-XX:TieredStopAtLevel=1", "-XX:+UseSerialGC")
"""The JVM options HermiT runs with: a short run is dominated by compiling and collecting, not by the
reasoning these options would slow down."""
JAVA_HINT = "install a Java runtime (Debian/Ubuntu: apt-get install default-jre-headless) or put java on PATH"
SETTING = "check_timeout"
"""The setting that bounds a HermiT run, in seconds."""


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


class ReasonerTimeoutError(ReasonerError):
    """HermiT did not finish within its time limit; its process was killed, and nothing was concluded."""

    http_status = 504

    def __init__(self, seconds: float, graphs: Sequence[str], triples: int) -> None:
        self.seconds = seconds
        self.graphs = tuple(graphs)
        self.triples = triples
        self.message = f"no answer within {seconds:g} s"
        names = ", ".join(shorten(graph) for graph in self.graphs)
        KnowledgeBaseError.__init__(
            self,
            f"HermiT did not finish over {names} ({triples} triples) within {seconds:g} s, and was stopped: give it "
            f"longer with the {SETTING} setting ({setting(SETTING).env}=SECONDS), or check fewer graphs (--graph)",
        )


class HermitMissingError(ReasonerError):
    """owlready2 no longer ships HermiT where cbrs looks for it (:func:`hermit_classpath`)."""

    http_status = 503

    def __init__(self, version: str, why: str) -> None:
        self.version = version
        KnowledgeBaseError.__init__(
            self,
            f"cbrs check found no HermiT in owlready2 {version}: {why}; install the owlready2 version "
            "pyproject.toml names (owlready2>=0.47,<1), with which cbrs was tested",
        )


class WriteRefusedError(KnowledgeBaseError):
    """HermiT's conclusions not written back: over inconsistent graphs every statement follows, and an
    unsatisfiable class is below every class, so what it concluded would say nothing true."""

    http_status = 409

    def __init__(self, result: CheckResult) -> None:
        self.result = result
        if not result.consistent:
            why = "they are inconsistent"
        else:
            count = len(result.unsatisfiable)
            named = ", ".join(shorten(iri) for iri in result.unsatisfiable[:5]) + (", ..." if count > 5 else "")
            why = f"{count} class{'es are' if count > 1 else ' is'} unsatisfiable ({named})"
        graphs = ", ".join(shorten(graph) for graph in result.graphs)
        super().__init__(
            f"HermiT's conclusions over {graphs} were not written to {shorten(INFERRED.value)}: {why}; "
            "nothing was written (cbrs check without --write-inferred says more)"
        )


@dataclass(frozen=True)
class RangeClash:
    subject: str
    property: str
    value: str
    datatype: str
    range: str
    admitted: tuple[str, ...] = ()
    """The datatypes a union range names (``range`` is then its node); empty for a named datatype."""

    def text(self) -> str:
        named = " or ".join(shorten(member) for member in self.admitted) if self.admitted else shorten(self.range)
        return (
            f"{shorten(self.subject)} {shorten(self.property)} {self.value} is an {shorten(self.datatype)}, "
            f"but {shorten(self.property)} has range {named}"
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
    conclusions: list[ox.Triple] = field(default_factory=list)
    """HermiT's direct subclasses, subproperties, equivalences and types (:func:`_conclusions`), stated or not."""

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


def check(
    kb: KnowledgeBase, graphs: Sequence[GraphName | str] = DEFAULT_GRAPHS, timeout: float | None = None
) -> CheckResult:
    """Classify ``graphs`` of the store with HermiT: cbrs's graphs by name, any other named graph by its IRI
    (:class:`NoSuchGraphError` for one the store does not hold); :class:`JavaMissingError` without Java.
    HermiT has ``timeout`` seconds (default: the ``check_timeout`` setting), else :class:`ReasonerTimeoutError`."""
    import owlready2

    limit = setting(SETTING).resolve() if timeout is None else timeout
    if not limit > 0:  # NaN too, which cbrs check --timeout nan passed on
        raise ValueError(f"HermiT's time limit is a positive number of seconds (inf: none), not {limit!r}")
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
        try:
            output = _hermit(java, path, limit)
        except _TimedOut:
            raise ReasonerTimeoutError(limit, [graph.value for graph in nodes], len(triples)) from None
    clashes = range_clashes(kb, names)
    if output is None:
        return CheckResult(names, len(triples), False, [], clashes, time.perf_counter() - start)
    conclusions, unsatisfiable = _conclusions(output)
    seconds = time.perf_counter() - start
    return CheckResult(names, len(triples), True, unsatisfiable, clashes, seconds, conclusions=conclusions)


def write_inferred(
    kb: KnowledgeBase, graphs: Sequence[GraphName | str] = DEFAULT_GRAPHS, timeout: float | None = None
) -> tuple[CheckResult, InferredGraph]:
    """Check ``graphs`` (:func:`check`), then make graph:inferred hold HermiT's conclusions that the store
    does not already say (:func:`kb.inferred.replace_inferred`): all or nothing, replacing what an earlier
    write-back put there. :class:`WriteRefusedError`, nothing written, when the graphs are inconsistent or
    have an unsatisfiable class; :class:`ReasonerTimeoutError`, nothing written, when HermiT ran out of time."""
    result = check(kb, graphs, timeout)
    if not result.ok:
        raise WriteRefusedError(result)
    return result, replace_inferred(kb, result.conclusions)


class _TimedOut(Exception):
    """HermiT's process outlived its time limit and was killed."""


def hermit_classpath() -> str:
    """The Java classpath of the HermiT that owlready2 ships: its patched classes, then its jar.

    owlready2 has no public name for it: this reads its private ``owlready2.reasoning._HERMIT_CLASSPATH``,
    the classpath its own ``sync_reasoner_hermit`` runs, here alone. Should a release rename it or move
    the jar, :class:`HermitMissingError` says so (tests/test_owl_numbers.py fails first)."""
    import owlready2
    import owlready2.reasoning

    version = str(getattr(owlready2, "VERSION", "?"))
    classpath = getattr(owlready2.reasoning, "_HERMIT_CLASSPATH", None)
    if not isinstance(classpath, str):
        raise HermitMissingError(version, "owlready2.reasoning has no _HERMIT_CLASSPATH")
    jars = [entry for entry in classpath.split(os.pathsep) if entry.endswith(".jar")]
    if not jars or not all(Path(jar).is_file() for jar in jars):
        raise HermitMissingError(version, f"its HermiT classpath names no jar that exists ({classpath})")
    return classpath


def _hermit(java: str, path: Path, timeout: float) -> str | None:
    """HermiT's classification of the ontology at ``path`` (its command line, as owlready2 runs it: classes,
    object and data properties, individuals), or None when it finds the ontology inconsistent; :class:`_TimedOut`
    when it has not finished within ``timeout`` seconds, its process then killed by its PID and reaped.

    HermiT is run here rather than through ``owlready2.sync_reasoner_hermit``, whose results keep one kind
    per entity: a class also used as an individual (OWL 2 punning, as home:Cup is) had its inferred
    superclasses taken for its types; and which has no time limit. The JVM options go in the child's
    environment only."""
    import owlready2.reasoning

    memory = getattr(owlready2.reasoning, "JAVA_MEMORY", 2000)
    command = [java, f"-Xmx{memory}M", "-cp", hermit_classpath(), "org.semanticweb.HermiT.cli.CommandLine"]
    command += ["-c", "-O", "-D", "-I", path.as_uri()]
    own = os.environ.get("JDK_JAVA_OPTIONS")
    environment = {**os.environ, "JDK_JAVA_OPTIONS": " ".join([*JVM_OPTIONS, *([own] if own else [])])}
    try:
        process = subprocess.Popen(
            command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=environment
        )
    except OSError as error:
        raise ReasonerError(str(error)) from error
    try:
        # inf (--timeout inf): no limit; the subprocess module cannot wait an infinite time
        out, err = process.communicate(timeout=timeout if math.isfinite(timeout) else None)
    except subprocess.TimeoutExpired:
        process.kill()  # this child, by its PID: the JVM starts no process of its own
        process.communicate()
        raise _TimedOut from None
    except BaseException:  # an interrupt while waiting: the JVM goes with it
        process.kill()
        process.communicate()
        raise
    output = out.decode("utf-8", "replace")
    errors = err.decode("utf-8", "replace")
    if process.returncode == 1 and "Inconsistent ontology" in output + errors:
        return None
    if process.returncode != 0:
        raise ReasonerError(errors or output)
    return output


_RELATION = re.compile(r"^([A-Za-z]+)\( ((?:<[^>]+>\s*)+)\)$", re.MULTILINE)
_PREDICATES = {
    "SubClassOf": RDFS + "subClassOf",
    "SubObjectPropertyOf": RDFS + "subPropertyOf",
    "SubDataPropertyOf": RDFS + "subPropertyOf",
    "Type": RDF + "type",
    "EquivalentClasses": OWL + "equivalentClass",
    "EquivalentObjectProperties": OWL + "equivalentProperty",
    "EquivalentDataProperties": OWL + "equivalentProperty",
}


def _conclusions(output: str) -> tuple[list[ox.Triple], list[str]]:
    """HermiT's conclusions as triples, and the unsatisfiable classes (those equivalent to owl:Nothing).

    HermiT prints the direct relations of its taxonomy: each class's direct superclasses, each
    individual's direct types, each set of equivalent classes or properties. Left out: those naming an
    OWL built-in (owl:Thing above every class, owl:Nothing below) or a node the loader made from a blank
    node (a class expression, no named class)."""
    conclusions: list[ox.Triple] = []
    unsatisfiable: set[str] = set()
    for relation, listed in _RELATION.findall(output):
        terms = listed.strip()[1:-1].split("> <")
        predicate = _PREDICATES.get(relation)
        if predicate is None:
            continue
        if relation == "EquivalentClasses" and OWL + "Nothing" in terms:
            unsatisfiable.update(term for term in terms if not term.startswith(OWL))
            continue
        if any(term.startswith((OWL, GENID)) for term in terms):
            continue
        pairs = [(a, b) for a in terms for b in terms if a < b] if relation.startswith("Equivalent") else [terms]
        node = ox.NamedNode(predicate)
        conclusions += [ox.Triple(ox.NamedNode(a), node, ox.NamedNode(b)) for a, b in pairs]
    return conclusions, sorted(unsatisfiable)


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


def range_clashes(kb: KnowledgeBase, graphs: Sequence[str]) -> list[RangeClash]:
    """Literals whose datatype is not one their property's rdfs:range admits (the named query
    ``range_clashes``: an XSD datatype, or a union of them, and the XSD types derived from those)."""
    rows = [row for graph in graphs for row in kb.select("range_clashes", {"graph": graph})]
    clashes = []
    members: dict[str, tuple[str, ...]] = {}
    for row in rows:
        literal, range_ = row["o"], row["range"]
        assert isinstance(literal, ox.Literal) and isinstance(range_, ox.NamedNode)
        if is_skolem(range_) and range_.value not in members:
            members[range_.value] = _union_members(kb, range_)
        clashes.append(
            RangeClash(
                row["s"].value,
                row["p"].value,
                literal.value,
                literal.datatype.value,
                range_.value,
                members.get(range_.value, ()),
            )
        )
    return clashes


def _union_members(kb: KnowledgeBase, node: ox.NamedNode) -> tuple[str, ...]:
    """The datatypes of the union ``node`` is (its owl:unionOf list), in order; empty if it is none."""
    found: list[str] = []
    union = next(iter(kb.store.quads(node, ox.NamedNode(OWL + "unionOf"), None)), None)
    cell = union.object if union is not None else None
    while isinstance(cell, ox.NamedNode) and cell.value != RDF + "nil" and len(found) < 100:
        first = next(iter(kb.store.quads(cell, ox.NamedNode(RDF + "first"), None)), None)
        rest = next(iter(kb.store.quads(cell, ox.NamedNode(RDF + "rest"), None)), None)
        if first is None or rest is None or not isinstance(first.object, ox.NamedNode):
            break
        found.append(first.object.value)
        cell = rest.object
    return tuple(found)
