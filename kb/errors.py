"""Typed errors of the knowledge base. Each keeps the offending input and maps to an HTTP status."""

from __future__ import annotations

import re
from collections.abc import Sequence

from cbrs.kb.namespaces import written


class KnowledgeBaseError(Exception):
    """Base of every error cbrs raises on purpose; ``str(error)`` is one line fit for a person."""

    http_status = 500


class StoreError(KnowledgeBaseError):
    """The store could not be opened or written. Its message shows no password a URL carries."""

    def __init__(self, location: str, reason: str) -> None:
        self.location = location
        self.reason = reason
        super().__init__(without_password(f"store {location}: {reason}"))


_USERINFO = re.compile(r"(\b[A-Za-z][A-Za-z0-9+.-]*://)([^/\s@:]*):(?!PASSWORD@)[^/\s@]*@")


def without_password(text: str) -> str:
    """``text`` with the password of every URL in it masked (``http://robot:***@host``): a remote store's
    URL may carry HTTP basic credentials, and messages end up in terminals and logs."""
    return _USERINFO.sub(r"\1\2:***@", text)


def _one_line(message: str, limit: int = 240) -> str:
    text = " ".join(message.split()) or "(no message)"
    return text if len(text) <= limit else text[:limit] + " ..."


class StoreEvaluationError(StoreError, RuntimeError):
    """The store refused a well-formed query or update (e.g. CREATE GRAPH of a graph that exists); nothing
    was written.

    It is a RuntimeError too, as pyoxigraph's own evaluation errors are, so code that catches those sees
    both backends fail alike. From a remote store, ``endpoint``, ``status`` and ``request`` say what was
    sent where.
    """

    http_status = 400

    def __init__(
        self,
        location: str,
        operation: str,
        message: str,
        endpoint: str | None = None,
        status: int | None = None,
        request: str | None = None,
    ) -> None:
        self.operation = operation
        self.message = message
        self.endpoint = endpoint
        self.status = status
        self.request = request
        where = f" (HTTP {status} from {endpoint})" if endpoint else ""
        super().__init__(location, f"{operation} failed: {_one_line(message)}{where}")


class RemoteStoreError(StoreError):
    """The SPARQL server behind a remote store refused a request for another reason than its syntax or
    evaluation (a wrong endpoint, a body too large, a proxy error). Keeps the endpoint URL, the HTTP
    status, the server's own message and the request text sent."""

    http_status = 502

    def __init__(self, location: str, endpoint: str, status: int, message: str, request: str | None = None) -> None:
        self.endpoint = endpoint
        self.status = status
        self.message = message
        self.request = request
        super().__init__(location, f"HTTP {status} from {endpoint}: {_one_line(message)}")


class RdfParseError(KnowledgeBaseError):
    """A file or text did not parse; nothing was loaded."""

    http_status = 400

    def __init__(self, source: str, message: str, line: int | None = None, column: int | None = None) -> None:
        self.source = source
        self.line = line
        self.column = column
        self.message = message
        where = source if line is None else f"{source}:{line}" + (f":{column}" if column else "")
        super().__init__(f"{where}: {_one_line(message)}")  # parsers quote the offending text, newlines and all


class DescribedElsewhereError(KnowledgeBaseError):
    """A load would describe (``cbrs:hasOWLSModel``) a service or requirement that the store describes in
    another graph: all graphs are read as one, and the two models would merge into one description with
    each input, precondition and effect twice. Nothing was loaded."""

    http_status = 409

    def __init__(self, source: str, subject: str, graph: str, elsewhere: str, requirement: bool) -> None:
        self.source = source
        self.subject = subject
        self.graph = graph
        self.elsewhere = elsewhere
        own = " (a task into graph:requirements, its classes in a file of their own)" if requirement else ""
        super().__init__(
            f"{source}: {written(subject)} is described in {written(elsewhere)} already: load the file into one "
            f"graph{own}, or cbrs deregister it first; all graphs are read as one, and loaded into "
            f"{written(graph)} too, its two descriptions would merge, each input, precondition and effect twice"
        )


class UnknownFormatError(KnowledgeBaseError):
    """The RDF serialisation of a file could not be told from its name or content."""

    http_status = 400

    def __init__(self, source: str, known: Sequence[str]) -> None:
        self.source = source
        super().__init__(
            f"{source}: cannot tell the RDF format; use one of the extensions {', '.join(known)} "
            "or pass the format explicitly"
        )


class UnknownGraphError(KnowledgeBaseError):
    http_status = 400

    def __init__(self, graph: str, known: Sequence[str]) -> None:
        self.graph = graph
        super().__init__(f"unknown graph {graph!r}; use one of {', '.join(known)} or a full graph IRI")


