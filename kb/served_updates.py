"""What a ``cbrs serve`` says of its updates to a remote store client: the header that names it, and its
refusal of an update read back as the error the embedded store raises.

A cbrs server runs each update through :meth:`KnowledgeBase.update` on its own store, with the embedded
store's checks, all or nothing, and brings graph:entailed up to date. It says so on every answer of its
SPARQL endpoints (``Cbrs-Server: cbrs/VERSION checked-updates``), so that a client on it need not first
carry a checked update out on a copy of the whole store (:mod:`kb.remote_updates`): it sends the text and
the server refuses it. The header only spares the client work the server does anyway; a server that did
not check would not send the word (:func:`cbrs.sparql_service.identity_header`), and one that lies could
write anything it likes to its own store regardless.

The server answers a refusal with its JSON error (``{"error": kind, "message": ..., "notes": [...]}``);
:func:`refusal` gives back the error of that class, with the same words and notes, for the kinds an
update's checks raise. Its structured fields (a shape error's problems, a map error's thing) are not sent.
"""

from __future__ import annotations

import json
from collections.abc import Callable

from cbrs.kb.errors import (
    BlankNodeInsertError,
    InvalidDescriptionError,
    KnowledgeBaseError,
    QuerySyntaxError,
    StoreEvaluationError,
    UndeclaredSuperclassError,
)
from cbrs.kb.remote_access import RemoteAccessError

HEADER = "Cbrs-Server"
"""The response header a cbrs server names itself by, on its SPARQL endpoints."""
CHECKED = "checked-updates"
"""The word in :data:`HEADER` that says its ``/update`` runs the embedded store's checks, all or nothing."""


def header_value(version: str, checked: bool) -> str:
    """:data:`HEADER`'s value for a server of cbrs ``version`` whose updates are ``checked`` or not."""
    return f"cbrs/{version}" + (f" {CHECKED}" if checked else "")


def claims_checked(value: str | None) -> bool:
    """Whether a :data:`HEADER` value says the server's updates are checked."""
    words = (value or "").split()
    return bool(words) and words[0].startswith("cbrs/") and CHECKED in words[1:]


def _refusal_classes() -> dict[str, type[KnowledgeBaseError]]:
    """The errors an update's checks raise, and every subclass, by the name the server sends as the kind."""
    from cbrs.kb.semantic_map import MapError  # it imports the knowledge base, which imports the store
    from cbrs.kb.shapes import DescriptionShapeError
    from cbrs.kb.superclasses import RemovedDeclarationError  # a subclass of one below, defined with its check

    found: dict[str, type[KnowledgeBaseError]] = {}
    waiting: list[type[KnowledgeBaseError]] = [
        MapError,
        InvalidDescriptionError,
        DescriptionShapeError,
        UndeclaredSuperclassError,
        RemovedDeclarationError,
        BlankNodeInsertError,
        RemoteAccessError,
    ]
    while waiting:
        cls = waiting.pop()
        found.setdefault(cls.__name__, cls)
        waiting.extend(cls.__subclasses__())
    return found


def refusal(
    location: str,
    endpoint: str,
    status: int,
    body: bytes,
    request: str,
    positions: Callable[[str], str] = str,
) -> KnowledgeBaseError | None:
    """The error a cbrs server's refusal (``body``, its JSON) of the caller's update or query ``request``
    stands for, as the embedded store raises it: a check's error of the same class, words and notes, a
    syntax error as :class:`QuerySyntaxError` of the text as given, an evaluation error as
    :class:`StoreEvaluationError` naming ``location`` (the store the caller named, not the server's own).
    ``positions`` corrects a syntax error's line for the prologue sent before the text. None for any other
    answer (left to the caller's handling of the status)."""
    try:
        said = json.loads(body)
    except ValueError:
        return None
    if not isinstance(said, dict) or not isinstance(said.get("error"), str) or not isinstance(said.get("message"), str):
        return None
    kind, message = said["error"], said["message"]
    notes = [note for note in said.get("notes") or () if isinstance(note, str)]
    error: KnowledgeBaseError
    if kind == "QuerySyntaxError":
        error = QuerySyntaxError(request, positions(message.removeprefix("SPARQL syntax error: ")))
    elif kind == "StoreEvaluationError":
        operation, _, reason = message.partition(" failed: ")
        error = StoreEvaluationError(location, operation.rsplit(" ", 1)[-1] or "update", reason or message)
        error.endpoint, error.status, error.request = endpoint, status, request
    else:
        cls = _refusal_classes().get(kind)
        if cls is None:
            return None
        error = cls.__new__(cls)  # its own constructor takes what the server read, which it does not send
        error.args = (message,)
    for note in notes:
        error.add_note(note)
    return error
