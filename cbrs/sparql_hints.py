"""Plain reasons for the SPARQL syntax errors whose parser message hides them.

Oxigraph's parser answers an update sent as a query with "expected CONSTRUCT", a query sent as an
update with "expected VERSION", and a prefix nobody declared with a list of the characters it could
have read ("expected one of Prefix not found, ['%'], ...") or, in a subject, "expected OPTIONAL". The
endpoint, the bridge's ``/cbrs/query`` and ``cbrs query`` put the reason in front: what the text is and
where to send it, or which prefix is undeclared and the nearest cbrs declares. The text is only read
here, never run: the parser still decides what is valid.
"""

from __future__ import annotations

import difflib
import re
from typing import Literal

from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.sparql_lexemes import HIDING

__all__ = ["FORMS", "TOKENS", "explain_syntax_error", "first_keyword", "operation_kind", "undeclared_prefix"]

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


def undeclared_prefix(text: str) -> str | None:
    """The first prefix ``text`` uses that neither its own ``PREFIX`` lines nor cbrs's table declare."""
    found = undeclared_prefixes(text)
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


def explain_syntax_error(error: QuerySyntaxError, text: str, expected: Literal["query", "update"]) -> QuerySyntaxError:
    """``error`` with a plain reason in front where the parser's list of expected tokens hides it: an
    update sent as a query (or the other way round), a misspelt first keyword, a prefix nobody declared,
    or a text that ends inside a block."""
    if type(error) is not QuerySyntaxError:  # QueryTooComplexError and the like say what they mean
        return error
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
        return QuerySyntaxError(text, f"{where}this is a SPARQL {kind}, not {article} {expected}: {how}")
    word = first_keyword(text) if kind is None else None
    close = (
        difflib.get_close_matches(word.upper(), FORMS if expected == "query" else _UPDATE_WORDS, n=1) if word else []
    )
    if close:  # SELEKT, INSRT: the parser says "expected CONSTRUCT", the last form it tried
        return QuerySyntaxError(
            text, f"{where}{word!r} begins no SPARQL {expected}: did you mean {close[0]}? (the parser: {said})"
        )
    prefix = undeclared_prefix(text)
    if prefix is not None:
        # Oxigraph says "Prefix not found" among the tokens it expected, or (in a subject) nothing of it
        close = difflib.get_close_matches(prefix, PREFIXES, n=1)
        if close:
            known = f"did you mean '{close[0]}:'?"
        elif "Prefix not found" in said:
            known = "cbrs declares " + ", ".join(f"{p}:" for p in PREFIXES)
        else:
            known = f"the parser: {said}"
        reason = f"the prefix '{prefix}:' is not declared: add PREFIX {prefix}: <IRI>; {known}"
        return QuerySyntaxError(text, where + reason)
    open_blocks = unclosed(text)
    if open_blocks:  # the parser lists every token that could have come next
        return QuerySyntaxError(
            text,
            f"{where or 'at the end: '}the text ends with {open_blocks} '{{' not closed: add '}}' where each "
            "block ends",
        )
    return error


_BRACE = re.compile(HIDING + r"|[{}]", re.DOTALL)
"""Strings, IRIs and comments, which hide the braces inside them; then the braces that count."""


def unclosed(text: str) -> int:
    """How many ``{`` of ``text`` (outside strings, IRIs and comments) no ``}`` closes: the parser's answer
    to a text that ends inside a block is a list of every token it could have read."""
    depth = 0
    for match in _BRACE.finditer(text):
        token = match.group()
        depth += 1 if token == "{" else -1 if token == "}" else 0
        depth = max(depth, 0)
    return depth