class ReplaceError(KnowledgeBaseError):
    """A load asked to replace a graph other than graph:map: the map is the one graph a lab replaces whole
    (its own home); services and requirements are deregistered one by one, a backup restored by graph."""

    http_status = 400

    def __init__(self, graph: str) -> None:
        self.graph = graph
        super().__init__(
            f"a load replaces only graph:map (a home of your own), not {graph!r}: load into graph:map with "
            "--graph map, deregister services or requirements, or restore a backup's graph (cbrs restore --graph)"
        )


class UnknownQueryError(KnowledgeBaseError):
    http_status = 404

    def __init__(self, name: str, known: Sequence[str]) -> None:
        self.name = name
        super().__init__(f"no named query {name!r}; known queries: {', '.join(known)}")


class BindingError(KnowledgeBaseError):
    """A value bound to a query variable is malformed or names a variable the query does not take."""

    http_status = 400

    def __init__(self, variable: str, value: object, reason: str) -> None:
        self.variable = variable
        self.value = value
        given = "" if value is None else f"={value!r}"  # None: a required parameter left out, not a value of None
        super().__init__(f"binding {variable}{given}: {reason}")


class QuerySyntaxError(KnowledgeBaseError):
    """``query`` does not parse; ``message`` says why. ``parsed`` is the parser's own words when ``message``
    is a plain reason put in their place (:func:`cbrs.kb.sparql_hints.explain_syntax_error`), None when
    ``message`` is the parser's: an explained error is not explained again."""

    http_status = 400

    def __init__(self, query: str, message: str, parsed: str | None = None) -> None:
        self.query = query
        self.message = message
        self.parsed = parsed
        one_line = " ".join(message.split())
        if len(one_line) > 240:
            one_line = one_line[:240] + " ..."
        super().__init__(f"SPARQL syntax error: {one_line}")


class QueryTooComplexError(QuerySyntaxError):
    """A query or update the store's SPARQL engine cannot run without risking the process (see
    :mod:`kb.query_guard`): it crashed an isolated checker, or could not be checked in time."""

    def __init__(self, query: str, message: str) -> None:
        super().__init__(query, message)
        self.args = (f"refused: {' '.join(message.split())}",)

    def __str__(self) -> str:
        return str(self.args[0])


class EngineFaultError(KnowledgeBaseError):
    """The store's SPARQL engine crashed on ``query`` (a query's or an update's text, as ``kind`` says) in
    a process of its own (a checker, a query worker, an update's child), which died instead of this one;
    ``reason`` is what the engine said as it died (:mod:`kb.engine_faults`). A fault of the engine, not of
    the text's syntax: HTTP 500."""

    http_status = 500

    def __init__(self, query: str, reason: str, kind: str = "query") -> None:
        self.query = query
        self.reason = reason
        self.kind = kind
        super().__init__(f"the {kind} crashed the store's SPARQL engine in an isolated process: {reason}")


class NotFoundError(KnowledgeBaseError):
    """No resource with this IRI is described in the store."""

    http_status = 404

    def __init__(self, iri: str, what: str = "resource") -> None:
        self.iri = iri
        self.what = what
        super().__init__(f"no {what} <{iri}> in the store")


class OutsideRegistryError(NotFoundError):
    """An advertisement that is in the store, but in another graph than the registry's (graph:services):
    ``cbrs load`` put it there with a file that also declares classes. It keeps the graph it is in."""

    def __init__(self, iri: str, graph: str) -> None:
        super().__init__(iri, "registered advertisement")
        self.graph = graph
        self.args = (
            f"<{iri}> is in the graph <{graph}>, not in graph:services, which the registry manages: "
            "cbrs load puts a file that declares classes into the ontology graph, descriptions and all; "
            "load the description with --graph services (or from a file of its own) to register, update "
            "or deregister it",
        )

    def __str__(self) -> str:
        return str(self.args[0])


class InvalidDescriptionError(KnowledgeBaseError):
    """A service description lacks what the six-tuple requires; ``problems`` lists each gap."""

    http_status = 400

    def __init__(self, iri: str, problems: Sequence[str]) -> None:
        self.iri = iri
        self.problems = list(problems)
        super().__init__(f"{_named(iri)} is not a valid service description: {'; '.join(self.problems)}")


