"""Plain reasons for the SPARQL syntax errors whose parser message hides them.

Oxigraph's parser answers an update sent as a query with "expected CONSTRUCT", a query sent as an
update with "expected VERSION", and a prefix nobody declared with a list of the characters it could
have read ("expected one of Prefix not found, ['%'], ...") or, in a subject, "expected OPTIONAL". The
endpoint, the bridge's ``/cbrs/query``, ``cbrs query`` and :meth:`KnowledgeBase.query
<cbrs.kb.knowledge_base.KnowledgeBase.query>` (and ``update``) put the reason in front: what the text is
and where to send it, or which prefix is undeclared and the nearest cbrs declares. The text is only read
here, never run: the parser still decides what is valid. An error explained once keeps the parser's
words (:attr:`QuerySyntaxError.parsed <cbrs.kb.errors.QuerySyntaxError>`) and is not explained again.

``cbrs query``, ``cbrs update`` and the browser's SPARQL editor also declare, above the text, the store's
derived prefixes it uses (``lab4:``, which cbrs prints): :func:`store_prefixes_used`.
"""

from __future__ import annotations

import difflib
import re
from collections import Counter
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from typing import Literal

from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.sparql_lexemes import HIDING

__all__ = [
    "FORMS",
    "TOKENS",
    "declared",
    "explain_syntax_error",
    "first_keyword",
    "one_line_up",
    "operation_kind",
    "prologue",
    "store_prefixes_used",
    "undeclared_prefix",
    "unexplained",
]

TOKENS = re.compile(
    r'(?P<iri><[^<>"{}|^`\\\x00-\x20]*>)|'
    + HIDING
    + r"""|[?$]\w+|@[A-Za-z][\w-]*|(?P<pname>[\w.\-\u00b7\u00c0-\uffff]*:(?:[^\s{}()\[\]<>"',;#\\]|\\.)*)"""
    r"|(?P<word>[A-Za-z_]\w*)",
    re.DOTALL,
)
"""SPARQL's tokens that say what a text is: IRIs (``iri``), prefixed names (``pname``) and keywords
(``word``); strings, comments, variables and language tags are matched whole so that nothing inside
them counts."""
FORMS = frozenset({"SELECT", "CONSTRUCT", "DESCRIBE", "ASK"})
_UPDATE_WORDS = frozenset({"INSERT", "DELETE", "LOAD", "CLEAR", "CREATE", "DROP", "COPY", "MOVE", "ADD", "WITH"})
_PROLOGUE_WORDS = frozenset({"PREFIX", "BASE", "VERSION"})
_ERROR_AT = re.compile(r"error at (\d+:\d+)(?::\s*)?")
_POSITION = re.compile(r"\berror at (\d+):(\d+)")


def first_keyword(text: str) -> str | None:
    """The first word of ``text`` after its prologue, as written (None: there is none)."""
    for match in TOKENS.finditer(text):
        word = match.group("word")
        if word and word.upper() not in _PROLOGUE_WORDS:
            return word  # IRIs, prefixed names, strings and comments of the prologue are passed by
    return None


def operation_kind(text: str) -> Literal["query", "update"] | None:
    """Whether ``text`` reads as a query or an update, by its first keyword after the prologue (None:
    neither, or nothing to read). Only for explaining a syntax error: the parser decides what runs."""
    word = (first_keyword(text) or "").upper()
    if word in FORMS:
        return "query"
    return "update" if word in _UPDATE_WORDS else None


def undeclared_prefix(text: str, known: Collection[str] = ()) -> str | None:
    """The first prefix ``text`` uses that neither its own ``PREFIX`` lines nor cbrs's table (nor ``known``)
    declare."""
    found = [prefix for prefix in undeclared_prefixes(text) if prefix not in known]
    return found[0] if found else None


def undeclared_prefixes(text: str) -> list[str]:
    """Every prefix ``text`` uses that neither its own ``PREFIX`` lines nor cbrs's table declare, in the
    order they are first used."""
    declared: set[str] = set()
    used: list[str] = []
    previous = ""
    for match in TOKENS.finditer(text):
        name = match.group("pname")
        if name is not None:
            prefix = name.partition(":")[0]
            if previous == "PREFIX":
                declared.add(prefix)
            elif text[match.start() - 1 : match.start()] == "<":  # an IRI the lexer could not read whole
                pass  # (<http://x/has a space>): its scheme is no prefix
            elif prefix not in PREFIXES and prefix != "_" and prefix not in used:  # _: names a blank node
                used.append(prefix)
        previous = (match.group("word") or "").upper()
    return [prefix for prefix in used if prefix not in declared]


