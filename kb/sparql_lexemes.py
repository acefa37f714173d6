"""The SPARQL lexemes that can hide other text: strings (all four quotings), IRIs and comments.

Checks that read a query as text before any parser does (the bracket count in :mod:`kb.store`, the
SERVICE/LOAD check in :mod:`kb.remote_access`) match these first, so that nothing inside them counts.
An IRI holds no ``<``, space or brace, so a keyword or bracket outside one is never read as inside.
"""

from collections.abc import Sequence

HIDING = (
    r'"""(?:[^"\\]|\\.|"(?!""))*"""'
    r"|'''(?:[^'\\]|\\.|'(?!''))*'''"
    r'|"(?:[^"\\\n]|\\.)*"'
    r"|'(?:[^'\\\n]|\\.)*'"
    r'|<[^<>"{}|^`\\\x00-\x20]*>'
    r"|#[^\n]*"
)
"""A regular expression alternation of the strings, IRIs and comments of SPARQL text."""


def closing_brace(words: Sequence[str], opening: int) -> int | None:
    """The index of the ``}`` that closes the ``{`` at ``opening`` among ``words`` (lexemes read with
    :data:`HIDING` first, so no brace inside a string, IRI or comment is one); None if none closes it."""
    depth = 0
    for index in range(opening, len(words)):
        depth += (words[index] == "{") - (words[index] == "}")
        if depth == 0:
            return index
    return None
