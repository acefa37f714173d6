"""The error of a name typed with a prefix nobody declared (:func:`cbrs.kb.namespaces.expand`).

A module of its own because :mod:`cbrs.kb.errors` writes IRIs with the prefix table, which raises this:
the table imports it only when it raises.
"""

from __future__ import annotations

from collections.abc import Sequence

from cbrs.kb.errors import KnowledgeBaseError


class UnknownPrefixError(KnowledgeBaseError, ValueError):
    """``name`` is ``prefix:local`` with a prefix that is neither declared (the table, or within
    :func:`~cbrs.kb.namespaces.store_names` the store's derived ones) nor an IRI scheme cbrs reads
    without ``<>``: ``hom:Cup`` for ``home:Cup`` was taken as an IRI of scheme ``hom`` and named nothing.
    ``near`` are the declared prefixes closest to ``prefix``. A ``ValueError`` too, as every name that
    does not read has been."""

    http_status = 400

    def __init__(self, name: str, prefix: str, near: Sequence[str], known: str) -> None:
        self.name = name
        self.prefix = prefix
        self.near = tuple(near)
        local = name.partition(":")[2]
        hint = f"; did you mean {' or '.join(f'{p}:{local}' for p in self.near)}?" if self.near else ""
        # what is wrong with the prefix alone, for a message of its own (a task name that names nothing)
        self.reason = f"{prefix}: is declared nowhere and is no IRI scheme cbrs reads bare{hint}"
        super().__init__(
            f"{name!r} is neither an absolute IRI nor a prefixed name with a known prefix: {self.reason} (known "
            f"prefixes: {known}; an IRI of another scheme is written in <>: docs/web.md, 'Names in the CLI')"
        )
