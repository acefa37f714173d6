"""A task written as Turtle text, checked and planned before it is stored, then saved all or nothing.

What the browser's task editor (``/tasks/new``) stands on. A draft is read as ``cbrs load --graph
requirements FILE`` reads a file: the same parser (:func:`kb.loader.parse_bytes`), its blank nodes named
as a load names them, and the same check against the SHACL shapes and the declared terms
(:func:`kb.shapes.check_descriptions`), against the store as it is, with nothing written. Its requirement
is read from the text alone, each parameter given the part tree the store's ontology has for its class,
so that it is composed (:meth:`Composer.compose` takes a requirement) as it would be once stored.

Saving is one SPARQL update through the endpoint's own guard (:meth:`SparqlService.update`: the update
token, read-only servers, the lock, graph:entailed): ``INSERT DATA`` of the draft's quads, after a
``DELETE DATA`` of what the stored task's previous text added when it replaces one. The update is
checked again as every update of graph:requirements is, and undone whole if refused.

What a saved text added is recorded by the same update in graph:task-drafts (:data:`RECORDS`), one node
per task (:func:`record_iri`), as N-Triples literals: the text's triples (``stated``) and the triples the
editor's saves of that task put into graph:requirements (``added``: absent before). A replace removes the
task's own description and whatever else its previous text stated that an editor's save added, except
what the new text or another saved task's text states; a triple a load put there is not the editor's to
remove. The copies are literals, not triples, so that queries over the union of the graphs see each
triple once.

The text needs no ``@prefix`` lines for the prefixes the store uses: those the text does not declare are
declared on one line put before it, and the parser's line numbers are given back as the text's own.
"""

from __future__ import annotations

import dataclasses
import difflib
import hashlib
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import pyoxigraph as ox

from cbrs.kb.descriptions import DescriptionReader
from cbrs.kb.errors import KnowledgeBaseError, RdfParseError
from cbrs.kb.loader import parse_bytes
from cbrs.kb.model import Requirement
from cbrs.kb.namespaces import BASE as CBRS_BASE
from cbrs.kb.namespaces import CBRS as CBRS_NS
from cbrs.kb.namespaces import GENID, GRAPH, RDF, RDFS, REQ, GraphName, near_prefixes, shorten
from cbrs.kb.registry import ComponentRegistry
from cbrs.kb.resources import ontology_dir
from cbrs.kb.shapes import DescriptionShapeError, ShapeProblem, check_descriptions
from cbrs.kb.store import EmbeddedStore, Store, data_block
from cbrs.kb.vocab import CBRS

if TYPE_CHECKING:
    from cbrs.actions.base_choice import BaseChoice
    from cbrs.actions.composer import Composer, CompositionResult
    from cbrs.kb import KnowledgeBase
    from cbrs.sparql_service import SparqlService

__all__ = [
    "DraftError",
    "DraftShapeError",
    "TaskDraft",
    "TaskExistsError",
    "example",
    "line_of",
    "plan",
    "read",
    "record_iri",
    "save",
]

SOURCE = "the task"
"""How errors name the text (it has no file)."""
BASE = REQ
"""What a relative IRI of the text (``<#MyTask>``) is resolved against: the requirements' namespace."""
EXAMPLES_FILE = "requirements.ttl"
"""The bundled requirements, from which the editor's example is taken."""
RECORDS = ox.NamedNode(GRAPH + "task-drafts")
"""The graph of what each saved text added (one node per task, :func:`record_iri`)."""
_DRAFT = CBRS_BASE + "task-draft#"
_TASK, _STATED, _ADDED = (ox.NamedNode(_DRAFT + name) for name in ("task", "stated", "added"))


class DraftError(KnowledgeBaseError):
    """The text is not one task the editor can check: not Turtle, no requirement, or several. ``line`` is
    the text's own line when known."""

    http_status = 400
    kind = "invalid-task"

    def __init__(self, message: str, line: int | None = None, column: int | None = None) -> None:
        self.line = line
        self.column = column
        where = f"line {line}{f', column {column}' if column else ''}: " if line else ""
        super().__init__(where + message)


