"""Which outside resources a query or update may make the store reach: none, unless allowed.

``SERVICE <endpoint>`` makes Oxigraph send a query to another server and ``LOAD <iri>`` makes it read
a URL or a file. From an anonymous client that turns the server into a port scanner and a proxy into
the lab's network (server-side request forgery), and ``LOAD <file:///etc/passwd>`` reads local files.
So both are refused before the store sees the text, unless the endpoint or IRI starts with one of the
allowed prefixes (setting ``federation_allow``; none by default). The check reads the text as SPARQL
tokens (strings, IRIs and comments cannot hide a keyword, and a keyword cannot hide in them, since an
IRI holds no ``<``, space or brace), so it needs no parser. An endpoint given by a variable or a
prefixed name is refused: only a full IRI can be matched against the allow-list.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.sparql_lexemes import HIDING

_TOKEN = re.compile(
    HIDING + r"|[?$][A-Za-z0-9_\u00b7-\uffff]+"
    r"|[A-Za-z_][\w.-]*:[^\s{}()<>;,\"']*"
    r"|[A-Za-z_][\w-]*"
    r"|\S",
    re.DOTALL,
)
_KEYWORDS = {"SERVICE": "a federated query (SERVICE)", "LOAD": "LOAD"}


class RemoteAccessError(KnowledgeBaseError):
    """A query or update would make the server reach an endpoint, URL or file it is not allowed to."""

    http_status = 400

    def __init__(self, query: str, what: str, target: str) -> None:
        self.query = query
        self.target = target
        super().__init__(
            f"{what} of {target} is refused: this server reaches no outside endpoint, URL or file unless its "
            "IRI starts with a prefix in the setting federation_allow (none by default)"
        )


def loads(text: str) -> bool:
    """Whether ``text`` holds a ``LOAD`` (read as SPARQL tokens, so not one inside a string or IRI)."""
    return any(m.group().upper() == "LOAD" for m in _TOKEN.finditer(text))


def refuse_remote_access(text: str, allowed: Sequence[str] = ()) -> None:
    """Raise :class:`RemoteAccessError` for a ``SERVICE`` or ``LOAD`` in ``text`` whose target is not allowed."""
    tokens = [m.group() for m in _TOKEN.finditer(text) if not m.group().startswith("#")]
    for position, token in enumerate(tokens):
        what = _KEYWORDS.get(token.upper())
        if what is None:
            continue
        following = tokens[position + 1 : position + 3]
        if following and following[0].upper() == "SILENT":
            following = following[1:]
        target = following[0] if following else "(nothing)"
        iri = target[1:-1] if target.startswith("<") and target.endswith(">") else None
        if iri is None or not any(iri.startswith(prefix) for prefix in allowed if prefix):
            raise RemoteAccessError(text, what, target)
