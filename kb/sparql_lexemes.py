"""The SPARQL lexemes that can hide other text: strings (all four quotings), IRIs and comments.

Checks that read a query as text before any parser does (the bracket count in :mod:`kb.store`, the
SERVICE/LOAD check in :mod:`kb.remote_access`) match these first, so that nothing inside them counts.
An IRI holds no ``<``, space or brace, so a keyword or bracket outside one is never read as inside.
"""

HIDING = (
    r'"""(?:[^"\\]|\\.|"(?!""))*"""'
    r"|'''(?:[^'\\]|\\.|'(?!''))*'''"
    r'|"(?:[^"\\\n]|\\.)*"'
    r"|'(?:[^'\\\n]|\\.)*'"
    r'|<[^<>"{}|^`\\\x00-\x20]*>'
    r"|#[^\n]*"
)
"""A regular expression alternation of the strings, IRIs and comments of SPARQL text."""