def store_prefixes_used(text: str, table: Callable[[], Mapping[str, str]]) -> dict[str, str]:
    """The prefixes of ``table`` (a store's derived prefixes, :mod:`cbrs.kb.derived_prefixes`) that ``text``
    uses and does not declare itself, in the order it uses them: what to declare above it, so that the names
    cbrs prints for the store (``lab4:Trolley1``) may be written in a query for it. ``table`` is read only
    when ``text`` uses a prefix nobody declares. A namespace that is no plain IRI is left out: the prologue
    is written from the store's IRIs, and nothing typed is put into it."""
    wanted = undeclared_prefixes(text)
    found = table() if wanted else {}
    return {
        prefix: found[prefix]
        for prefix in wanted
        if prefix in found and _PREFIX_NAME.fullmatch(prefix) and _PLAIN_IRI.fullmatch(found[prefix])
    }


def prologue(prefixes: Mapping[str, str]) -> str:
    """``PREFIX`` declarations of ``prefixes`` on one line, for :func:`store_prefixes_used`'s prefixes: the
    parser's line numbers are then off by one (:func:`one_line_up`); empty for none."""
    if not prefixes:
        return ""
    return " ".join(f"PREFIX {prefix}: <{namespace}>" for prefix, namespace in prefixes.items()) + "\n"


def declared(prefixes: Mapping[str, str], text: str) -> str:
    """The user's own ``text`` under a :func:`prologue` of ``prefixes`` (the store's derived ones it uses and
    does not declare, :func:`store_prefixes_used`: names and namespaces checked there, from the store's
    IRIs only). Nothing typed goes into the prologue; the text itself is the user's query or update, run
    as written."""
    return prologue(prefixes) + text


def one_line_up(error: QuerySyntaxError, text: str) -> QuerySyntaxError:
    """``error`` of ``text`` run under a one-line :func:`prologue`, its ``error at LINE:COLUMN`` counted
    in ``text`` as written."""
    if type(error) is not QuerySyntaxError:
        return error

    def up(match: re.Match[str]) -> str:
        return f"error at {max(int(match.group(1)) - 1, 1)}:{match.group(2)}"

    parsed = None if error.parsed is None else _POSITION.sub(up, error.parsed, count=1)
    return QuerySyntaxError(text, _POSITION.sub(up, error.message, count=1), parsed)


def unexplained(error: QuerySyntaxError) -> QuerySyntaxError:
    """``error`` in the parser's own words: for a caller that explains it with more than the knowledge base
    knew (``cbrs query`` ran the text under a prologue of its own: the places are counted without it)."""
    if type(error) is not QuerySyntaxError or error.parsed is None:
        return error
    return QuerySyntaxError(error.query, error.parsed)


_PREFIX_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")  # the derived prefixes' form (kb.derived_prefixes)
_PLAIN_IRI = re.compile(r'[^<>"{}|^`\\\x00-\x20]+')  # SPARQL's IRIREF, without its brackets


def explain_syntax_error(
    error: QuerySyntaxError,
    text: str,
    expected: Literal["query", "update"],
    known: Mapping[str, str] | None = None,
    offered: Callable[[], Mapping[str, str]] | None = None,
) -> QuerySyntaxError:
    """``error`` with a plain reason in front where the parser's list of expected tokens hides it: an
    update sent as a query (or the other way round), a misspelt first keyword, a prefix nobody declared,
    a bracket closed by the wrong kind, or a text that ends inside brackets. ``known`` are prefixes the
    text was run with besides cbrs's (a store's derived prefixes): not undeclared, and offered for a
    misspelt one with their namespace. ``offered`` gives the store's derived prefixes where the text was
    run without them (the endpoint), read only for a prefix nobody declared: such a prefix is given its
    declaration, a misspelt one the nearest with its own, so that ``cbrs query``, the endpoint and the
    browser's SPARQL editor say the same."""
    if type(error) is not QuerySyntaxError or error.parsed is not None:  # QueryTooComplexError says what it
        return error  # means; an error explained (by the knowledge base) keeps its explanation

    def explained(reason: str) -> QuerySyntaxError:
        return QuerySyntaxError(text, reason, parsed=error.message)

    at = _ERROR_AT.search(error.message)
    where = f"error at {at.group(1)}: " if at else ""
    said = " ".join(_ERROR_AT.sub("", error.message, count=1).split())  # the parser's words, without the place
    kind = operation_kind(text)
    if kind is not None and kind != expected:
        how = {
            "update": "POST it as update= or as application/sparql-update, with the update token",
            "query": "send it as query= or as application/sparql-query",
        }[kind]
        article = "an" if expected == "update" else "a"
        return explained(f"{where}this is a SPARQL {kind}, not {article} {expected}: {how}")
    word = first_keyword(text) if kind is None else None
    close = (
        difflib.get_close_matches(word.upper(), FORMS if expected == "query" else _UPDATE_WORDS, n=1) if word else []
    )
    if close:  # SELEKT, INSRT: the parser says "expected CONSTRUCT", the last form it tried
        return explained(f"{where}{word!r} begins no SPARQL {expected}: did you mean {close[0]}? (the parser: {said})")
    prefix = undeclared_prefix(text, known or {})
    if prefix is not None:
        return explained(where + _undeclared_reason(prefix, said, {**(offered() if offered else {}), **(known or {})}))
    nesting = _nesting(text)
    if nesting.wrong is not None and (at is None or _offset(text, at.group(1)) >= nesting.wrong.closed_at):
        wrong = nesting.wrong  # the parser's list would name what may follow, not which bracket is wrong
        return explained(
            f"{where}the {wrong.closer!r} at {_place(text, wrong.closed_at)} comes while the {wrong.opener!r} "
            f"opened at {_place(text, wrong.opened_at)} is open: close it with {_CLOSERS[wrong.opener]!r} first, "
            f"or remove the {wrong.closer!r}",
        )
    if nesting.wrong is None and nesting.open:  # the parser lists every token that could have come next
        return explained(f"{where or 'at the end: '}the text ends with {_still_open(nesting.open)}")
    return error


