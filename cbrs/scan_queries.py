"""Which SPARQL queries are one index scan: cheap, and stoppable without a worker process.

The endpoint evaluates a query in a worker process because Oxigraph cannot be interrupted while it
computes (an aggregate, a join, a sort). A query that is one triple pattern with at least one bound
term and no modifier but ``LIMIT`` is different: Oxigraph answers it by walking one index range and
hands out each matching triple as a solution as it goes, so the serialiser's writer, which checks the
deadline and the byte budget on every chunk (:class:`cbrs.sparql_service._BudgetWriter`), stops it as
surely as killing a process would, and it needs no more memory than the result it writes. Such a
query, the point lookup of a robot (``SELECT ?p ?o WHERE { <thing> ?p ?o }``), is evaluated on the
request's own thread, which saves the round trip to a worker (a process hop and a JSON frame each way).

The test is on the text, strictly: a prologue of ``PREFIX`` / ``BASE``, ``SELECT`` of variables or ``*``
(or ``ASK``), optional ``FROM`` / ``FROM NAMED`` clauses, ``WHERE { s p o }`` with terms that are IRIs,
prefixed names, variables, ``a`` or (as object) literals, each variable once, then an optional
``LIMIT``; or the empty group (``ASK {}``, what health checks send), which reads nothing. Anything
else (a comment, a path, a filter, ``DISTINCT``, ``OFFSET``, a blank node, an escape in a prefixed
name) is not recognised and goes to a worker as before. ``OFFSET`` and a repeated
variable are left out on purpose: with them, Oxigraph walks triples that produce no output, which the
writer's deadline could not see.
"""

from __future__ import annotations

import re

_IRI = r'<[^<>"{}|^`\\\x00-\x20]*>'
# Names are read with \w (letters and digits of every script, and _); the rarer characters SPARQL
# allows in them (U+00B7, U+203F...) and %-escapes are not recognised, and such a query takes a worker.
_PN = r"[^\W\d_](?:[\w\-.]*[\w\-])?"
_LOCAL = r"[\w:](?:[\w\-.:]*[\w\-:])?"
_PNAME = rf"(?:{_PN})?:(?:{_LOCAL})?"
_VAR = r"[?$]\w+"
_STRING = r'"(?:[^"\\\n\r]|\\.)*"' + r"|'(?:[^'\\\n\r]|\\.)*'"
_LITERAL = (
    rf"(?:(?:{_STRING})(?:@[A-Za-z]+(?:-[A-Za-z0-9]+)*|\^\^(?:{_IRI}|{_PNAME}))?"
    r"|[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|(?i:true|false))"
)
_NODE = rf"(?:{_IRI}|{_PNAME}|{_VAR})"
_S = r"\s*"

# Keywords are matched case-insensitively, and only they (a case-insensitive pattern over wide
# character ranges takes a second to compile).
_SHAPE = re.compile(
    rf"{_S}(?:(?:(?i:BASE){_S}{_IRI}|(?i:PREFIX){_S}(?:{_PN})?:{_S}{_IRI}){_S})*"
    rf"(?P<form>(?i:SELECT){_S}(?P<projection>\*|(?:{_VAR}{_S})+)|(?i:ASK)){_S}"
    rf"(?P<dataset>(?:(?i:FROM){_S}(?:(?i:NAMED)\s+)?(?:{_IRI}|{_PNAME}){_S})*)"
    rf"(?:(?i:WHERE){_S})?\{{{_S}(?:(?P<s>{_NODE}){_S}(?P<p>{_NODE}|a(?=[\s<?$])){_S}(?P<o>{_NODE}|{_LITERAL}){_S}\.?{_S})?\}}"
    rf"{_S}(?:(?i:LIMIT){_S}(?P<limit>\d+){_S})?"
)


_IRI_OR_STRING = re.compile(rf"{_IRI}|{_STRING}")


def uses_prefixes(text: str) -> bool:
    """Whether ``text`` may use a prefixed name (a colon outside IRIs and strings): a query that uses
    none is evaluated without cbrs's prefix table, whose hand-over costs more than a lookup."""
    return ":" in _IRI_OR_STRING.sub("", text)


def is_single_scan(text: str) -> bool:
    """Whether ``text`` is a query Oxigraph answers with one index scan that yields a solution per
    triple it reads (see the module's docstring); it may still be malformed in ways the parser finds."""
    return single_scan(text) is not None


def single_scan(text: str) -> re.Match[str] | None:
    """The match of a single scan (:func:`is_single_scan`), ``None`` for any other text. Its groups are
    ``form`` (from ``SELECT`` or ``ASK`` to the projection's end), ``projection`` (``None`` for ``ASK``),
    ``dataset`` (the ``FROM`` clauses, maybe empty), ``s``, ``p``, ``o`` (``None`` for the empty group)
    and ``limit``; the prologue is what precedes ``form``. :mod:`cbrs.pattern_lookup` reads them."""
    match = _SHAPE.fullmatch(text)
    if match is None:
        return None
    if match.group("s") is None:
        return match  # an empty group (ASK {}, a liveness probe): one empty solution, no scan at all
    terms = [match.group("s"), match.group("p"), match.group("o")]
    variables = [term for term in terms if term[0] in "?$"]
    if len(variables) == 3:
        return None  # the whole store: not a lookup
    names = [v[1:] for v in variables]
    return match if len(set(names)) == len(names) else None
