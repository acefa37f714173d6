"""How a person is shown an IRI that no prefix covers: its tail, not the whole IRI.

The pages (``cbrs.web.links.name_parts``) and a run's ``shown`` name (``cbrs.tasks.shown_name``) both show
such an IRI so; it lives here, outside the web package, so that the task runner needs no Flask.
"""

from __future__ import annotations

__all__ = ["tail", "tail_parts"]


def tail_parts(iri: str) -> tuple[str, str]:
    """The part of ``iri`` after its last ``/`` split at ``#``: ``("my_ontology.owl#", "Car")`` rather
    than ``http://127.0.0.1/ontology/my_ontology.owl#Car``, which filled table columns and hid the
    local name at the end (the pages showed OWLS-TC's IRIs so before they had derived prefixes, and the
    match form still takes a concept so named). An IRI without such a tail is ``("", iri)``."""
    _, scheme, rest = iri.partition("://")
    _host, slash, path = rest.partition("/")
    if not scheme or not slash or not path or iri.endswith("/"):  # no path to take a tail of
        return "", iri
    namespace, hash_, local = path.rsplit("/", 1)[-1].rpartition("#")
    if not hash_ or not local:
        return "", path.rsplit("/", 1)[-1]
    return namespace + "#", local


def tail(iri: str) -> str:
    """:func:`tail_parts` as one string (``my_ontology.owl#Car``)."""
    return "".join(tail_parts(iri))