@dataclass(frozen=True)
class Problem:
    """One shape or term problem of a draft: what is wrong, the term (or value) at fault, its line."""

    message: str
    term: str | None
    line: int | None


class DraftShapeError(DraftError):
    """The task breaks a shape or names a misspelt term, as a load would refuse it (422: the text is
    Turtle, its content is not a task the store takes); nothing was written."""

    http_status = 422
    kind = "invalid-description"

    def __init__(self, error: DescriptionShapeError, problems: Sequence[Problem]) -> None:
        self.problems = list(problems)
        self.iri = error.iri
        first = self.problems[0] if self.problems else None
        super().__init__(str(error), first.line if first else None)


class TaskExistsError(DraftError):
    """A task of this name is stored already, and the save was not asked to replace it."""

    http_status = 409
    kind = "task-exists"

    def __init__(self, iri: str) -> None:
        self.iri = iri
        super().__init__(
            f"a task named {shorten(iri)} is stored already: ask to replace it, or give the task another name"
        )


@dataclass(frozen=True)
class TaskDraft:
    """A checked task: its text, its IRI, the quads a save writes and the requirement read from them."""

    text: str
    iri: str
    quads: tuple[ox.Quad, ...]
    requirement: Requirement
    exists: bool  # a task of this name is stored already (saving it replaces that one)


def read(kb: KnowledgeBase, text: str, prefixes: Mapping[str, str]) -> TaskDraft:
    """``text`` parsed and checked as a load into graph:requirements checks a file, against ``kb`` as it
    is, writing nothing; ``prefixes`` (name → namespace) are declared for it where it does not declare
    them. :class:`DraftError` (400) for text that is no one task, :class:`DraftShapeError` (422)."""
    if not text.strip():
        raise DraftError("the text is empty: write a task (a cbrs:Requirement) in Turtle")
    head = _declarations(text, prefixes)
    try:
        parsed = parse_bytes((head + text).encode("utf-8"), SOURCE, ox.RdfFormat.TURTLE, GraphName.REQUIREMENTS, BASE)
    except RdfParseError as error:
        line = error.line - 1 if error.line and head else error.line
        raise DraftError(error.message + _prefix_hint(error.message), line, error.column) from None
    iri = _the_requirement(parsed.quads, text)
    try:
        check_descriptions(kb.store, parsed.quads)
    except DescriptionShapeError as error:
        raise DraftShapeError(error, [_located(p, text) for p in error.shape_problems]) from None
    requirement = _requirement(kb, parsed.quads, iri)
    exists = any(kb.store.quads(ox.NamedNode(iri), ox.NamedNode(RDF + "type"), None, GraphName.REQUIREMENTS.node))
    return TaskDraft(text, iri, tuple(parsed.quads), requirement, exists)


def plan(composer: Composer, draft: TaskDraft) -> tuple[CompositionResult, BaseChoice | None]:
    """The draft composed as ``cbrs plan`` composes a stored task (not recorded): in a home of two or more
    mobile bases, the plan of the base a run would choose, and that choice (None otherwise:
    ``actions.base_choice.choose_in_map``). Call with the store's lock held, as for any composition."""
    from cbrs.actions.base_choice import choose_in_map  # the planner loads with the first plan

    return choose_in_map(composer, draft.requirement, composer.compose(draft.requirement))