class ForeignStatementError(InvalidDescriptionError):
    """A registration states something new about a term another graph describes (``home:Cup
    rdfs:subClassOf home:Door``): written to graph:services it would change that term for every reader
    of the union graph, and stay after the component went. ``statement`` is the triple as Turtle."""

    def __init__(self, source: str, subject: str, graph: str, statement: str) -> None:
        self.subject = subject
        self.graph = graph
        self.statement = statement
        super().__init__(
            source,
            [
                f"it states {statement}, about {written(subject)}, which {written(graph)} describes: a "
                "registration adds descriptions and terms of its own, not statements about the store's other "
                "terms (change those with cbrs load into their graph)"
            ],
        )


def _named(iri: str) -> str:
    """``<iri>`` for an absolute IRI; a file name or ``<registration>`` as it is (not ``<<registration>>``)."""
    return f"<{iri}>" if _ABSOLUTE_IRI.match(iri) and " " not in iri else iri


_ABSOLUTE_IRI = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:[^\\]")


class BlankNodeInsertError(KnowledgeBaseError):
    """An update that would insert a blank node: cbrs names every node it stores."""

    http_status = 400

    def __init__(self, update: str, node: str) -> None:
        self.update = update
        self.node = node
        super().__init__(
            f"the update inserts a blank node ({node}); cbrs names every node it stores so that it can be read "
            "and deleted by name: give it an IRI (a description's parts under its own IRI, <...#output1>)"
        )


class BlankNodeError(InvalidDescriptionError):
    """A description names a blank node where an IRI is needed (written by an update, not the loader,
    which names every node): it cannot be read, addressed or deleted by name."""

    def __init__(self, iri: str, node: str) -> None:
        super().__init__(iri, [f"{node} is a blank node where an IRI is needed; give it an IRI (cbrs load names them)"])
        self.node = node


class NotAnIriError(InvalidDescriptionError):
    """A stored description has a literal where an IRI is needed (a parameter type ``"x"``): the shapes
    refuse it on every way in, so it got in before they covered that node or around cbrs."""

    def __init__(self, iri: str, value: str) -> None:
        super().__init__(iri, [f"{value} stands where an IRI is needed"])
        self.value = value


class AlreadyRegisteredError(KnowledgeBaseError):
    http_status = 409

    def __init__(self, iri: str) -> None:
        self.iri = iri
        super().__init__(f"<{iri}> is already registered; update it instead")


class CatalogueError(KnowledgeBaseError):
    """An ontology catalogue (a folder, an OASIS XML catalogue or a TSV mapping) could not be read."""

    http_status = 400

    def __init__(self, source: str, reason: str) -> None:
        self.source = source
        self.reason = reason
        super().__init__(f"catalogue {source}: {reason}")


class PartCycleError(KnowledgeBaseError):
    """A load would make a concept a part of itself (A hasPart B, B hasPart A); nothing was loaded.

    Every part tree through such a concept is endless, so every description using it, and every
    ranking or plan that reads those descriptions, would fail; the load is refused instead."""

    http_status = 400

    def __init__(self, sources: Sequence[str], cycle: Sequence[str]) -> None:
        self.sources = list(sources)
        self.cycle = list(cycle)
        super().__init__(
            f"{', '.join(self.sources)}: hasPart cycle {' -> '.join(self.cycle)}; "
            "a concept cannot be a part of itself, so nothing was loaded"
        )


class UndeclaredSuperclassError(KnowledgeBaseError):
    """A load declares a class under a term of cbrs's own vocabularies (home:, cbrs:, act:) that they do
    not declare, nor the store, nor the load: ``lab8:Apple rdfs:subClassOf home:Fruit``. The class would
    hang from nothing the components know, so no step would take a thing of it, and the task's refusal
    could not say why; nothing was loaded. ``suggestion`` is a declared term of a near spelling, if any;
    ``line`` the line of ``source`` (a file) where the subclass is written, as other refused loads name it."""

    http_status = 400

    def __init__(
        self,
        source: str,
        subclass: str,
        superclass: str,
        suggestion: str | None,
        undone: str = "nothing was loaded",
        line: int | None = None,
    ) -> None:
        self.source = source
        self.subclass = subclass
        self.superclass = superclass
        self.suggestion = suggestion
        self.line = line
        from cbrs.kb.namespaces import shorten

        near = f"did you mean {shorten(suggestion)}? " if suggestion else ""
        where = f"{source}:{line}" if line else source
        super().__init__(
            f"{where}: {shorten(subclass)} rdfs:subClassOf {shorten(superclass)}: {shorten(superclass)} is declared "
            f"nowhere in the store or in this input, so {shorten(subclass)} would be below no class the components "
            f"know and no step would take a thing of it; {near}name a class the vocabulary declares (cbrs query "
            "'SELECT ?c WHERE { ?c rdfs:subClassOf+ home:PhysicalObject }' lists the things an arm can move), or a "
            f"class of your own namespace declared under one; {undone}"
        )
