"""A query's text with its result cut at so many solutions, so that the editor reads no more than it shows.

The editor shows the first rows of a result. Run as written, ``SELECT * WHERE { ?s ?p ?o }`` on OWLS-TC
had the engine produce and serialise all 178,000 solutions (50 MB of JSON, 18 to 22 s at load 5) to show 1,000.
With a ``LIMIT`` of one row more than shown, Oxigraph stops producing solutions there (it evaluates
lazily), and the extra row tells the page the result was cut. The query still goes through the
endpoint's service, with its deadline, byte budget and worker slots.

The text is read with the lexemes that can hide a brace or a keyword (strings, IRIs, comments, prefixed
names: :data:`cbrs.kb.sparql_hints.TOKENS`), never parsed here: only a ``LIMIT`` clause is added or
lowered, and the parser still decides what the text means. A text this reading does not understand is
left as it is (:func:`bounded` answers ``None``), and the caller runs it whole.

A CONSTRUCT or DESCRIBE is bounded the same way, after its template: its ``LIMIT`` counts solutions,
not triples, so the editor counts the triples that come back (:mod:`cbrs.web.editor`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from cbrs.kb.sparql_hints import TOKENS

# The tokens of TOKENS, and the brackets and integers between them that the bound depends on.
_LEXEMES = re.compile(
    TOKENS.pattern + r"|(?P<open>[{(\[])|(?P<close>[})\]])|(?P<integer>\d+)",
    re.DOTALL,
)
_PROLOGUE = frozenset({"PREFIX", "BASE", "VERSION"})
# The forms a LIMIT bounds, and how many top-level blocks come before the solution modifiers: a
# CONSTRUCT's template and then its WHERE block (one block in its short form, CONSTRUCT WHERE { }).
_BLOCKS = {"SELECT": 1, "CONSTRUCT": 2, "DESCRIBE": 1}


@dataclass(frozen=True)
class Bounded:
    """A query text that yields at most ``limit`` rows; ``changed`` says whether it differs from the text
    given (it already had a ``LIMIT`` no greater)."""

    text: str
    limit: int
    changed: bool


def bounded(text: str, limit: int) -> Bounded | None:
    """``text`` with a ``LIMIT`` of at most ``limit`` solutions, if it is a SELECT, CONSTRUCT or DESCRIBE
    query with a ``WHERE`` block that this reading understands; ``None`` for any other text (ASK, a
    DESCRIBE of named resources alone, an update, unbalanced brackets).

    The ``LIMIT`` goes after the ``WHERE`` block's solution modifiers and before a closing ``VALUES``
    block, where the grammar puts it (``SelectQuery ... SolutionModifier ValuesClause``); a ``LIMIT``
    the query has is lowered to ``limit`` when greater, and kept when not."""
    depth = 0
    form: str | None = None
    blocks = 0  # top-level blocks still to close before the solution modifiers
    where_closed = False
    values_at: int | None = None
    limit_word = False
    for match in _LEXEMES.finditer(text):
        kind = match.lastgroup
        if kind == "open":
            depth += 1
        elif kind == "close":
            depth -= 1
            if depth < 0:
                return None
            if depth == 0 and form is not None and not where_closed and match.group() == "}":
                blocks -= 1
                where_closed = blocks == 0
        elif kind == "word":
            word = match.group().upper()
            if form is None:
                if word in _PROLOGUE:
                    continue
                if word not in _BLOCKS:
                    return None
                form, blocks = word, _BLOCKS[word]
            elif form == "CONSTRUCT" and word == "WHERE" and blocks == 2 and depth == 0:
                blocks = 1  # the short form: no template block before this one
            elif where_closed and depth == 0:
                if word == "VALUES" and values_at is None:
                    values_at = match.start()
                limit_word = word == "LIMIT" and values_at is None
                continue
        elif kind == "integer" and limit_word:
            given = int(match.group())
            if given <= limit:
                return Bounded(text, given, changed=False)
            return Bounded(text[: match.start()] + str(limit) + text[match.end() :], limit, changed=True)
        limit_word = False
    if form is None or not where_closed or depth != 0:
        return None
    clause = f"LIMIT {limit}"
    if values_at is not None:
        return Bounded(f"{text[:values_at]}{clause}\n{text[values_at:]}", limit, changed=True)
    return Bounded(f"{text}\n{clause}", limit, changed=True)  # on its own line: the text may end in a comment