def save(sparql: SparqlService, draft: TaskDraft, token: str | None, replace: bool = False) -> int:
    """Write ``draft`` into graph:requirements in one update with the update ``token``; a stored task of
    its name is replaced only with ``replace`` (else :class:`TaskExistsError`), and with it what its
    previously saved text added. Returns the number of triples the stored task had (0 for a new one)."""
    sparql.check_token(token)  # before anything is read: no answer about the store without the token
    store, graph = sparql.kb.store, GraphName.REQUIREMENTS.node
    with sparql.lock:
        stored = any(store.quads(ox.NamedNode(draft.iri), ox.NamedNode(RDF + "type"), None, graph))
        if stored and not replace:
            raise TaskExistsError(draft.iri)
        record = ox.NamedNode(record_iri(draft.iri))
        records = list(store.quads(None, None, None, RECORDS))
        mine = [q for q in records if q.subject == record]  # the previous save's record
        owned = set(ComponentRegistry(store, sparql.kb.standard_terms).owned_quads(draft.iri, graph) if stored else [])
        previous = {q for q in owned | _recorded(mine, _STATED) if _present(store, q)} if stored else set()
        text = _as_stored(draft.quads)
        said = _recorded((q for q in records if q.subject != record), _STATED) | set(text)
        by_editor = _recorded(records, _ADDED)  # a triple a load put there is not the editor's to remove
        removing = [q for q in previous if q not in said and (q in owned or q in by_editor)]
        inserting = [q for q in text if not _present(store, q)]
        carried = [q for q in _recorded(mine, _ADDED) if q not in removing and _present(store, q)]
        written = _record(record, draft.iri, text, [*inserting, *carried])
        # Terms serialised by data_block (escaped N-Triples), never the text itself.
        update = "INSERT DATA {\n" + data_block([*inserting, *written]) + "}"
        if removing or mine:
            update = "DELETE DATA {\n" + data_block([*removing, *mine]) + "} ;\n" + update
        sparql.update(update, token)
    return len(previous)


def record_iri(task: str) -> str:
    """The node of graph:task-drafts that records what the saved text of ``task`` added."""
    return _DRAFT + hashlib.sha256(task.encode("utf-8")).hexdigest()[:32]


def _as_stored(quads: Sequence[ox.Quad]) -> list[ox.Quad]:
    """``quads`` as the store keeps them: Oxigraph writes each literal in its canonical form (a text's
    ``10.0`` is stored as ``10``), and a record must name the triples it will find."""
    scratch = ox.Store()
    scratch.extend(quads)
    return list(scratch)


def _record(node: ox.NamedNode, task: str, text: Sequence[ox.Quad], added: Sequence[ox.Quad]) -> list[ox.Quad]:
    """The record of a save: the task, the text's triples and those the editor added, as N-Triples."""

    def literal(quads: Sequence[ox.Quad]) -> ox.Literal:
        triples = sorted((q.triple for q in quads), key=str)
        return ox.Literal((ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES) or b"").decode("utf-8"))

    return [
        ox.Quad(node, _TASK, ox.NamedNode(task), RECORDS),
        ox.Quad(node, _STATED, literal(text), RECORDS),
        ox.Quad(node, _ADDED, literal(added), RECORDS),
    ]


def _present(store: Store, quad: ox.Quad) -> bool:
    subject, graph = quad.subject, quad.graph_name
    if not isinstance(subject, ox.NamedNode | ox.BlankNode) or not isinstance(graph, ox.NamedNode):
        return False
    return quad in set(store.quads(subject, quad.predicate, None, graph))


def _recorded(quads: Iterable[ox.Quad], kind: ox.NamedNode) -> set[ox.Quad]:
    """The graph:requirements quads the ``kind`` literals among ``quads`` record."""
    graph = GraphName.REQUIREMENTS.node
    found = set()
    for quad in quads:
        if quad.predicate == kind and isinstance(quad.object, ox.Literal):
            for triple in ox.parse(quad.object.value.encode("utf-8"), format=ox.RdfFormat.N_TRIPLES):
                found.add(ox.Quad(triple.subject, triple.predicate, triple.object, graph))
    return found


