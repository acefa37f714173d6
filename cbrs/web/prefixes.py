"""The browser's derived prefixes for the namespaces a store uses that cbrs's prefix table does not
declare (``books:Novel``): the rule is :mod:`cbrs.kb.derived_prefixes`, shared with the CLI, which
prints and takes the same names (docs/web.md, "Names, pictures, keyboard").

The table is read from the store once per store generation (:func:`cbrs.web.context.per_generation`),
and once per request on a remote store. An on-disk store's table is the one the CLI keeps in its folder
(:func:`cbrs.kb.derived_prefixes.for_store`): reading every term of a million-triple store took a core
12.5 s at each start of ``cbrs serve``.
"""

from __future__ import annotations

from flask import g, has_app_context

from cbrs.kb.derived_prefixes import derive, for_store, name_for, namespace, read
from cbrs.web import context

__all__ = ["by_namespace", "derive", "derived", "name_for", "namespace", "read"]


def derived() -> dict[str, str]:
    """The current store's derived prefixes (prefix → namespace); none outside an app context."""
    return _tables()[0]


def by_namespace() -> dict[str, str]:
    """Namespace → derived prefix, for shortening."""
    return _tables()[1]


def _tables() -> tuple[dict[str, str], dict[str, str]]:
    """Both directions of the table, kept per store generation and, for a remote store (which counts no
    generations), per request: a page shortens hundreds of IRIs."""
    if not has_app_context():
        return {}, {}
    if "cbrs_derived_prefixes" not in g:
        kb = context.kb()

        def compute() -> tuple[dict[str, str], dict[str, str]]:
            table = for_store(kb)
            return table, {ns: prefix for prefix, ns in table.items()}

        g.cbrs_derived_prefixes = context.per_generation("derived_prefixes", compute)
    tables: tuple[dict[str, str], dict[str, str]] = g.cbrs_derived_prefixes
    return tables