def _undeclared_reason(prefix: str, said: str, derived: Mapping[str, str]) -> str:
    """Why the text did not parse, for ``prefix`` that nothing declares: its declaration when it is one of
    the store's ``derived`` prefixes, else the nearest prefix (a derived one with its declaration)."""
    if prefix in derived:  # the store's, used where no one declares it for the text (the endpoint)
        return (
            f"the prefix '{prefix}:' is not declared: add PREFIX {prefix}: <{derived[prefix]}> (derived for this "
            "store; the endpoint declares cbrs's own prefixes only)"
        )
    # Oxigraph says "Prefix not found" among the tokens it expected, or (in a subject) nothing of it
    close = difflib.get_close_matches(prefix, [*PREFIXES, *derived], n=1)
    if close and close[0] in derived:  # the store's: the declaration is known
        hint = f"did you mean '{close[0]}:' (PREFIX {close[0]}: <{derived[close[0]]}>, derived for this store)?"
    elif close:
        hint = f"did you mean '{close[0]}:'?"
    elif "Prefix not found" in said:
        hint = "cbrs declares " + ", ".join(f"{p}:" for p in PREFIXES)
    else:
        hint = f"the parser: {said}"
    return f"the prefix '{prefix}:' is not declared: add PREFIX {prefix}: <IRI>; {hint}"


_CLOSERS = {"{": "}", "(": ")", "[": "]"}
_OPENERS = {closer: opener for opener, closer in _CLOSERS.items()}
_BRACKET = re.compile(HIDING + r"|\\.|[{}()\[\]]", re.DOTALL)
"""Strings, IRIs, comments and escaped characters (``ex:a\\(``), which hide the brackets inside them; then
the brackets that count."""


@dataclass(frozen=True)
class WrongBracket:
    """A closing bracket that closes a different kind than the innermost one open (offsets into the text)."""

    closer: str
    closed_at: int
    opener: str
    opened_at: int


@dataclass(frozen=True)
class Nesting:
    """How a text's brackets nest: the first wrongly closed one, and those still open at its end
    (outermost first, as ``(bracket, offset)``) — read up to the first wrong one."""

    wrong: WrongBracket | None
    open: tuple[tuple[str, int], ...]


def _nesting(text: str) -> Nesting:
    """How the ``{}``, ``()`` and ``[]`` of ``text`` (outside strings, IRIs and comments) nest. A closer
    with nothing open is left to the parser, whose message names it well."""
    stack: list[tuple[str, int]] = []
    for match in _BRACKET.finditer(text):
        token = match.group()
        if token in _CLOSERS:
            stack.append((token, match.start()))
        elif token in _OPENERS and stack:
            opener, opened_at = stack[-1]
            if _CLOSERS[opener] != token:
                return Nesting(WrongBracket(token, match.start(), opener, opened_at), tuple(stack))
            stack.pop()
    return Nesting(None, tuple(stack))


def _still_open(stack: tuple[tuple[str, int], ...]) -> str:
    """What is still open: for blocks alone (the common case) their count and where to close them;
    otherwise each kind counted and the closers to add, innermost first."""
    kinds = Counter(bracket for bracket, _ in stack)
    if set(kinds) == {"{"}:
        return f"{kinds['{']} '{{' not closed: add '}}' where each block ends"
    counted = " and ".join(f"{n} {bracket!r}" for bracket, n in kinds.items())
    closers = "".join(_CLOSERS[bracket] for bracket, _ in reversed(stack))
    add = f"add {closers!r} (innermost first)" if len(closers) <= 12 else "close each where it ends"
    return f"{counted} not closed: {add}"


def _place(text: str, offset: int) -> str:
    """``line:column`` of ``offset``, both from 1 as the parser counts them."""
    line = text.count("\n", 0, offset) + 1
    column = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return f"{line}:{column}"


def _offset(text: str, place: str) -> int:
    """The offset of the parser's ``line:column``, the inverse of :func:`_place`."""
    line, column = (int(part) for part in place.split(":"))
    start = 0
    for _ in range(line - 1):
        found = text.find("\n", start)
        if found < 0:
            return len(text)
        start = found + 1
    return start + column - 1