def example(name: str, as_name: str | None = None) -> str:
    """The Turtle of the bundled requirement ``name`` (a local name under ``req:``) as the bundled file
    writes it, without its ``@prefix`` lines (the editor declares the store's prefixes), named ``as_name``
    when given (a new task to edit, not the stored one); the file's first requirement when it has none
    of that name."""
    text = (ontology_dir() / EXAMPLES_FILE).read_text(encoding="utf-8")
    blocks = re.findall(r"^(req:(\w+) a cbrs:Requirement ;.*?\.)\s*$", text, re.MULTILINE | re.DOTALL)
    if not blocks:
        raise KnowledgeBaseError(f"{EXAMPLES_FILE} holds no requirement written as req:Name a cbrs:Requirement")
    chosen = next((block for block, local in blocks if local == name), blocks[0][0])
    if as_name is not None:
        chosen = re.sub(r"^req:\w+", f"req:{as_name}", chosen)
    return str(chosen) + "\n"


# -- pieces ----------------------------------------------------------------------------------------

_DECLARED = re.compile(r"(?:@prefix|PREFIX)\s+([\w.-]*):", re.IGNORECASE)


def _declarations(text: str, prefixes: Mapping[str, str]) -> str:
    """One line declaring each of ``prefixes`` the text does not declare itself (its own win)."""
    own = set(_DECLARED.findall(text))
    declared = [f"@prefix {p}: <{ns}> ." for p, ns in prefixes.items() if p not in own and re.fullmatch(r"[\w.-]*", p)]
    return " ".join(declared) + "\n" if declared else ""


_UNDECLARED = re.compile(r"The prefix ([\w.-]*): has not been declared")
"""Oxigraph's Turtle parser's words for a prefix used and not declared."""


def _prefix_hint(message: str) -> str:
    """For a prefix neither the text nor the store declares: the store's prefixes nearest it (hme: for home:)."""
    found = _UNDECLARED.search(message)
    if found is None:
        return ""
    near = near_prefixes(found.group(1))
    meant = f"did you mean {' or '.join(p + ':' for p in near)}? " if near else ""
    return f"; {meant}(declare a prefix of your own with @prefix {found.group(1)}: <IRI> .)"


def _the_requirement(quads: Sequence[ox.Quad], text: str) -> str:
    """The IRI of the one requirement the text describes; a page saves one task at a time."""
    kinds = (ox.NamedNode(RDF + "type"), ox.NamedNode(CBRS.Requirement))
    found = sorted(
        {q.subject.value for q in quads if (q.predicate, q.object) == kinds and isinstance(q.subject, ox.NamedNode)}
    )
    named = [iri for iri in found if not iri.startswith(GENID)]
    if not found:
        raise _no_requirement(quads, text)
    if len(named) != len(found):
        raise DraftError("the task has no name: give the cbrs:Requirement an IRI (req:MyTask), not a blank node")
    if len(found) > 1:
        raise DraftError(
            f"the text describes {len(found)} tasks ({', '.join(shorten(i) for i in found)}): save one at a time"
        )
    return found[0]


_DECLARED = re.compile(r"^\s*(?:@prefix\s+|PREFIX\s+)([A-Za-z][\w.-]*)?:\s*<([^>\s]*)>", re.IGNORECASE | re.MULTILINE)


def declared_prefixes(text: str) -> dict[str, str]:
    """The prefixes ``text`` declares itself (``@prefix lab14: <...#> .``, name → namespace): how its writer
    names its own terms, which the pages may not know yet."""
    return {name: ns for name, ns in _DECLARED.findall(text) if name}


def _no_requirement(quads: Sequence[ox.Quad], text: str) -> DraftError:
    """The text names no cbrs:Requirement: when it types a thing with a class spelt like it
    (``cbrs:Requirment``, ``req:Requirement``), that class, its line and the class meant."""
    usage = "a task is a cbrs:Requirement (req:MyTask a cbrs:Requirement ; ...)"
    kinds = {
        q.object.value
        for q in quads
        if q.predicate.value == RDF + "type"
        and isinstance(q.subject, ox.NamedNode)
        and isinstance(q.object, ox.NamedNode)
    }
    for kind in sorted(kinds):
        local = re.split(r"[#/:]", kind)[-1].casefold()
        if difflib.SequenceMatcher(None, local, "requirement").ratio() >= 0.75:
            shown = shorten(kind)
            return DraftError(
                f"the text describes no task: its {shown} is no class of cbrs; did you mean cbrs:Requirement? "
                f"({usage})",
                line_of(text, shown if shown != kind else f"<{kind}>"),
            )
    return DraftError(f"the text describes no task: {usage}")


