"""The error a remote service call fails with, apart from :mod:`cbrs.actions.remote` (the executor's
remote component): the bridge client and the component SDK raise it in a component's own program,
which should not import the executor, the knowledge base and the planner to do so."""

from __future__ import annotations

__all__ = ["RemoteCallError"]


class RemoteCallError(Exception):
    """A remote service answered with ``result: false``; the message is its reason."""
