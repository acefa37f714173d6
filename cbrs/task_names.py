"""Names as a person types them: a bare local name of any namespace, a prefixed name or an IRI.

The composer resolves a bare name in the bundled namespaces only (``req:NAME``, then ``act:NAME``); a
task loaded under its own namespace (``lab:FetchMyCup``) is listed by its local name, so a listed name
must resolve too. :func:`task_iri` turns what was typed into the IRI the composer is given, or fails
with a did-you-mean and every known task spelt as it can be typed. :func:`near_names` offers the
like of that did-you-mean for any name that names nothing (``cbrs show``, ``cbrs match``).
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.actions.errors import UnknownTaskError
from cbrs.actions.model import ActionLibrary
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import namespace
from cbrs.kb.name_errors import UnknownPrefixError
from cbrs.kb.namespaces import expand, written
from cbrs.kb.owls import local_name


class TaskNameError(UnknownTaskError):
    """No task (or more than one) answers to ``name``; ``suggestions`` are the likeliest meant.
    ``prefix_reason`` is what is wrong with the prefix ``name`` was typed with, when nobody declared it
    (:attr:`~cbrs.kb.name_errors.UnknownPrefixError.reason`, with the prefixes nearest it): part of the
    message, not a note, since the pages show a message alone."""

    def __init__(
        self,
        name: str,
        known: Sequence[str],
        suggestions: Sequence[str],
        ambiguous: bool = False,
        prefix_reason: str | None = None,
    ) -> None:
        super().__init__(name, known)
        self.suggestions = tuple(suggestions)
        self.ambiguous = ambiguous
        self.prefix_reason = prefix_reason
        if ambiguous:
            text = f"{name!r} names {len(suggestions)} tasks; type one of {', '.join(suggestions)}"
        else:
            why = f" ({prefix_reason})" if prefix_reason else ""
            hint = f"; did you mean {' or '.join(suggestions)}?" if suggestions else "."
            text = f"no requirement or action named {name!r}{why}{hint} Known tasks: {', '.join(known)}"
        self.args = (text,)

    def __str__(self) -> str:
        return str(self.args[0])


@dataclass(frozen=True)
class _Task:
    iri: str
    listed: bool  # a requirement, or an action with sub-actions: what the known list shows


def task_iri(kb: KnowledgeBase, name: str, library: ActionLibrary | None = None) -> str:
    """The IRI of the requirement or action ``name`` means; :class:`TaskNameError` when there is none (a
    prefix nobody declared, ``rq:FetchMyPen``, named in it with the prefixes nearest it)."""
    tasks = _tasks(kb, library or ActionLibrary.from_kb(kb))
    typed = name.strip()
    prefix_reason = None  # rq:FetchMyPen: the local names' did-you-mean alone did not say the prefix is wrong
    if ":" in typed:
        try:
            iri = expand(typed)
        except UnknownPrefixError as unknown:
            iri, prefix_reason = "", unknown.reason
        except ValueError:
            iri = ""
        if any(task.iri == iri for task in tasks):
            return iri
    else:
        found = _bare(typed, tasks)
        if found is not None:
            return found
        named = sorted(task.iri for task in tasks if local_name(task.iri) == typed)
        if named:
            raise TaskNameError(name, _known(tasks), [_typed(iri, tasks) for iri in named], ambiguous=True)
    raise TaskNameError(name, _known(tasks), _suggestions(typed, tasks), prefix_reason=prefix_reason)


def known_tasks(kb: KnowledgeBase, library: ActionLibrary | None = None) -> list[str]:
    """Every task the store can express (its requirements and the actions with sub-actions), each
    spelt as :func:`task_iri` takes it back: what a person is offered to choose from."""
    return _known(_tasks(kb, library or ActionLibrary.from_kb(kb)))


def _tasks(kb: KnowledgeBase, library: ActionLibrary) -> list[_Task]:
    requirements = [_Task(row["requirement"].value, True) for row in kb.select("requirements")]
    actions = [_Task(action.iri, bool(action.sub_actions)) for action in library]
    return requirements + actions


def _bare(name: str, tasks: Sequence[_Task]) -> str | None:
    """The task a bare name means: ``req:NAME``, else ``act:NAME`` (as the composer tries them), else the
    one task of any namespace with that local name."""
    iris = {task.iri for task in tasks}
    for bundled in (expand(f"req:{name}"), expand(f"act:{name}")):
        if bundled in iris:
            return bundled
    named = {iri for iri in iris if local_name(iri) == name}
    return named.pop() if len(named) == 1 else None


def _typed(iri: str, tasks: Sequence[_Task]) -> str:
    """How to type ``iri``: its bare name when that means it, else its prefixed name, else ``<IRI>``."""
    bare = local_name(iri)
    if _bare(bare, tasks) == iri:
        return bare
    return written(iri)


def _known(tasks: Sequence[_Task]) -> list[str]:
    return sorted({_typed(task.iri, tasks) for task in tasks if task.listed})


def _suggestions(typed: str, tasks: Sequence[_Task]) -> list[str]:
    return sorted({_typed(iri, tasks) for iri in _closest(typed, [task.iri for task in tasks])})


def _closest(typed: str, iris: Iterable[str]) -> list[str]:
    """The IRIs whose local names are the closest spellings of ``typed``'s, with case aside: those
    differing only in case alone, else the best few difflib finds."""
    key = (local_name(typed) if ":" in typed else typed).lower()
    by_name: dict[str, list[str]] = {}
    for iri in iris:
        by_name.setdefault(local_name(iri).lower(), []).append(iri)
    if key in by_name:
        close = [key]
    else:
        scored = sorted(((difflib.SequenceMatcher(None, key, n).ratio(), n) for n in by_name), reverse=True)
        best = scored[0][0] if scored else 0.0
        close = [n for score, n in scored[:3] if score >= max(0.75, best - 0.05)]
    return [iri for name in close for iri in by_name[name]]


# The resources described in one namespace, bound as a string: read only when a name named nothing.
_IN_NAMESPACE = "SELECT DISTINCT ?s ?namespace WHERE { ?s ?p ?o FILTER(STRSTARTS(STR(?s), ?namespace)) }"


def near_names(kb: KnowledgeBase, iri: str, among: Iterable[str] | None = None) -> list[str]:
    """The names a person who typed ``iri`` (which names nothing) likely meant, written as they can be
    typed back (prefixed, with the store's derived prefixes within ``store_names``): the closest local
    names ``among`` the IRIs given, by default the subjects of the store in ``iri``'s namespace."""
    if among is None:
        ns = namespace(iri)
        if ns is None:
            return []
        rows = kb.query(_IN_NAMESPACE, {"namespace": ox.Literal(ns)})
        if not isinstance(rows, ox.QuerySolutions):  # a SELECT's answer always is
            return []
        among = [row[0].value for row in rows if isinstance(row[0], ox.NamedNode)]
    return sorted({written(found) for found in _closest(iri, among) if found != iri})