def _requirement(kb: KnowledgeBase, quads: Sequence[ox.Quad], iri: str) -> Requirement:
    """The requirement as the store would read it: from the draft's quads alone, each parameter with the
    part tree of its class in ``kb``'s ontology."""
    scratch = EmbeddedStore(ox.Store(), ":memory:")
    # the reader's queries find descriptions by their class (rdfs:subClassOf* cbrs:ServiceDescription)
    core = ox.NamedNode(RDFS + "subClassOf")
    classes = [q for q in kb.store.quads(None, core, None) if str(q.subject).startswith(f"<{CBRS_NS}")]
    scratch.add([*quads, *classes])
    found = cast(Requirement, DescriptionReader(scratch, kb.queries).read(iri))
    inputs = tuple(dataclasses.replace(p, tree=kb.part_tree(p.type)) for p in found.inputs)
    outputs = tuple(dataclasses.replace(p, tree=kb.part_tree(p.type)) for p in found.outputs)
    return dataclasses.replace(found, inputs=inputs, outputs=outputs)


_NAMED = re.compile(r"(?<![\w<])([A-Za-z][\w.-]*:[\w.-]*\w)|<([^>\s]+)>")


def _located(problem: ShapeProblem, text: str) -> Problem:
    """``problem`` with the term it is about (its value, else the first name its message gives) and the
    first line of ``text`` that writes that term; else the line that names the task."""
    terms = [problem.value] if problem.value is not None else []
    terms += [a or b for a, b in _NAMED.findall(problem.message)]
    for term in terms:
        line = line_of(text, term)
        if line is not None:
            return Problem(problem.text(), term, line)
    return Problem(problem.text(), terms[0] if terms else None, line_of(text, shorten(problem.description)))


def line_of(text: str, term: str) -> int | None:
    """The first line of ``text`` that writes ``term`` (a prefixed name, ``<IRI>`` or a literal) as a whole,
    outside comments: a file's header often names the very term at fault ("home:Refridgerator for
    home:Refrigerator"), and the page pointed at it."""
    pattern = re.compile(rf"(?<![\w:-]){re.escape(term)}(?![\w-])")
    for number, line in enumerate(_uncommented(text), start=1):
        if pattern.search(line):
            return number
    return None


def _uncommented(text: str) -> list[str]:
    """``text``'s lines with each Turtle comment cut off: a ``#`` outside an ``<IRI>`` and a string (short
    or long, which may span lines) begins one, to the line's end."""
    lines: list[str] = []
    quote = ""  # the string we are in: '"', "'", '"""' or "'''"
    for line in text.splitlines():
        kept, i = [], 0
        while i < len(line):
            char = line[i]
            if quote:
                if char == "\\":
                    kept.append(line[i : i + 2])
                    i += 2
                    continue
                if line.startswith(quote, i):
                    kept.append(quote)
                    i += len(quote)
                    quote = ""
                    continue
            elif char in "\"'":
                quote = char * 3 if line.startswith(char * 3, i) else char
                kept.append(quote)
                i += len(quote)
                continue
            elif char == "<":
                end = line.find(">", i)
                if end > i and not any(c.isspace() for c in line[i:end]):
                    kept.append(line[i : end + 1])
                    i = end + 1
                    continue
            elif char == "#":
                break
            kept.append(char)
            i += 1
        if len(quote) == 1:  # a short string ends with its line (broken Turtle: the parser says so)
            quote = ""
        lines.append("".join(kept))
    return lines
